// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/web/Server.h"

#include <fmt/format.h>
#include <httplib.h>

#include <fstream>

namespace underfoot::web {

namespace {

/// The request as WebApi sees it (the body only once httplib has read it).
HttpRequest toApi(const httplib::Request& req) {
    HttpRequest r;
    r.method = req.method;
    r.path = req.path;
    for (const auto& [name, value] : req.headers) r.headers.emplace(name, value);
    r.body = req.body;
    r.remoteAddr = req.remote_addr;
    return r;
}

void setHeaders(const HttpAnswer& a, httplib::Response& res) {
    for (const auto& [name, value] : a.headers) res.set_header(name, value);
}

void sendJson(httplib::Response& res, int status, const nlohmann::json& body) {
    res.status = status;
    res.set_header("Cache-Control", "no-store");
    res.set_content(body.dump(), "application/json; charset=utf-8");
}

/// Status, headers and body (or the clip file, streamed) of `a` into `res`.
void apply(const HttpAnswer& a, httplib::Response& res) {
    if (a.clip) {
        auto in = std::make_shared<std::ifstream>(a.clip->path, std::ios::binary);
        if (!*in) {
            sendJson(res, 404, {{"error", "clip: the file cannot be read"}});
            return;
        }
        res.status = a.status;
        setHeaders(a, res);
        res.set_content_provider(
            static_cast<std::size_t>(a.clip->size), a.clip->contentType,
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
        return;
    }
    res.status = a.status;
    setHeaders(a, res);
    if (!a.contentType.empty()) res.set_content(a.body, a.contentType);
}

} // namespace

struct WebServer::Impl {
    ServerOptions options;
    WebApi api;
    httplib::Server server;
    int port = -1;

    Impl(WebStudy& s, ServerOptions o) : options(std::move(o)), api(s, options) {}

    void routes() {
        server.set_payload_max_length(options.maxBodyBytes);
        server.new_task_queue = [n = options.threads] {
            return new httplib::ThreadPool(static_cast<std::size_t>(n));
        };
        server.set_read_timeout(10, 0);
        server.set_write_timeout(30, 0);
        server.set_keep_alive_timeout(5);
        // Before httplib reads the body: counters, security headers, rate limit (WebApi::admit).
        server.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
            HttpAnswer a;
            const bool admitted = api.admit(toApi(req), a);
            if (admitted) {
                setHeaders(a, res);
                return httplib::Server::HandlerResponse::Unhandled;
            }
            apply(a, res);
            return httplib::Server::HandlerResponse::Handled;
        });
        // What httplib refuses itself (413 too large, 400 malformed, 404 unknown method/path).
        server.set_error_handler([](const httplib::Request&, httplib::Response& res) {
            if (res.body.empty()) {
                const HttpAnswer e = WebApi::error(res.status);
                res.set_content(e.body, e.contentType);
                res.set_header("Cache-Control", "no-store");
            }
        });
        // Every GET/HEAD and POST goes to WebApi::route, which answers unknown paths with 404.
        auto handler = [this](const httplib::Request& req, httplib::Response& res) {
            HttpAnswer a;
            api.route(toApi(req), a);
            apply(a, res);
        };
        server.Get(".*", handler);
        server.Post(".*", handler);
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
    return impl_->api.counters();
}

} // namespace underfoot::web
