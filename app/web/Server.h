// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The HTTP side of `underfoot serve` (cpp-httplib): the participant page from the program's
/// embedded resources, the JSON API over WebStudy, clip delivery, request size and rate limits.
/// The link token travels in the `Authorization: Bearer` header (the page reads it from the
/// link's #fragment, which browsers never send to servers or in Referer headers).
#include "app/web/Api.h"
#include "app/web/WebStudy.h"

#include <cstddef>
#include <memory>
#include <string>

namespace underfoot::web {

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

} // namespace underfoot::web
