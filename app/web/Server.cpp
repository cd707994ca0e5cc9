// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/web/Server.h"

#include "app/web/Limits.h"

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/thread_pool.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <fmt/format.h>
#include <sys/resource.h>

#include <array>
#include <atomic>
#include <chrono>
#include <mutex>
#include <optional>
#include <thread>
#include <unordered_map>
#include <vector>

namespace underfoot::web {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = asio::ip::tcp;
using boost::system::error_code;
using SteadyClock = std::chrono::steady_clock;

namespace {

SteadyClock::duration seconds(double s) {
    return std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(s));
}

/// The peer's address as text (an IPv4-mapped IPv6 peer as IPv4), "" when unknown.
std::string peerAddress(const tcp::socket& socket) {
    error_code ec;
    const tcp::endpoint ep = socket.remote_endpoint(ec);
    if (ec) return {};
    return canonicalAddress(ep.address().to_string()).value_or(ep.address().to_string());
}

/// After a refusal whose body was not read: bytes read and dropped before the socket closes,
/// and for how long, so that the client reads the answer instead of a reset (RFC 9112 §9.6).
constexpr std::size_t kLingerBytes = 64 * 1024;
constexpr double kLingerSeconds = 1.0;

} // namespace

struct WebServer::Impl {
    ServerOptions options;
    WebApi api;
    TrustedProxies proxies;
    // Connection accounting; declared before the io_context, whose destruction ends the
    // connections still queued in it.
    std::mutex connectionsMutex;
    std::size_t open = 0;
    std::unordered_map<std::string, std::size_t> perAddress;
    std::atomic<std::size_t> connectionsRefused{0}, timedOut{0}, httpRefused{0};
    asio::io_context ioc;
    tcp::acceptor acceptor{ioc};
    asio::steady_timer acceptRetry{ioc};
    // Declared last: joined and destroyed first (its queued calls hold connections).
    asio::thread_pool workers;
    int port = -1;

    Impl(WebStudy& s, ServerOptions o)
        : options(std::move(o)), api(s, options), proxies(options.trustedProxies),
          workers(static_cast<std::size_t>(std::max(1, options.threads))) {}
    ~Impl() {
        ioc.stop();
        workers.stop();
        workers.join();
    }

    /// Counts a new connection; false when a cap is reached.
    bool claim(const std::string& peer) {
        std::lock_guard lock(connectionsMutex);
        if (open >= options.maxConnections) return false;
        if (!proxies.trusts(peer)) {
            std::size_t& n = perAddress[addressKey(peer)];
            if (n >= options.maxConnectionsPerAddress) return false;
            ++n;
        }
        ++open;
        return true;
    }
    void release(const std::string& peer) {
        std::lock_guard lock(connectionsMutex);
        --open;
        if (proxies.trusts(peer)) return;
        const auto it = perAddress.find(addressKey(peer));
        if (it != perAddress.end() && --it->second == 0) perAddress.erase(it);
    }

    void accept();
};

namespace {

/// One client connection: requests one after the other (keep-alive), each read with a
/// deadline for its header and body, checked by WebApi::admit before its body is read.
class Connection : public std::enable_shared_from_this<Connection> {
  public:
    Connection(WebServer::Impl& server, tcp::socket socket, std::string peer)
        : server_(server), stream_(std::move(socket)), peer_(std::move(peer)),
          buffer_(server.options.maxHeaderBytes + server.options.maxBodyBytes + 8192) {
        // Answers go out as header and body writes: no Nagle delay between them.
        error_code ignored;
        stream_.socket().set_option(tcp::no_delay(true), ignored);
    }
    ~Connection() { server_.release(peer_); }

    void start() { awaitRequest(); }

  private:
    const ServerOptions& options() const { return server_.options; }

    /// Waits (idle timeout) for the first byte of the next request.
    void awaitRequest() {
        if (buffer_.size() > 0) { // pipelined: the next request is here already
            readHeader();
            return;
        }
        stream_.expires_after(seconds(options().idleTimeoutS));
        stream_.async_read_some(buffer_.prepare(4096),
                                [self = shared_from_this()](error_code ec, std::size_t n) {
                                    if (ec) return; // idle timeout, closed or reset: done
                                    self->buffer_.commit(n);
                                    self->readHeader();
                                });
    }

    /// Reads the header; the request's deadline starts at its first byte.
    void readHeader() {
        deadline_ = SteadyClock::now() + seconds(options().requestTimeoutS);
        request_ = HttpRequest{}; // nothing of the previous request on this connection
        parser_.emplace();
        parser_->header_limit(static_cast<std::uint32_t>(options().maxHeaderBytes));
        parser_->body_limit(static_cast<std::uint64_t>(options().maxBodyBytes));
        stream_.expires_at(deadline_);
        http::async_read_header(
            stream_, buffer_, *parser_,
            [self = shared_from_this()](error_code ec, std::size_t) { self->onHeader(ec); });
    }

