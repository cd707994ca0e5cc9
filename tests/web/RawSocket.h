// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// Raw TCP connections for the web tests' attacks: bytes an HTTP client would never send
// (headers one line at a time, bodies without end, conflicting framing), from any loopback
// address, without blocking (every wait has a deadline).
#include <arpa/inet.h>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <optional>
#include <poll.h>
#include <string>
#include <string_view>
#include <sys/socket.h>
#include <unistd.h>

namespace underfoot::web::test {

using RawClock = std::chrono::steady_clock;

inline int pollMs(RawClock::time_point deadline) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - RawClock::now()).count();
    return left < 0 ? 0 : static_cast<int>(left);
}

class RawSocket {
  public:
    /// Connects from `source` to 127.0.0.1:`port` (ok() false when it could not within 2 s).
    RawSocket(int port, const std::string& source = "127.0.0.1") {
        fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
        if (fd_ < 0) return;
        sockaddr_in src{};
        src.sin_family = AF_INET;
        ::inet_pton(AF_INET, source.c_str(), &src.sin_addr);
        sockaddr_in dst{};
        dst.sin_family = AF_INET;
        dst.sin_port = htons(static_cast<std::uint16_t>(port));
        ::inet_pton(AF_INET, "127.0.0.1", &dst.sin_addr);
        if (::bind(fd_, reinterpret_cast<sockaddr*>(&src), sizeof src) != 0) {
            close();
            return;
        }
        if (::connect(fd_, reinterpret_cast<sockaddr*>(&dst), sizeof dst) != 0 &&
            errno != EINPROGRESS) {
            close();
            return;
        }
        pollfd p{fd_, POLLOUT, 0};
        int err = 0;
        socklen_t len = sizeof err;
        if (::poll(&p, 1, 2000) != 1 || ::getsockopt(fd_, SOL_SOCKET, SO_ERROR, &err, &len) != 0 ||
            err != 0)
            close();
    }
    ~RawSocket() { close(); }
    RawSocket(const RawSocket&) = delete;
    RawSocket& operator=(const RawSocket&) = delete;
    RawSocket(RawSocket&& o) noexcept : fd_(o.fd_) { o.fd_ = -1; }

    bool ok() const { return fd_ >= 0; }
    int fd() const { return fd_; }
    void close() {
        if (fd_ >= 0) ::close(fd_);
        fd_ = -1;
    }

    /// Sends all of `bytes`; false when the peer closed or they did not go out in time.
    bool send(std::string_view bytes, double timeoutS = 5.0) {
        const auto deadline = RawClock::now() + seconds(timeoutS);
        while (!bytes.empty()) {
            const ssize_t n = ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL);
            if (n > 0) {
                bytes.remove_prefix(static_cast<std::size_t>(n));
                continue;
            }
            if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) return false;
            pollfd p{fd_, POLLOUT, 0};
            if (::poll(&p, 1, pollMs(deadline)) != 1) return false;
        }
        return true;
    }

    /// Reads what arrives until the peer closes (EOF or reset) or `timeoutS` passes; `closed`
    /// tells which.
    std::string readUntilClosed(double timeoutS, bool* closed = nullptr) {
        const auto deadline = RawClock::now() + seconds(timeoutS);
        std::string out;
        char buf[4096];
        while (true) {
            const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
            if (n > 0) {
                out.append(buf, static_cast<std::size_t>(n));
                continue;
            }
            if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK)) {
                if (closed) *closed = true;
                return out;
            }
            pollfd p{fd_, POLLIN, 0};
            if (::poll(&p, 1, pollMs(deadline)) != 1) {
                if (closed) *closed = false;
                return out;
            }
        }
    }

    /// Sends `head`, then `bodyBytes` of body in pieces made by `piece(size)`, while reading
    /// what the server answers; stops when the server closed or stopped reading for
    /// `stallS`, or everything went out and an answer came. Returns the bytes of body sent.
    template <typename Piece>
    std::size_t stream(std::string_view head, std::size_t bodyBytes, Piece piece,
                       std::string& answer, double stallS = 2.0) {
        if (!send(head)) return 0;
        std::size_t sent = 0;
        std::string pending;
        std::size_t pieceBody = 0;
        auto lastProgress = RawClock::now();
        char buf[4096];
        while (true) {
            if (pending.empty() && sent < bodyBytes) {
                pieceBody = std::min<std::size_t>(64 * 1024, bodyBytes - sent);
                pending = piece(pieceBody);
            }
            pollfd p{fd_, static_cast<short>(POLLIN | (pending.empty() ? 0 : POLLOUT)), 0};
            if (::poll(&p, 1, 100) < 0) break;
            if (p.revents & (POLLIN | POLLHUP | POLLERR)) {
                const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
                if (n > 0) {
                    answer.append(buf, static_cast<std::size_t>(n));
                    lastProgress = RawClock::now();
                } else if (n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK)) {
                    break; // closed by the server
                }
            }
            if ((p.revents & POLLOUT) && !pending.empty()) {
                const ssize_t n = ::send(fd_, pending.data(), pending.size(), MSG_NOSIGNAL);
                if (n > 0) {
                    // Body bytes only (a chunk's framing counts as sent with its data).
                    pending.erase(0, static_cast<std::size_t>(n));
                    if (pending.empty()) sent += pieceBody;
                    lastProgress = RawClock::now();
                } else if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) {
                    answer += readUntilClosed(0.5);
                    break;
                }
            }
            if (pending.empty() && sent >= bodyBytes && !answer.empty()) break;
            if (RawClock::now() - lastProgress > seconds(stallS)) break;
        }
        return sent;
    }

  private:
    static RawClock::duration seconds(double s) {
        return std::chrono::duration_cast<RawClock::duration>(std::chrono::duration<double>(s));
    }
    int fd_ = -1;
};

/// The status code of the first answer in `text` (0 when there is none).
inline int statusOf(const std::string& text) {
    if (text.rfind("HTTP/1.", 0) != 0 || text.size() < 12) return 0;
    return std::atoi(text.c_str() + 9);
}

/// How many answers (status lines) `text` holds.
inline int answersIn(const std::string& text) {
    int n = 0;
    for (std::size_t at = text.find("HTTP/1."); at != std::string::npos;
         at = text.find("HTTP/1.", at + 1))
        n += at == 0 || text[at - 1] == '\n';
    return n;
}

} // namespace underfoot::web::test
