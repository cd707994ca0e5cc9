// SPDX-License-Identifier: GPL-3.0-or-later
// `underfoot serve` behind a reverse proxy, as docs/howto/online-test.md sets it up: a small
// forwarding proxy in the test (each client connection forwarded on its own connection from
// 127.0.0.1, X-Forwarded-For appended as nginx's $proxy_add_x_forwarded_for does), 64
// participants from 64 loopback addresses opening their links at the same moment.
#include "RawSocket.h"
#include "ServeProcess.h"

#include <gtest/gtest.h>

#include <mutex>

namespace underfoot::web::test {
namespace {

using Clock = std::chrono::steady_clock;

class ForwardingProxy {
  public:
    explicit ForwardingProxy(int upstreamPort) : upstream_(upstreamPort) {
        listen_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
        sockaddr_in a{};
        a.sin_family = AF_INET;
        ::inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
        socklen_t len = sizeof a;
        if (::bind(listen_, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
            ::listen(listen_, 256) != 0 ||
            ::getsockname(listen_, reinterpret_cast<sockaddr*>(&a), &len) != 0)
            throw std::runtime_error("proxy: cannot listen");
        port_ = ntohs(a.sin_port);
        acceptor_ = std::thread([this] { acceptLoop(); });
    }
    ~ForwardingProxy() {
        stop_ = true;
        acceptor_.join();
        ::close(listen_);
        std::lock_guard lock(mutex_);
        for (auto& t : relays_) t.join();
    }
    int port() const { return port_; }

  private:
    void acceptLoop() {
        while (!stop_) {
            pollfd p{listen_, POLLIN, 0};
            if (::poll(&p, 1, 100) != 1) continue;
            sockaddr_in peer{};
            socklen_t len = sizeof peer;
            const int client =
                ::accept4(listen_, reinterpret_cast<sockaddr*>(&peer), &len, SOCK_CLOEXEC);
            if (client < 0) continue;
            char addr[INET_ADDRSTRLEN] = {};
            ::inet_ntop(AF_INET, &peer.sin_addr, addr, sizeof addr);
            std::lock_guard lock(mutex_);
            relays_.emplace_back([this, client, a = std::string(addr)] { relay(client, a); });
        }
    }

    /// Forwards one client connection: its request head with X-Forwarded-For added, then the
    /// bytes both ways until both sides are done.
    void relay(int client, const std::string& clientAddr) {
        RawSocket up(upstream_, "127.0.0.1");
        std::string head;
        char buf[16384];
        const auto deadline = Clock::now() + std::chrono::seconds(10);
        while (up.ok() && head.find("\r\n\r\n") == std::string::npos && head.size() < 65536) {
            pollfd p{client, POLLIN, 0};
            if (::poll(&p, 1, pollMs(deadline)) != 1) break;
            const ssize_t n = ::recv(client, buf, sizeof buf, 0);
            if (n <= 0) break;
            head.append(buf, static_cast<std::size_t>(n));
        }
        const auto end = head.find("\r\n\r\n");
        if (!up.ok() || end == std::string::npos) {
            ::close(client);
            return;
        }
        head.insert(end + 2, "X-Forwarded-For: " + clientAddr + "\r\n");
        bool ok = up.send(head);
        bool clientOpen = true, upOpen = true;
        while (ok && (clientOpen || upOpen) && !stop_) {
            pollfd p[2] = {{client, static_cast<short>(clientOpen ? POLLIN : 0), 0},
                           {up.fd(), static_cast<short>(upOpen ? POLLIN : 0), 0}};
            if (::poll(p, 2, 100) <= 0) continue;
            if (p[0].revents) {
                const ssize_t n = ::recv(client, buf, sizeof buf, 0);
                if (n > 0) {
                    ok = up.send(std::string_view(buf, static_cast<std::size_t>(n)));
                } else {
                    clientOpen = false;
                    ::shutdown(up.fd(), SHUT_WR);
                }
            }
            if (p[1].revents) {
                const ssize_t n = ::recv(up.fd(), buf, sizeof buf, MSG_DONTWAIT);
                if (n > 0) {
                    ok = ::send(client, buf, static_cast<std::size_t>(n), MSG_NOSIGNAL) == n;
                } else if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK)) {
                    upOpen = false;
                    ::shutdown(client, SHUT_WR);
                }
            }
        }
        ::close(client);
    }