    void onHeader(error_code ec) {
        if (ec) return failed(ec);
        const auto& m = parser_->get();
        answer_ = HttpAnswer{};
        request_.method = std::string(m.method_string());
        request_.remoteAddr = peer_;
        for (const auto& f : m)
            request_.headers.emplace(std::string(f.name_string()), std::string(f.value()));
        const auto path = decodeTargetPath(std::string_view(m.target().data(), m.target().size()));
        if (!path) return refuse(400);
        request_.path = *path;
        if (!server_.api.admitAsksStudy(request_))
            return admitted(server_.api.admit(request_, answer_));
        // A token seen for the first time is looked up in the study (blocking): on a worker.
        // The time it waits there is the server's, not the client's: it does not count
        // against the deadline.
        const auto queued = SteadyClock::now();
        asio::post(server_.workers, [self = shared_from_this(), queued] {
            const bool ok = self->server_.api.admit(self->request_, self->answer_);
            const auto spent = SteadyClock::now() - queued;
            asio::post(self->stream_.get_executor(), [self, ok, spent] {
                self->deadline_ += spent;
                self->admitted(ok);
            });
        });
    }

    void admitted(bool ok) {
        if (!ok) return send(std::move(answer_), true); // the body stays unread: close after
        if (parser_->is_done()) return onBody({});
        const auto& m = parser_->get();
        if (m.version() >= 11 && beast::iequals(m[http::field::expect], "100-continue")) {
            auto cont = std::make_shared<http::response<http::empty_body>>(http::status::continue_,
                                                                           m.version());
            stream_.expires_at(deadline_);
            http::async_write(stream_, *cont,
                              [self = shared_from_this(), cont](error_code e, std::size_t) {
                                  if (e) return self->failed(e);
                                  self->readBody();
                              });
            return;
        }
        readBody();
    }

    void readBody() {
        stream_.expires_at(deadline_);
        http::async_read(
            stream_, buffer_, *parser_,
            [self = shared_from_this()](error_code ec, std::size_t) { self->onBody(ec); });
    }

    void onBody(error_code ec) {
        if (ec) return failed(ec);
        request_.body = std::move(parser_->get().body());
        if (!WebApi::touchesStudy(request_)) {
            server_.api.route(request_, answer_);
            return send(std::move(answer_), false);
        }
        asio::post(server_.workers, [self = shared_from_this()] {
            self->server_.api.route(self->request_, self->answer_);
            asio::post(self->stream_.get_executor(),
                       [self] { self->send(std::move(self->answer_), false); });
        });
    }

    /// A read that ended early: a timeout (the stream has closed the socket), the client gone,
    /// or a request the parser refused (answered, then closed).
    void failed(error_code ec) {
        if (ec == beast::error::timeout) {
            ++server_.timedOut;
            return;
        }
        if (ec == http::error::end_of_stream || ec == asio::error::eof ||
            ec == asio::error::connection_reset || ec == asio::error::broken_pipe ||
            ec == asio::error::operation_aborted)
            return;
        const bool header = !parser_ || !parser_->is_header_done();
        if (ec == http::error::header_limit || (ec == http::error::buffer_overflow && header))
            return refuse(431);
        if (ec == http::error::body_limit || ec == http::error::buffer_overflow) return refuse(413);
        refuse(400);
    }

    void refuse(int status) {
        ++server_.httpRefused;
        send(WebApi::error(status), true);
    }

    /// Writes `a`, then waits for the next request or closes.
    void send(HttpAnswer a, bool close) {
        const bool head = request_.method == "HEAD";
        const unsigned version =
            parser_ && parser_->is_header_done() ? parser_->get().version() : 11;
        const bool keepAlive =
            !close && parser_ && parser_->is_header_done() && parser_->keep_alive();
        auto fill = [&](auto& res) {
            res.result(static_cast<unsigned>(a.status));
            res.version(version);
            for (const auto& [name, value] : a.headers) res.insert(name, value);
            if (!a.contentType.empty()) res.set(http::field::content_type, a.contentType);
            res.keep_alive(keepAlive);
        };
        if (a.clip) {
            http::file_body::value_type file;
            error_code ec;
            file.open(a.clip->path.c_str(), beast::file_mode::scan, ec);
            if (ec) {
                a = WebApi::error(404);
                a.body = R"({"error":"clip: the file cannot be read"})";
            } else if (!head) {
                auto res = std::make_shared<http::response<http::file_body>>();
                fill(*res);
                res->body() = std::move(file);
                res->prepare_payload();
                return write(res, keepAlive);
            } else {
                auto res = std::make_shared<http::response<http::empty_body>>();
                fill(*res);
                res->content_length(file.size());
                return write(res, keepAlive);
            }
        }
        if (head) {
            auto res = std::make_shared<http::response<http::empty_body>>();
            fill(*res);
            res->content_length(a.body.size());
            return write(res, keepAlive);
        }
        auto res = std::make_shared<http::response<http::string_body>>();
        fill(*res);
        res->body() = std::move(a.body);
        res->prepare_payload();
        write(res, keepAlive);
    }

    template <class Message>
    void write(std::shared_ptr<Message> res, bool keepAlive) {
        stream_.expires_after(seconds(options().writeTimeoutS));
        http::async_write(stream_, *res,
                          [self = shared_from_this(), res, keepAlive](error_code ec, std::size_t) {
                              if (ec) return;
                              if (keepAlive)
                                  self->awaitRequest();
                              else
                                  self->linger();
                          });
    }

