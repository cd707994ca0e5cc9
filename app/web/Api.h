// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The request handling of `underfoot serve` without sockets or an HTTP library: one
/// HttpRequest (method, path, headers, body, peer address) in, one HttpAnswer out. It applies
/// the framing rules and rate limits, checks the link token before a body is read, routes the
/// participant page, the embedded assets, the JSON API over WebStudy and the clip requests,
/// and maps refusals and errors to status codes with a JSON message. app/web/Server.cpp feeds
/// it from Boost.Beast; the fuzz target tests/fuzz/fuzz_web_request.cpp calls it directly.
/// Every limit and status is listed in docs/reference/web-server.md.
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
    /// Largest request body accepted (bytes), with Content-Length or chunked; larger: 413.
    std::size_t maxBodyBytes = 16 * 1024;
    /// Largest request line + header fields (bytes), and most header fields; more: 431.
    std::size_t maxHeaderBytes = 8 * 1024;
    std::size_t maxHeaderFields = 64;
    /// A request's header and body must arrive within this time of its first byte.
    double requestTimeoutS = 10.0;
    /// A connection with no request in progress (new or kept alive) is closed after this.
    double idleTimeoutS = 5.0;
    /// Writing one answer (a clip included) must end within this time.
    double writeTimeoutS = 60.0;
    /// Open connections in all, and from one address (trusted proxies are not counted per
    /// address); more are closed when accepted.
    std::size_t maxConnections = 1024;
    std::size_t maxConnectionsPerAddress = 64;
    /// Peers whose X-Forwarded-For names the client (`--trusted-proxy`).
    std::vector<std::string> trustedProxies;
    /// API requests per second per invitation (or per client address for requests without a
    /// real invitation's token) in the long run, and the burst allowed above it; more: 429.
    /// The page and its assets are not rate limited.
    double ratePerSecond = 20.0;
    double burst = 60.0;
    /// Rate-limit buckets kept (least recently used evicted first).
    std::size_t rateBuckets = 16384;
    /// Threads that run the network (every connection, none blocking) and threads that run
    /// the API's calls into the study.
    int ioThreads = 2;
    int threads = 4;
};

/// Counters of one server run (printed at the clean stop).
struct ServerCounters {
    std::size_t requests = 0;
    std::size_t refused = 0;
    std::size_t rateLimited = 0;
    /// Connections closed at accept (connection caps).
    std::size_t connectionsRefused = 0;
    /// Requests cut by the request deadline or the idle timeout mid-request.
    std::size_t timedOut = 0;
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
    /// Throws std::invalid_argument when a trusted proxy is not an IP address.
    WebApi(WebStudy& study, const ServerOptions& options);
    ~WebApi();
    WebApi(const WebApi&) = delete;
    WebApi& operator=(const WebApi&) = delete;

    /// Whether handling `request` may call into the study (blocking: the HTTP layer runs such
    /// requests off its network thread). The page and its assets do not.
    static bool touchesStudy(const HttpRequest& request);
    /// Whether admit() would ask the study about `request`'s token (blocking; only for a
    /// well-formed token not seen before).
    bool admitAsksStudy(const HttpRequest& request) const;
    /// Step 1, with the headers only (before any body is read): counts the request, sets the
    /// security headers, refuses bad framing (400: Content-Length with Transfer-Encoding, a
    /// transfer coding other than chunked; 431: too many header fields), applies the rate
    /// limit (429) and, for the API, checks that the token opens an invitation (403). False
    /// when `answer` is final.
    bool admit(const HttpRequest& request, HttpAnswer& answer);
    /// Step 2: routes the request (with its body) and handles it into `answer`.
    void route(const HttpRequest& request, HttpAnswer& answer);
    /// Both steps and the body size limit (413), as the HTTP layer applies them.
    HttpAnswer handle(const HttpRequest& request);
    /// The answer to a request the HTTP layer refused itself (400 malformed, 413 too large,
    /// 431 header too large): the same JSON error body and headers as the API's own refusals.
    static HttpAnswer error(int status);
    ServerCounters counters() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace underfoot::web
