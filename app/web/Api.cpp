// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/web/Api.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <functional>
#include <mutex>
#include <regex>
#include <unordered_map>

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

/// Token buckets per key (link token or address), bounded in number.
class RateLimiter {
  public:
    RateLimiter(double rate, double burst) : rate_(rate), burst_(burst) {}
    bool allow(const std::string& key) {
        const double now =
            std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
                .count();
        std::lock_guard lock(mutex_);
        if (buckets_.size() > 100000) buckets_.clear(); // bounded memory under a flood of keys
        auto [it, fresh] = buckets_.try_emplace(key, Bucket{burst_, now});
        Bucket& b = it->second;
        if (!fresh) b.tokens = std::min(burst_, b.tokens + (now - b.at) * rate_);
        b.at = now;
        if (b.tokens < 1.0) return false;
        b.tokens -= 1.0;
        return true;
    }

  private:
    struct Bucket {
        double tokens;
        double at;
    };
    double rate_, burst_;
    std::mutex mutex_;
    std::unordered_map<std::string, Bucket> buckets_;
};

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
    return status == 413 ? "request too large" : status == 404 ? "not found" : "bad request";
}

} // namespace

HttpAnswer WebApi::error(int status) {
    HttpAnswer a;
    sendJson(a, status, {{"error", errorText(status)}});
    return a;
}

struct WebApi::Impl {
    WebStudy& study;
    ServerOptions options;
    RateLimiter limiter;
    std::atomic<std::size_t> requests{0}, refused{0}, rateLimited{0};

    Impl(WebStudy& s, const ServerOptions& o)
        : study(s), options(o), limiter(options.ratePerSecond, options.burst) {}

    /// Counts the request, sets the security headers, applies the rate limit; false when the
    /// request is answered already (429).
    bool admit(const HttpRequest& req, HttpAnswer& res) {
        ++requests;
        securityHeaders(res);
        std::string key = bearer(req);
        if (key.size() != 43) key = "addr:" + req.remoteAddr;
        if (!limiter.allow(key)) {
            ++rateLimited;
            res.headers.emplace_back("Retry-After", "1");
            sendJson(res, 429, {{"error", "too many requests; retry in a second"}});
            return false;
        }
        return true;
    }

    /// Runs `body`, mapping refusals and errors to their status and a JSON message.
    bool guarded(const HttpRequest& req, HttpAnswer& res, const std::function<void()>& body) {
        try {
            body();
            return true;
        } catch (const ApiError& e) {
            ++refused;
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
        static const std::regex assetPath(R"(/assets/([A-Za-z0-9_.-]+))");
        static const std::regex clipPath(R"(/api/clip/([0-9]{1,6}))");
        const bool get = req.method == "GET" || req.method == "HEAD";
        const bool post = req.method == "POST";
        const std::string& p = req.path;
        std::smatch m;
        if (get && p == "/") {
            res.contentType = "text/plain; charset=utf-8";
            res.body = "Underfoot online study. Please open the personal link you received.\n";
        } else if (get && p == "/p") {
            asset("index.html", res);
        } else if (get && std::regex_match(p, m, assetPath)) {
            // Embedded files only, looked up by exact name: no file system access, no listing.
            const std::string name = m[1];
            if (name == "index.html" || name.find("..") != std::string::npos)
                sendJson(res, 404, {{"error", errorText(404)}});
            else
                asset(name, res);
        } else if (get && p == "/api/state") {
            api(req, res, [this](const std::string& t, const json&) { return study.state(t); });
        } else if (post && p == "/api/consent") {
            api(req, res,
                [this](const std::string& t, const json& b) { return study.consent(t, b); });
        } else if (post && p == "/api/client") {
            const std::string ua = req.header("User-Agent");
            api(req, res,
                [&](const std::string& t, const json& b) { return study.client(t, b, ua); });
        } else if (post && p == "/api/screening") {
            api(req, res,
                [this](const std::string& t, const json& b) { return study.screening(t, b); });
        } else if (post && p == "/api/present") {
            api(req, res,
                [this](const std::string& t, const json& b) { return study.present(t, b); });
        } else if (post && p == "/api/answer") {
            api(req, res,
                [this](const std::string& t, const json& b) { return study.answer(t, b); });
        } else if (post && p == "/api/break") {
            api(req, res,
                [this](const std::string& t, const json& b) { return study.finishBreak(t, b); });
        } else if (get && std::regex_match(p, m, clipPath)) {
            // The clip of the participant's current trial, by trial index (never by file name,
            // which would tell the answer; never a path from the request).
            ClipFile clip;
            if (!guarded(req, res, [&] { clip = study.clip(bearer(req), std::stoi(m[1].str())); }))
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
        HttpAnswer big = error(413);
        big.headers.insert(big.headers.begin(), res.headers.begin(), res.headers.end());
        return big;
    }
    impl_->route(request, res);
    return res;
}

bool WebApi::admit(const HttpRequest& request, HttpAnswer& answer) {
    return impl_->admit(request, answer);
}

void WebApi::route(const HttpRequest& request, HttpAnswer& answer) {
    impl_->route(request, answer);
}

ServerCounters WebApi::counters() const {
    return {impl_->requests.load(), impl_->refused.load(), impl_->rateLimited.load()};
}

} // namespace underfoot::web