    /// Closes after an answer: the sending side first, then what the client still sends is
    /// read and dropped (bounded in bytes and time) so that it sees the answer, not a reset.
    void linger() {
        error_code ec;
        stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
        if (ec) return;
        discard_ = std::make_unique<std::array<char, 4096>>();
        stream_.expires_after(seconds(kLingerSeconds));
        drain();
    }
    void drain() {
        stream_.async_read_some(asio::buffer(*discard_),
                                [self = shared_from_this()](error_code ec, std::size_t n) {
                                    self->drained_ += n;
                                    if (!ec && self->drained_ < kLingerBytes) self->drain();
                                });
    }

    WebServer::Impl& server_;
    beast::tcp_stream stream_;
    std::string peer_;
    beast::flat_buffer buffer_;
    std::optional<http::request_parser<http::string_body>> parser_;
    SteadyClock::time_point deadline_;
    HttpRequest request_;
    HttpAnswer answer_;
    std::unique_ptr<std::array<char, 4096>> discard_;
    std::size_t drained_ = 0;
};

} // namespace

void WebServer::Impl::accept() {
    // Each connection on its own strand: its handlers never run at the same time, whichever
    // network thread runs them.
    acceptor.async_accept(asio::make_strand(ioc), [this](error_code ec, tcp::socket socket) {
        if (ec == asio::error::operation_aborted) return; // stopped
        if (ec) { // out of descriptors (EMFILE) or a connection gone before it was accepted
            acceptRetry.expires_after(std::chrono::milliseconds(50));
            acceptRetry.async_wait([this](error_code e) {
                if (!e) accept();
            });
            return;
        }
        const std::string peer = peerAddress(socket);
        if (peer.empty() || !claim(peer)) {
            ++connectionsRefused;
            error_code ignored;
            socket.close(ignored);
        } else {
            std::make_shared<Connection>(*this, std::move(socket), peer)->start();
        }
        accept();
    });
}

WebServer::WebServer(WebStudy& study, ServerOptions options)
    : impl_(std::make_unique<Impl>(study, std::move(options))) {}

WebServer::~WebServer() {
    stop();
}

int WebServer::bind() {
    auto& o = impl_->options;
    error_code ec;
    tcp::endpoint endpoint;
    const auto address = asio::ip::make_address(o.bind, ec);
    if (!ec) {
        endpoint = tcp::endpoint(address, static_cast<unsigned short>(o.port));
    } else { // a host name such as localhost
        tcp::resolver resolver(impl_->ioc);
        const auto found = resolver.resolve(o.bind, std::to_string(o.port), ec);
        if (!ec && !found.empty()) endpoint = found.begin()->endpoint();
    }
    auto& acc = impl_->acceptor;
    if (!ec) acc.open(endpoint.protocol(), ec);
    if (!ec) acc.set_option(asio::socket_base::reuse_address(true), ec);
    if (!ec) acc.bind(endpoint, ec);
    if (!ec) acc.listen(asio::socket_base::max_listen_connections, ec);
    if (ec)
        throw std::runtime_error(fmt::format("cannot listen on {}:{}: {} (address in use, not an "
                                             "address of this machine, or a privileged port)",
                                             o.bind, o.port, ec.message()));
    impl_->port = acc.local_endpoint().port();
    // Each connection is a descriptor: raise the soft limit towards the hard one, and keep the
    // cap under what the process may open (the study, clips and logs need a few).
    rlimit files{};
    if (::getrlimit(RLIMIT_NOFILE, &files) == 0) {
        const rlim_t want = static_cast<rlim_t>(o.maxConnections) + 256;
        if (files.rlim_cur < want && files.rlim_cur != RLIM_INFINITY) {
            files.rlim_cur = std::min(want, files.rlim_max);
            ::setrlimit(RLIMIT_NOFILE, &files);
            ::getrlimit(RLIMIT_NOFILE, &files);
        }
        if (files.rlim_cur != RLIM_INFINITY && files.rlim_cur < want)
            o.maxConnections =
                files.rlim_cur > 320 ? static_cast<std::size_t>(files.rlim_cur - 256) : 64;
    }
    return impl_->port;
}

void WebServer::run() {
    impl_->accept();
    std::vector<std::thread> more;
    for (int i = 1; i < impl_->options.ioThreads; ++i)
        more.emplace_back([this] { impl_->ioc.run(); });
    impl_->ioc.run();
    for (auto& t : more) t.join();
    // Calls into the study still running end before run() returns (the caller then closes the
    // study's sessions); queued ones are dropped with their connections.
    impl_->workers.stop();
    impl_->workers.join();
}

void WebServer::stop() {
    impl_->ioc.stop();
}

ServerCounters WebServer::counters() const {
    ServerCounters c = impl_->api.counters();
    c.refused += impl_->httpRefused.load();
    c.connectionsRefused = impl_->connectionsRefused.load();
    c.timedOut = impl_->timedOut.load();
    return c;
}

} // namespace underfoot::web
