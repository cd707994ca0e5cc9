// SPDX-License-Identifier: GPL-3.0-or-later
// The request limits without a network (app/web/Limits.h): token buckets evicted least
// recently used one at a time, client addresses behind trusted proxies, request paths.
#include "app/web/Limits.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace underfoot::web {
namespace {

TEST(WebLimits, BucketAllowsTheBurstThenTheRate) {
    RateLimiter limiter(5.0, 10.0, 100);
    int allowed = 0;
    for (int i = 0; i < 30; ++i) allowed += limiter.allow("k", 100.0);
    EXPECT_EQ(allowed, 10);
    // 1 s later: 5 more tokens.
    allowed = 0;
    for (int i = 0; i < 30; ++i) allowed += limiter.allow("k", 101.0);
    EXPECT_EQ(allowed, 5);
    // Never more than the burst, however long the pause.
    allowed = 0;
    for (int i = 0; i < 30; ++i) allowed += limiter.allow("k", 10000.0);
    EXPECT_EQ(allowed, 10);
}

TEST(WebLimits, AFloodOfKeysEvictsTheLeastRecentlyUsedOnlyNeverAll) {
    RateLimiter limiter(1.0, 2.0, 1000);
    // An exhausted bucket that its owner keeps using.
    while (limiter.allow("victim", 0.0)) {
    }
    // 100,000 new keys (the old table was cleared at 100,000): the table stays at its
    // capacity, one eviction per new key; a key used within the last 999 keys survives.
    for (int i = 0; i < 100000; ++i) {
        limiter.allow("flood" + std::to_string(i), 0.0);
        EXPECT_LE(limiter.size(), 1000u);
        if (i % 500 == 0) {
            EXPECT_FALSE(limiter.allow("victim", 0.0)) << i;
        }
    }
    EXPECT_EQ(limiter.size(), 1000u);
    EXPECT_TRUE(limiter.holds("victim"));
    EXPECT_TRUE(limiter.holds("flood99999"));
    EXPECT_TRUE(limiter.holds("flood99001"));
    EXPECT_FALSE(limiter.holds("flood0"));
    // A bucket nobody uses goes, the oldest first.
    RateLimiter small(1.0, 1.0, 3);
    small.allow("a", 0.0);
    small.allow("b", 0.0);
    small.allow("c", 0.0);
    small.allow("a", 0.0); // a is now the most recent
    small.allow("d", 0.0); // evicts b
    EXPECT_TRUE(small.holds("a"));
    EXPECT_FALSE(small.holds("b"));
    EXPECT_TRUE(small.holds("c"));
    EXPECT_TRUE(small.holds("d"));
}

TEST(WebLimits, AddressesAreCanonicalAndIpv6IsKeyedByItsSlash64) {
    EXPECT_EQ(canonicalAddress("127.0.0.1"), "127.0.0.1");
    EXPECT_EQ(canonicalAddress(" 10.1.2.3 "), "10.1.2.3");
    EXPECT_EQ(canonicalAddress("::ffff:192.0.2.7"), "192.0.2.7");
    EXPECT_EQ(canonicalAddress("[2001:DB8::1]"), "2001:db8::1");
    EXPECT_EQ(canonicalAddress("2001:0db8:0000:0000:0000:0000:0000:0001"), "2001:db8::1");
    for (const char* bad : {"", "localhost", "1.2.3", "1.2.3.4.5", "256.1.1.1", "1.2.3.4:80", "::g",
                            "unknown", "_hidden"})
        EXPECT_FALSE(canonicalAddress(bad)) << bad;
    EXPECT_EQ(addressKey("192.0.2.7"), "192.0.2.7");
    EXPECT_EQ(addressKey("2001:db8:1:2:aaaa:bbbb:cccc:dddd"), "2001:db8:1:2::/64");
    EXPECT_EQ(addressKey("2001:db8:1:2::1"), addressKey("2001:db8:1:2:ffff::9"));
}

TEST(WebLimits, ForwardedForIsBelievedFromTrustedProxiesOnly) {
    const TrustedProxies none;
    EXPECT_EQ(none.client("127.0.0.1", {"203.0.113.9"}), "127.0.0.1");
    const TrustedProxies proxy({"127.0.0.1"});
    // From the proxy: the rightmost entry (the one the proxy appended).
    EXPECT_EQ(proxy.client("127.0.0.1", {"203.0.113.9"}), "203.0.113.9");
    EXPECT_EQ(proxy.client("127.0.0.1", {"198.51.100.1, 203.0.113.9"}), "203.0.113.9");
    // A client's own X-Forwarded-For is a lie the proxy keeps on the left; several headers are
    // one list.
    EXPECT_EQ(proxy.client("127.0.0.1", {"1.1.1.1", "203.0.113.9"}), "203.0.113.9");
    // Chained trusted proxies are skipped; garbage stops the walk at the last trusted hop.
    const TrustedProxies chain({"127.0.0.1", "10.0.0.2"});
    EXPECT_EQ(chain.client("127.0.0.1", {"203.0.113.9, 10.0.0.2"}), "203.0.113.9");
    EXPECT_EQ(chain.client("127.0.0.1", {"203.0.113.9, nonsense, 10.0.0.2"}), "10.0.0.2");
    EXPECT_EQ(proxy.client("127.0.0.1", {""}), "127.0.0.1");
    EXPECT_EQ(proxy.client("127.0.0.1", {}), "127.0.0.1");
    EXPECT_EQ(proxy.client("127.0.0.1", {"[2001:db8::5]"}), "2001:db8::5");
    // Not from the proxy: the header is ignored.
    EXPECT_EQ(proxy.client("198.51.100.7", {"203.0.113.9"}), "198.51.100.7");
    try {
        TrustedProxies bad({"proxy.example.org"});
        FAIL() << "a host name was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("--trusted-proxy 'proxy.example.org'"),
                  std::string::npos);
    }
}

TEST(WebLimits, RequestTargetsDecodeToPaths) {
    EXPECT_EQ(decodeTargetPath("/api/clip/3?x=1"), "/api/clip/3");
    EXPECT_EQ(decodeTargetPath("/p#frag"), "/p");
    EXPECT_EQ(decodeTargetPath("/assets/..%2F..%2Fetc"), "/assets/../../etc");
    EXPECT_EQ(decodeTargetPath("/%41%62"), "/Ab");
    for (const char* bad :
         {"", "*", "http://example.org/p", "p", "/%", "/%4", "/%zz", "/a%00", "/a%0a", "/a%7F"})
        EXPECT_FALSE(decodeTargetPath(bad)) << bad;
}

} // namespace
} // namespace underfoot::web
