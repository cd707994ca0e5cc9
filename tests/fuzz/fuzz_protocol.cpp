// SPDX-License-Identifier: GPL-3.0-or-later
// Protocol TOML (experiment/Protocol.h: parseProtocol); refusal: ProtocolError naming the file.
#include "FuzzSupport.h"
#include "experiment/Protocol.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string name = "fuzz_protocol.toml";
    fuzz::expectReadOrRefusal<experiment::ProtocolError>(
        name, [&] { (void)experiment::parseProtocol(fuzz::text(data, size), name); });
    return 0;
}
