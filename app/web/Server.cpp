// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/web/Server.h"

#include <fmt/format.h>
#include <httplib.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <mutex>
#include <unordered_map>

namespace underfoot::web {

namespace {

using nlohmann::json;

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

std::string bearer(const httplib::Request& req) {
    const std::string h = req.get_header_value("Authorization");
    constexpr std::string_view prefix = "Bearer ";
    if (h.size() > prefix.size() && h.compare(0, prefix.size(), prefix) == 0 && h.size() < 200)
        return h.substr(prefix.size());
    return {};
}

void securityHeaders(httplib::Response& res) {
    res.set_header("X-Content-Type-Options", "nosniff");
    res.set_header("Referrer-Policy", "no-referrer");
    res.set_header("X-Frame-Options", "DENY");
    res.set_header("Content-Security-Policy",
                   "default-src 'self'; script-src 'self'; style-src 'self'; img-src 'self' data:; "
                   "media-src 'self' blob:; connect-src 'self'; frame-ancestors 'none'");
}

void sendJson(httplib::Response& res, int status, const json& body) {
    res.status = status;
    res.set_header("Cache-Control", "no-store");
    res.set_content(body.dump(), "application/json; charset=utf-8");
}

} // namespace

struct WebServer::Impl {
    WebStudy& study;
    ServerOptions options;
    httplib::Server server;
    RateLimiter limiter;
    int port = -1;
    std::atomic<std::size_t> requests{0}, refused{0}, rateLimited{0};

    Impl(WebStudy& s, ServerOptions o)
        : study(s), options(std::move(o)), limiter(options.ratePerSecond, options.burst) {}

