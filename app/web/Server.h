// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The HTTP side of `underfoot serve`: HTTP/1.1 (RFC 9112) over Boost.Beast and Asio, one
/// network thread driving every connection (a slow or idle client holds a socket, never a
/// thread) and a few worker threads for the calls into the study. It enforces the connection
/// limits (a deadline for each request's header and body, an idle timeout, caps on
/// connections in all and per address, header and body size limits that hold for chunked
/// bodies too) and hands each request to WebApi (app/web/Api.h) in two steps: the headers
/// (token and rate limit checked) before the body is read, then the whole request. The limits
/// are listed in docs/reference/web-server.md.
#include "app/web/Api.h"
#include "app/web/WebStudy.h"

#include <memory>

namespace underfoot::web {

class WebServer {
  public:
    /// Throws std::invalid_argument when an option is unusable (a trusted proxy that is not an
    /// IP address).
    WebServer(WebStudy& study, ServerOptions options);
    ~WebServer();
    WebServer(const WebServer&) = delete;
    WebServer& operator=(const WebServer&) = delete;
    /// Binds the socket (throws std::runtime_error naming the address when it cannot); returns
    /// the port.
    int bind();
    /// Serves until stop() (blocking); returns once the calls into the study have ended.
    void run();
    /// Stops run() (from any thread, also before run()).
    void stop();
    ServerCounters counters() const;

    struct Impl;

  private:
    std::unique_ptr<Impl> impl_;
};

} // namespace underfoot::web
