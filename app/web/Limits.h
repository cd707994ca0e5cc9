// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Request limits of `underfoot serve` that do not depend on the HTTP library: token-bucket
/// rate limits kept in a bounded table evicted least-recently-used, the client address behind
/// trusted reverse proxies (the rightmost untrusted X-Forwarded-For entry, as RFC 7239 §5.2
/// and nginx's realip module read it), and the decoding of a request target into the path the
/// router sees (RFC 3986 §2.1 percent-encoding).
#include <cstddef>
#include <list>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace underfoot::web {

/// Token buckets (`rate` tokens per second, at most `burst`), one per key, in a table of at
/// most `capacity` keys: a new key beyond it evicts the least recently used one, never more.
/// Thread-safe.
class RateLimiter {
  public:
    RateLimiter(double rate, double burst, std::size_t capacity);
    /// Takes one token from `key`'s bucket at time `nowSeconds` (monotonic); false when empty.
    bool allow(const std::string& key, double nowSeconds);
    /// allow() at the steady clock's time.
    bool allow(const std::string& key);
    std::size_t size() const;
    /// Whether `key` has a bucket (tests).
    bool holds(const std::string& key) const;

  private:
    struct Bucket {
        std::string key;
        double tokens;
        double at;
    };
    double rate_, burst_;
    std::size_t capacity_;
    mutable std::mutex mutex_;
    /// Most recently used first.
    std::list<Bucket> order_;
    std::unordered_map<std::string, std::list<Bucket>::iterator> index_;
};

/// An IP address in its canonical text (IPv4 dotted, IPv6 RFC 5952; an IPv4-mapped IPv6
/// address as IPv4), or nullopt when `text` is not an address.
std::optional<std::string> canonicalAddress(std::string_view text);

/// The rate-limit key of a client address: the address itself for IPv4, its /64 prefix for
/// IPv6 (one subscriber's network; a single host can use any address in it).
std::string addressKey(const std::string& address);

/// The reverse proxies whose X-Forwarded-For is believed (`serve --trusted-proxy`).
class TrustedProxies {
  public:
    TrustedProxies() = default;
    /// Throws std::invalid_argument naming an entry that is not an IP address.
    explicit TrustedProxies(const std::vector<std::string>& addresses);
    bool empty() const { return addresses_.empty(); }
    bool trusts(const std::string& peer) const;
    /// The client's address: `peer` unless it is a trusted proxy; then the rightmost entry of
    /// the X-Forwarded-For values (in header order) that is not a trusted proxy. An entry that
    /// is not an address stops the walk: the last trusted hop is the client then.
    std::string client(const std::string& peer, const std::vector<std::string>& forwardedFor) const;

  private:
    std::vector<std::string> addresses_;
};

/// The path of a request target ("/api/clip/3?x=1" -> "/api/clip/3"), percent-decoded;
/// nullopt when the target is not an origin-form path, holds a malformed escape or decodes to
/// a control character (NUL included).
std::optional<std::string> decodeTargetPath(std::string_view target);

} // namespace underfoot::web
