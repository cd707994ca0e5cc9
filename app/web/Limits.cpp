// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/web/Limits.h"

#include <arpa/inet.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <stdexcept>

namespace underfoot::web {

RateLimiter::RateLimiter(double rate, double burst, std::size_t capacity)
    : rate_(rate), burst_(burst), capacity_(std::max<std::size_t>(capacity, 1)) {}

bool RateLimiter::allow(const std::string& key, double now) {
    std::lock_guard lock(mutex_);
    auto it = index_.find(key);
    if (it == index_.end()) {
        if (index_.size() >= capacity_) { // evict the least recently used bucket, one only
            index_.erase(order_.back().key);
            order_.pop_back();
        }
        order_.push_front({key, burst_, now});
        it = index_.emplace(key, order_.begin()).first;
    } else {
        order_.splice(order_.begin(), order_, it->second);
        Bucket& b = *it->second;
        b.tokens = std::min(burst_, b.tokens + std::max(0.0, now - b.at) * rate_);
        b.at = now;
    }
    Bucket& b = *it->second;
    if (b.tokens < 1.0) return false;
    b.tokens -= 1.0;
    return true;
}

bool RateLimiter::allow(const std::string& key) {
    const double now =
        std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
    return allow(key, now);
}

std::size_t RateLimiter::size() const {
    std::lock_guard lock(mutex_);
    return index_.size();
}

bool RateLimiter::holds(const std::string& key) const {
    std::lock_guard lock(mutex_);
    return index_.count(key) != 0;
}

std::optional<std::string> canonicalAddress(std::string_view text) {
    // Trim spaces and tabs (X-Forwarded-For lists are "a, b").
    while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
    while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
    if (text.empty() || text.size() > INET6_ADDRSTRLEN) return std::nullopt;
    // "[v6]" as some proxies write it.
    if (text.front() == '[' && text.back() == ']') text = text.substr(1, text.size() - 2);
    const std::string s(text);
    char out[INET6_ADDRSTRLEN] = {};
    in_addr v4{};
    if (inet_pton(AF_INET, s.c_str(), &v4) == 1) {
        inet_ntop(AF_INET, &v4, out, sizeof out);
        return std::string(out);
    }
    in6_addr v6{};
    if (inet_pton(AF_INET6, s.c_str(), &v6) != 1) return std::nullopt;
    if (IN6_IS_ADDR_V4MAPPED(&v6)) {
        std::memcpy(&v4, &v6.s6_addr[12], 4);
        inet_ntop(AF_INET, &v4, out, sizeof out);
        return std::string(out);
    }
    inet_ntop(AF_INET6, &v6, out, sizeof out);
    return std::string(out);
}

std::string addressKey(const std::string& address) {
    in6_addr v6{};
    if (address.find(':') == std::string::npos || inet_pton(AF_INET6, address.c_str(), &v6) != 1)
        return address;
    std::memset(&v6.s6_addr[8], 0, 8);
    char out[INET6_ADDRSTRLEN] = {};
    inet_ntop(AF_INET6, &v6, out, sizeof out);
    return std::string(out) + "/64";
}

TrustedProxies::TrustedProxies(const std::vector<std::string>& addresses) {
    for (const auto& a : addresses) {
        const auto c = canonicalAddress(a);
        if (!c)
            throw std::invalid_argument(fmt::format(
                "--trusted-proxy '{}': not an IP address; expected the address the reverse "
                "proxy connects from, e.g. 127.0.0.1",
                a));
        addresses_.push_back(*c);
    }
}

bool TrustedProxies::trusts(const std::string& peer) const {
    return std::find(addresses_.begin(), addresses_.end(), peer) != addresses_.end();
}

std::string TrustedProxies::client(const std::string& peer,
                                   const std::vector<std::string>& forwardedFor) const {
    if (!trusts(peer)) return peer;
    // All entries, in order: several headers are one list (RFC 9110 §5.3).
    std::vector<std::string_view> entries;
    for (const auto& header : forwardedFor) {
        std::string_view rest = header;
        while (true) {
            const auto comma = rest.find(',');
            entries.push_back(rest.substr(0, comma));
            if (comma == std::string_view::npos) break;
            rest.remove_prefix(comma + 1);
        }
    }
    std::string client = peer;
    for (auto it = entries.rbegin(); it != entries.rend(); ++it) {
        const auto a = canonicalAddress(*it);
        if (!a) break;
        client = *a;
        if (!trusts(*a)) break;
    }
    return client;
}

namespace {
int hexValue(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}
} // namespace

std::optional<std::string> decodeTargetPath(std::string_view target) {
    if (target.empty() || target.front() != '/') return std::nullopt;
    target = target.substr(0, target.find_first_of("?#"));
    std::string out;
    out.reserve(target.size());
    for (std::size_t i = 0; i < target.size(); ++i) {
        char c = target[i];
        if (c == '%') {
            if (i + 2 >= target.size()) return std::nullopt;
            const int hi = hexValue(target[i + 1]), lo = hexValue(target[i + 2]);
            if (hi < 0 || lo < 0) return std::nullopt;
            c = static_cast<char>(hi * 16 + lo);
            i += 2;
        }
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return std::nullopt;
        out.push_back(c);
    }
    return out;
}

} // namespace underfoot::web
