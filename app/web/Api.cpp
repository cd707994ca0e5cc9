// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/web/Api.h"

#include "app/web/Limits.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstdint>
#include <functional>
#include <mutex>
#include <unordered_set>

namespace underfoot::web {

using nlohmann::json;

bool HeaderNameLess::operator()(const std::string& a, const std::string& b) const {
    return std::lexicographical_compare(
        a.begin(), a.end(), b.begin(), b.end(),
        [](unsigned char x, unsigned char y) { return std::tolower(x) < std::tolower(y); });
}

std::string HttpRequest::header(const std::string& name) const {
    const auto it = headers.find(name);
    return it == headers.end() ? std::string() : it->second;
}

namespace {

std::string bearer(const HttpRequest& req) {
    const std::string h = req.header("Authorization");
    constexpr std::string_view prefix = "Bearer ";
    if (h.size() > prefix.size() && h.compare(0, prefix.size(), prefix) == 0 && h.size() < 200)
        return h.substr(prefix.size());
    return {};
}

void securityHeaders(HttpAnswer& res) {
    res.headers.emplace_back("X-Content-Type-Options", "nosniff");
    res.headers.emplace_back("Referrer-Policy", "no-referrer");
    res.headers.emplace_back("X-Frame-Options", "DENY");
    res.headers.emplace_back(
        "Content-Security-Policy",
        "default-src 'self'; script-src 'self'; style-src 'self'; img-src 'self' data:; "
        "media-src 'self' blob:; connect-src 'self'; frame-ancestors 'none'");
}

void sendJson(HttpAnswer& res, int status, const json& body) {
    res.status = status;
    res.headers.emplace_back("Cache-Control", "no-store");
    res.contentType = "application/json; charset=utf-8";
    res.body = body.dump(-1, ' ', false, json::error_handler_t::replace);
}

const char* errorText(int status) {
    switch (status) {
    case 404:
        return "not found";
    case 413:
        return "request body too large";
    case 431:
        return "request header too large or too many header fields";
    case 503:
        return "the server is busy; retry in a moment";
    default:
        return "bad request";
    }
}

/// What follows `prefix` in `path` when it is 1 to `maxLength` characters that all pass
/// `allowed`; "" otherwise.
template <typename Allowed>
std::string suffix(const std::string& path, std::string_view prefix, std::size_t maxLength,
                   Allowed allowed) {
    if (path.size() <= prefix.size() || path.size() > prefix.size() + maxLength ||
        path.compare(0, prefix.size(), prefix) != 0)
        return {};
    const std::string rest = path.substr(prefix.size());
    return std::all_of(rest.begin(), rest.end(), allowed) ? rest : std::string();
}

/// The API's POST calls that take the token and the JSON body only.
using StudyCall = json (WebStudy::*)(const std::string& token, const json& body);
const std::map<std::string, StudyCall> kPostCalls{
    {"/api/consent", &WebStudy::consent},     {"/api/screening/start", &WebStudy::screeningStart},
    {"/api/screening", &WebStudy::screening}, {"/api/present", &WebStudy::present},
    {"/api/answer", &WebStudy::answer},       {"/api/break", &WebStudy::finishBreak}};

/// A link token as `study invite` writes it: 43 characters of base64url (256 bits).
bool plausibleToken(const std::string& t) {
    return t.size() == 43 && std::all_of(t.begin(), t.end(), [](unsigned char c) {
               return std::isalnum(c) || c == '-' || c == '_';
           });
}

/// What is wrong with the numbers or the nesting of a request body ("" when nothing): every
/// integer must fit in 32 bits (trial indices, ratings and counts do; 2^32 + n must not turn
/// into n), every number must be finite, objects and arrays nest at most 8 deep.
std::string numberProblem(const json& body) {
    constexpr int maxDepth = 8;
    std::vector<std::pair<const json*, int>> todo{{&body, 0}};
    while (!todo.empty()) {
        const auto [j, depth] = todo.back();
        todo.pop_back();
        if (j->is_number_unsigned()) {
            if (j->get<std::uint64_t>() > static_cast<std::uint64_t>(INT32_MAX))
                return fmt::format("the integer {} is out of range (at most {})", j->dump(),
                                   INT32_MAX);
        } else if (j->is_number_integer()) {
            const auto v = j->get<std::int64_t>();
            if (v < INT32_MIN || v > INT32_MAX)
                return fmt::format("the integer {} is out of range ({} to {})", v, INT32_MIN,
                                   INT32_MAX);
        } else if (j->is_number_float()) {
            if (!std::isfinite(j->get<double>())) return "a number is not finite";
        } else if (j->is_structured()) {
            if (depth >= maxDepth)
                return fmt::format("objects and arrays nest deeper than {} levels", maxDepth);
            for (const auto& child : *j) todo.emplace_back(&child, depth + 1);
        }
    }
    return {};
}

} // namespace

HttpAnswer WebApi::error(int status) {
    HttpAnswer a;
    securityHeaders(a);
    sendJson(a, status, {{"error", errorText(status)}});
    return a;
}

bool WebApi::touchesStudy(const HttpRequest& request) {
    return request.path.rfind("/api/", 0) == 0;
}

struct WebApi::Impl {
    WebStudy& study;
    ServerOptions options;
    TrustedProxies proxies;
    RateLimiter limiter;
    std::atomic<std::size_t> requests{0}, refused{0}, rateLimited{0};
    /// Tokens known to open an invitation (only real ones: bounded by the invitations).
    std::mutex knownMutex;
    std::unordered_set<std::string> known;
    std::atomic<bool> warnedForwarded{false};

