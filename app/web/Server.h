// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The HTTP side of `underfoot serve` (cpp-httplib): the participant page from the program's
/// embedded resources, the JSON API over WebStudy, clip delivery, request size and rate limits.
/// The link token travels in the `Authorization: Bearer` header (the page reads it from the
/// link's #fragment, which browsers never send to servers or in Referer headers).
#include "app/web/WebStudy.h"

#include <cstddef>
#include <memory>
#include <string>

namespace underfoot::web {

struct ServerOptions {
    std::string bind = "127.0.0.1";
    /// 0: any free port (tests).
    int port = 8080;
    /// Largest request body accepted (bytes); larger bodies get 413.
    std::size_t maxBodyBytes = 16 * 1024;
    /// Requests per second per participant link (or per address without a valid-looking token)
    /// in the long run, and the burst allowed above it; more get 429.
    double ratePerSecond = 20.0;
    double burst = 60.0;
    /// Worker threads.
    int threads = 16;
};

/// Counters of one server run (printed at the clean stop).
struct ServerCounters {
    std::size_t requests = 0;
    std::size_t refused = 0;
    std::size_t rateLimited = 0;
};

class WebServer {
  public:
    WebServer(WebStudy& study, ServerOptions options);
    ~WebServer();
    /// Binds the socket (throws std::runtime_error naming the address when it cannot); returns
    /// the port.
    int bind();
    /// Serves until stop() (blocking).
    void run();
    /// Stops run() (from any thread).
    void stop();
    ServerCounters counters() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// One embedded file of app/web/assets (path like "app.js"), or nullptr.
struct Asset {
    const unsigned char* data;
    std::size_t size;
    const char* contentType;
};
const Asset* findAsset(const std::string& name);

} // namespace underfoot::web
