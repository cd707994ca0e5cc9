// SPDX-License-Identifier: GPL-3.0-or-later
// Option values typed on the command line or stored in a protocol: the first line names the
// parser, the rest is its input.
//   walker\n<spec>            engine::WalkerParameters::parse (`--walker cadence=100,mass=70`);
//                             refusal: std::invalid_argument naming the walker spec
//   wading\n<key=value lines> engine::wadingOptionsFromParameters + validateWadingOptions (a
//                             protocol's `wading = { ... }`, `underfoot wade`); refusal:
//                             WadingOptionError naming the wading parameter or option
// Anything else: both parsers on the whole input.
#include "FuzzSupport.h"
#include "engine/control/VirtualWalker.h"
#include "engine/wading/Wading.h"

#include <map>

namespace {
void walker(const std::string& spec) {
    using namespace underfoot;
    underfoot::fuzz::expectReadOrRefusal<std::invalid_argument>("walker spec", [&] {
        const auto p = engine::WalkerParameters::parse(spec);
        // What parse accepts must pass validate and print back to the same parameters.
        p.validate();
        const auto again = engine::WalkerParameters::parse(p.toString());
        if (again.toString() != p.toString())
            fuzz::fail("walker spec does not round-trip: " + p.toString());
    });
}

void wading(const std::string& text) {
    using namespace underfoot;
    std::map<std::string, std::string> params;
    std::size_t pos = 0;
    while (pos < text.size()) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string::npos) end = text.size();
        const std::string line = text.substr(pos, end - pos);
        pos = end + 1;
        const std::size_t eq = line.find('=');
        if (eq == std::string::npos) continue;
        params[line.substr(0, eq)] = line.substr(eq + 1);
    }
    fuzz::expectReadOrRefusal<engine::WadingOptionError>("wading", [&] {
        const auto o = engine::wadingOptionsFromParameters(params);
        engine::validateWadingOptions(o);
    });
}
} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string input = underfoot::fuzz::text(data, size);
    const std::size_t nl = input.find('\n');
    const std::string head = input.substr(0, nl);
    const std::string rest = nl == std::string::npos ? std::string() : input.substr(nl + 1);
    if (head == "walker")
        walker(rest);
    else if (head == "wading")
        wading(rest);
    else {
        walker(input);
        wading(input);
    }
    return 0;
}