    int upstream_;
    int listen_ = -1;
    int port_ = 0;
    std::atomic<bool> stop_{false};
    std::thread acceptor_;
    std::mutex mutex_;
    std::vector<std::thread> relays_;
};

struct Start {
    int pageRefused = 0, apiRateLimited = 0, failed = 0, started = 0;
    double slowestStartS = 0;
};

/// 64 participants open their links at once through the proxy: the page and its two files,
/// the state, consent, client, screening, the first trial's clip, play and answer. With
/// `retry`, a 429 or a lost connection is tried again a second later, as the page does.
Start openAtOnce(const StudyFixture& f, int proxyPort, bool retry) {
    constexpr int n = 64;
    Start out;
    std::mutex mutex;
    std::atomic<int> ready{0};
    std::vector<std::thread> threads;
    for (int i = 0; i < n; ++i)
        threads.emplace_back([&, i] {
            ApiClient c(proxyPort, f.links[i].token, clientAddress(i));
            ++ready;
            while (ready.load() < n) std::this_thread::yield();
            const auto t0 = Clock::now();
            bool ok = true;
            auto call = [&](auto&& request, bool page) {
                for (int attempt = 0;; ++attempt) {
                    const Reply r = request();
                    {
                        std::lock_guard lock(mutex);
                        if (r.status == 429) (page ? out.pageRefused : out.apiRateLimited) += 1;
                    }
                    if (r.status == 200) return r;
                    if (!retry || attempt >= 30 || (r.status != 429 && r.status != 0)) {
                        ok = false;
                        return r;
                    }
                    std::this_thread::sleep_for(std::chrono::seconds(1));
                }
            };
            // The page and its files, as a browser asks for them: without the token (it
            // stays in the link's #fragment).
            for (const char* p : {"/p", "/assets/app.js", "/assets/style.css"})
                if (ok)
                    call([&] { return exchange(proxyPort, "GET", p, {}, "", clientAddress(i)); },
                         true);
            json state;
            if (ok) call([&] { return c.get("/api/state"); }, false);
            if (ok)
                call(
                    [&] {
                        return c.post(
                            "/api/consent",
                            {{"consent", true}, {"fields", {{"listening_device", "headphones"}}}});
                    },
                    false);
            if (ok) call([&] { return c.post("/api/client", {{"sampleRate", 48000}}); }, false);
            if (ok) state = call([&] { return doScreening(c); }, false).body;
            if (ok) {
                const int t = state["trial"]["index"];
                call([&] { return c.get("/api/clip/" + std::to_string(t)); }, false);
                if (ok) call([&] { return c.post("/api/present", {{"trial", t}}); }, false);
                if (ok)
                    call([&] { return c.post("/api/answer", validAnswer(state, "s1")); }, false);
            }
            std::lock_guard lock(mutex);
            (ok ? out.started : out.failed) += 1;
            out.slowestStartS = std::max(out.slowestStartS,
                                         std::chrono::duration<double>(Clock::now() - t0).count());
        });
    for (auto& t : threads) t.join();
    return out;
}

TEST(WebProxy, SixtyFourParticipantsOpeningTheirLinksAtOnceAllStart) {
    StudyFixture f(64);
    // A strict rate (5 per second, burst 15) so that a shared address could not pass 64 first
    // requests: only per-client addresses from X-Forwarded-For can.
    ServeProcess s(f, 0, {"--trusted-proxy", "127.0.0.1", "--rate", "5"});
    ForwardingProxy proxy(s.port());
    const Start st = openAtOnce(f, proxy.port(), false);
    std::printf("[figures] 64 at once behind the proxy, --trusted-proxy: %d started, %d failed, "
                "%d page requests and %d API requests refused with 429, slowest start %.2f s\n",
                st.started, st.failed, st.pageRefused, st.apiRateLimited, st.slowestStartS);
    EXPECT_EQ(st.started, 64);
    EXPECT_EQ(st.failed, 0);
    EXPECT_EQ(st.pageRefused, 0);
    EXPECT_EQ(st.apiRateLimited, 0);
}

TEST(WebProxy, WithoutTrustedProxyThePageIsServedAndEveryoneStartsOnRetries) {
    StudyFixture f(64);
    ServeProcess s(f, 0, {"--rate", "5"});
    ForwardingProxy proxy(s.port());
    const Start st = openAtOnce(f, proxy.port(), true);
    std::printf("[figures] 64 at once behind the proxy, no --trusted-proxy: %d started, %d "
                "failed, %d page requests and %d API requests refused with 429, slowest start "
                "%.2f s\n",
                st.started, st.failed, st.pageRefused, st.apiRateLimited, st.slowestStartS);
    EXPECT_EQ(st.started, 64);
    EXPECT_EQ(st.pageRefused, 0);
    // Everyone's first API request shares 127.0.0.1's bucket (burst 15): the rest wait.
    EXPECT_GT(st.apiRateLimited, 0);
}

} // namespace
} // namespace underfoot::web::test