    Impl(WebStudy& s, const ServerOptions& o)
        : study(s), options(o), proxies(o.trustedProxies),
          limiter(o.ratePerSecond, o.burst, o.rateBuckets) {}

    bool isKnown(const std::string& token) {
        std::lock_guard lock(knownMutex);
        return known.count(token) != 0;
    }

    /// The client's address (behind a trusted proxy: from X-Forwarded-For).
    std::string clientAddress(const HttpRequest& req) {
        const std::string peer = canonicalAddress(req.remoteAddr).value_or(req.remoteAddr);
        std::vector<std::string> forwarded;
        for (auto [it, end] = req.headers.equal_range("X-Forwarded-For"); it != end; ++it)
            forwarded.push_back(it->second);
        if (!forwarded.empty() && !proxies.trusts(peer) && !warnedForwarded.exchange(true))
            fmt::print(stderr,
                       "serve: requests from {} carry X-Forwarded-For, but {} is not a "
                       "--trusted-proxy: every client behind it shares that address's limits\n",
                       peer, peer);
        return proxies.client(peer, forwarded);
    }

    /// Refuses bad framing; "" when the request may go on.
    static std::pair<int, std::string> framingProblem(const HttpRequest& req,
                                                      std::size_t maxFields) {
        if (req.headers.size() > maxFields)
            return {431, fmt::format("{} header fields; at most {} are accepted",
                                     req.headers.size(), maxFields)};
        const auto te = req.headers.count("Transfer-Encoding");
        const auto cl = req.headers.count("Content-Length");
        if (te > 0 && cl > 0)
            return {400, "a request with both Content-Length and Transfer-Encoding is refused "
                         "(RFC 9112 §6.1)"};
        if (te > 1 || cl > 1) return {400, "a repeated Content-Length or Transfer-Encoding"};
        if (te == 1) {
            std::string v = req.header("Transfer-Encoding");
            std::transform(v.begin(), v.end(), v.begin(),
                           [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
            if (v != "chunked")
                return {400, "Transfer-Encoding '" + req.header("Transfer-Encoding") +
                                 "': only 'chunked' is accepted"};
        }
        return {0, {}};
    }

    /// Counts the request, sets the security headers, refuses bad framing, applies the rate
    /// limit and checks the token of API requests; false when the request is answered already.
    bool admit(const HttpRequest& req, HttpAnswer& res) {
        ++requests;
        securityHeaders(res);
        if (const auto [status, why] = framingProblem(req, options.maxHeaderFields); status) {
            ++refused;
            sendJson(res, status, {{"error", why}});
            return false;
        }
        // The page and its assets are static, embedded and served without the study: no rate
        // limit (the connection caps bound what one address can hold).
        if (!touchesStudy(req)) return true;
        const std::string token = bearer(req);
        const bool knownToken = !token.empty() && isKnown(token);
        // A real invitation has its own bucket; anything else shares its address's.
        const std::string key = knownToken ? "t:" + token : "a:" + addressKey(clientAddress(req));
        if (!limiter.allow(key)) {
            ++rateLimited;
            res.headers.emplace_back("Retry-After", "1");
            sendJson(res, 429, {{"error", "too many requests; retry in a second"}});
            return false;
        }
        if (knownToken) return true;
        bool real = false;
        if (plausibleToken(token)) {
            if (!guarded(req, res, [&] { real = study.isInvitation(token); })) return false;
        }
        if (!real) {
            ++refused;
            sendJson(res, 403,
                     {{"error", "this link is not valid (unknown or mistyped token); please use "
                                "the exact link you received"}});
            return false;
        }
        std::lock_guard lock(knownMutex);
        known.insert(token);
        return true;
    }

    /// Runs `body`, mapping refusals and errors to their status and a JSON message.
    bool guarded(const HttpRequest& req, HttpAnswer& res, const std::function<void()>& body) {
        try {
            body();
            return true;
        } catch (const ApiError& e) {
            ++refused;
            if (e.retryAfter > 0)
                res.headers.emplace_back("Retry-After", std::to_string(e.retryAfter));
            sendJson(res, e.status, {{"error", e.what()}});
        } catch (const experiment::StoreError& e) {
            ++refused;
            sendJson(res, 422, {{"error", e.what()}});
        } catch (const std::exception& e) {
            ++refused;
            fmt::print(stderr, "serve: {} {}: {}\n", req.method, req.path, e.what());
            sendJson(res, 500, {{"error", "internal error; the request was not stored"}});
        }
        return false;
    }

    /// Runs one API call: parses the body, maps errors to status codes.
    void api(const HttpRequest& req, HttpAnswer& res,
             const std::function<json(const std::string& token, const json& body)>& call) {
        json body = json::object();
        if (!req.body.empty()) {
            body = json::parse(req.body, nullptr, false);
            if (body.is_discarded() || !body.is_object()) {
                ++refused;
                sendJson(res, 400, {{"error", "the request body is not a JSON object"}});
                return;
            }
            if (const std::string problem = numberProblem(body); !problem.empty()) {
                ++refused;
                sendJson(res, 400, {{"error", req.path + ": " + problem}});
                return;
            }
        }
        guarded(req, res, [&] { sendJson(res, 200, call(bearer(req), body)); });
    }

    void asset(const std::string& name, HttpAnswer& res) {
        const Asset* a = findAsset(name);
        if (!a) {
            sendJson(res, 404, {{"error", errorText(404)}});
            return;
        }
        res.headers.emplace_back("Cache-Control", "no-cache");
        res.contentType = a->contentType;
        res.body.assign(reinterpret_cast<const char*>(a->data), a->size);
    }

    void route(const HttpRequest& req, HttpAnswer& res) {
        const bool get = req.method == "GET" || req.method == "HEAD";
        const bool post = req.method == "POST";
        const std::string& p = req.path;
        const std::string assetName = suffix(p, "/assets/", 64, [](unsigned char c) {
            return std::isalnum(c) || c == '_' || c == '.' || c == '-';
        });
        const std::string clipIndex =
            suffix(p, "/api/clip/", 6, [](unsigned char c) { return std::isdigit(c) != 0; });
        const std::string toneIndex = suffix(p, "/api/screening/tones/", 2,
                                             [](unsigned char c) { return std::isdigit(c) != 0; });
        if (get && p == "/") {
            res.contentType = "text/plain; charset=utf-8";
            res.body = "Underfoot online study. Please open the personal link you received.\n";
        } else if (get && p == "/p") {
            asset("index.html", res);
        } else if (get && !assetName.empty()) {
            // Embedded files only, looked up by exact name: no file system access, no listing.
            if (assetName == "index.html" || assetName.find("..") != std::string::npos)
                sendJson(res, 404, {{"error", errorText(404)}});
            else
                asset(assetName, res);
        } else if (get && p == "/api/state") {
            api(req, res, [this](const std::string& t, const json&) { return study.state(t); });
        } else if (post && p == "/api/client") {
            const std::string ua = req.header("User-Agent");
            api(req, res,
                [&](const std::string& t, const json& b) { return study.client(t, b, ua); });
        } else if (const auto call = post ? kPostCalls.find(p) : kPostCalls.end();
                   call != kPostCalls.end()) {
            api(req, res,
                [&](const std::string& t, const json& b) { return (study.*(call->second))(t, b); });
        } else if (get && !toneIndex.empty()) {
            // A triplet of the headphone check by its index only: nothing in the path, the
            // headers or a file name says which interval is the quiet one.
            std::string wav;
            if (!guarded(req, res,
                         [&] { wav = study.screeningTones(bearer(req), std::stoi(toneIndex)); }))
                return;
            res.headers.emplace_back("Cache-Control", "private, no-store");
            res.contentType = "audio/wav";
            res.body = std::move(wav);
        } else if (get && !clipIndex.empty()) {
            // The clip of the participant's current trial, by trial index (never by file name,
            // which would tell the answer; never a path from the request).
            ClipFile clip;
            if (!guarded(req, res, [&] { clip = study.clip(bearer(req), std::stoi(clipIndex)); }))
                return;
            res.headers.emplace_back("Cache-Control", "private, no-store");
            res.contentType = clip.contentType;
            res.clip = std::move(clip);
        } else {
            sendJson(res, 404, {{"error", errorText(404)}});
        }
    }
};

WebApi::WebApi(WebStudy& study, const ServerOptions& options)
    : impl_(std::make_unique<Impl>(study, options)) {}
WebApi::~WebApi() = default;

HttpAnswer WebApi::handle(const HttpRequest& request) {
    HttpAnswer res;
    if (!impl_->admit(request, res)) return res;
    if (request.body.size() > impl_->options.maxBodyBytes) {
        ++impl_->refused;
        return error(413);
    }
    impl_->route(request, res);
    return res;
}

bool WebApi::admitAsksStudy(const HttpRequest& request) const {
    if (!touchesStudy(request)) return false;
    const std::string token = bearer(request);
    return plausibleToken(token) && !impl_->isKnown(token);
}

bool WebApi::admit(const HttpRequest& request, HttpAnswer& answer) {
    return impl_->admit(request, answer);
}

void WebApi::route(const HttpRequest& request, HttpAnswer& answer) {
    impl_->route(request, answer);
}

ServerCounters WebApi::counters() const {
    ServerCounters c;
    c.requests = impl_->requests.load();
    c.refused = impl_->refused.load();
    c.rateLimited = impl_->rateLimited.load();
    return c;
}

} // namespace underfoot::web
