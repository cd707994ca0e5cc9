// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The request handling of `underfoot serve` without sockets or HTTP headers of a library
/// (issue #16): one HttpRequest (method, path, headers, body, peer address) in, one HttpAnswer
/// out. It applies the rate limit and the body size limit, routes the participant page, the
/// embedded assets, the JSON API over WebStudy and the clip requests, and maps refusals and
/// errors to status codes with a JSON message. app/web/Server.cpp adapts cpp-httplib to it;
/// the fuzz target tests/fuzz/fuzz_web_request.cpp calls it directly.
#include "app/web/WebStudy.h"

#include <atomic>
#include <cstddef>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

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

/// One embedded file of app/web/assets (path like "app.js"), or nullptr.
struct Asset {
    const unsigned char* data;
    std::size_t size;
    const char* contentType;
};
const Asset* findAsset(const std::string& name);

/// Header names compare without case (RFC 9110).
struct HeaderNameLess {
    bool operator()(const std::string& a, const std::string& b) const;
};
using HttpHeaders = std::multimap<std::string, std::string, HeaderNameLess>;

/// A request as the HTTP layer decoded it (`path` without the query, percent-decoded).
struct HttpRequest {
    std::string method;
    std::string path;
    HttpHeaders headers;
    std::string body;
    std::string remoteAddr;
    /// The first value of header `name`, or "".
    std::string header(const std::string& name) const;
};

/// The answer: status, headers, and either a body or a clip file to stream.
struct HttpAnswer {
    int status = 200;
    std::vector<std::pair<std::string, std::string>> headers;
    std::string contentType;
    std::string body;
    /// Set when the answer is the content of a clip file (streamed by the HTTP layer).
    std::optional<ClipFile> clip;
};

/// Routes and handles requests; thread-safe (WebStudy serialises the store).
class WebApi {
  public:
    WebApi(WebStudy& study, const ServerOptions& options);
    ~WebApi();
    WebApi(const WebApi&) = delete;
    WebApi& operator=(const WebApi&) = delete;

    /// Step 1, before the body is read: counts the request, sets the security headers, applies
    /// the rate limit. False when `answer` is final (429).
    bool admit(const HttpRequest& request, HttpAnswer& answer);
    /// Step 2: routes the request (with its body) and handles it into `answer`.
    void route(const HttpRequest& request, HttpAnswer& answer);
    /// Both steps and the body size limit (413), as the HTTP layer applies them.
    HttpAnswer handle(const HttpRequest& request);
    /// The answer to a request the HTTP layer refused before handle() (413 too large, 400
    /// malformed, 404): the same JSON error body as the API's own refusals.
    static HttpAnswer error(int status);
    ServerCounters counters() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace underfoot::web