    /// Runs one API call: parses the body, maps errors to status codes.
    void api(const httplib::Request& req, httplib::Response& res,
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

    /// Runs `body`, mapping refusals and errors to their status and a JSON message.
    bool guarded(const httplib::Request& req, httplib::Response& res,
                 const std::function<void()>& body) {
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

    void routes() {
        server.set_payload_max_length(options.maxBodyBytes);
        server.new_task_queue = [n = options.threads] {
            return new httplib::ThreadPool(static_cast<std::size_t>(n));
        };
        server.set_read_timeout(10, 0);
        server.set_write_timeout(30, 0);
        server.set_keep_alive_timeout(5);
        server.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
            ++requests;
            securityHeaders(res);
            std::string key = bearer(req);
            if (key.size() != 43) key = "addr:" + req.remote_addr;
            if (!limiter.allow(key)) {
                ++rateLimited;
                res.set_header("Retry-After", "1");
                sendJson(res, 429, {{"error", "too many requests; retry in a second"}});
                return httplib::Server::HandlerResponse::Handled;
            }
            return httplib::Server::HandlerResponse::Unhandled;
        });
        server.set_error_handler([](const httplib::Request&, httplib::Response& res) {
            if (res.body.empty()) {
                const char* what = res.status == 413   ? "request too large"
                                   : res.status == 404 ? "not found"
                                                       : "bad request";
                sendJson(res, res.status, {{"error", what}});
            }
        });

        auto asset = [](const std::string& name, httplib::Response& res) {
            const Asset* a = findAsset(name);
            if (!a) {
                res.status = 404;
                return;
            }
            res.set_header("Cache-Control", "no-cache");
            res.set_content(reinterpret_cast<const char*>(a->data), a->size, a->contentType);
        };
        server.Get("/", [](const httplib::Request&, httplib::Response& res) {
            res.set_content("Underfoot online study. Please open the personal link you "
                            "received.\n",
                            "text/plain; charset=utf-8");
        });
        server.Get("/p", [asset](const httplib::Request&, httplib::Response& res) {
            asset("index.html", res);
        });
        // Embedded files only, looked up by exact name: no file system access, no listing.
        server.Get(R"(/assets/([A-Za-z0-9_.-]+))",
                   [asset](const httplib::Request& req, httplib::Response& res) {
                       const std::string name = req.matches[1];
                       if (name == "index.html" || name.find("..") != std::string::npos) {
                           res.status = 404;
                           return;
                       }
                       asset(name, res);
                   });

        server.Get("/api/state", [this](const httplib::Request& req, httplib::Response& res) {
            api(req, res, [this](const std::string& t, const json&) { return study.state(t); });
        });
        server.Post("/api/consent", [this](const httplib::Request& req, httplib::Response& res) {
            api(req, res,
                [this](const std::string& t, const json& b) { return study.consent(t, b); });
        });
        server.Post("/api/client", [this](const httplib::Request& req, httplib::Response& res) {
            const std::string ua = req.get_header_value("User-Agent");
            api(req, res,
                [&](const std::string& t, const json& b) { return study.client(t, b, ua); });
        });
        server.Post("/api/screening", [this](const httplib::Request& req, httplib::Response& res) {
            api(req, res,
                [this](const std::string& t, const json& b) { return study.screening(t, b); });
        });
        server.Post("/api/present", [this](const httplib::Request& req, httplib::Response& res) {
            api(req, res,
                [this](const std::string& t, const json& b) { return study.present(t, b); });
        });
        server.Post("/api/answer", [this](const httplib::Request& req, httplib::Response& res) {
            api(req, res,
                [this](const std::string& t, const json& b) { return study.answer(t, b); });
        });
        server.Post("/api/break", [this](const httplib::Request& req, httplib::Response& res) {
            api(req, res,
                [this](const std::string& t, const json& b) { return study.finishBreak(t, b); });
        });
        // The clip of the participant's current trial, by trial index (never by file name, which
        // would tell the answer; never a path from the request).
        server.Get(R"(/api/clip/([0-9]{1,6}))",
                   [this](const httplib::Request& req, httplib::Response& res) {
                       ClipFile clip;
                       if (!guarded(req, res, [&] {
                               clip = study.clip(bearer(req), std::stoi(req.matches[1]));
                           }))
                           return;
                       auto in = std::make_shared<std::ifstream>(clip.path, std::ios::binary);
                       if (!*in) {
                           sendJson(res, 404, {{"error", "clip: the file cannot be read"}});
                           return;
                       }
                       res.set_header("Cache-Control", "private, no-store");
                       res.set_content_provider(
                           static_cast<std::size_t>(clip.size), clip.contentType,
                           [in](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
                               char buf[64 * 1024];
                               in->seekg(static_cast<std::streamoff>(offset));
                               const std::size_t n = std::min(length, sizeof buf);
                               in->read(buf, static_cast<std::streamsize>(n));
                               const auto got = static_cast<std::size_t>(in->gcount());
                               if (got == 0) return false;
                               sink.write(buf, got);
                               return true;
                           });
                   });
    }
};

WebServer::WebServer(WebStudy& study, ServerOptions options)
    : impl_(std::make_unique<Impl>(study, std::move(options))) {
    impl_->routes();
}

WebServer::~WebServer() {
    stop();
}

int WebServer::bind() {
    const auto& o = impl_->options;
    if (o.port == 0) {
        impl_->port = impl_->server.bind_to_any_port(o.bind);
    } else if (impl_->server.bind_to_port(o.bind, o.port)) {
        impl_->port = o.port;
    }
    if (impl_->port <= 0)
        throw std::runtime_error(fmt::format("cannot listen on {}:{} (address in use, not an "
                                             "address of this machine, or a privileged port)",
                                             o.bind, o.port));
    return impl_->port;
}

void WebServer::run() {
    impl_->server.listen_after_bind();
}

void WebServer::stop() {
    if (impl_->server.is_running()) impl_->server.stop();
}

ServerCounters WebServer::counters() const {
    return {impl_->requests.load(), impl_->refused.load(), impl_->rateLimited.load()};
}

} // namespace underfoot::web
