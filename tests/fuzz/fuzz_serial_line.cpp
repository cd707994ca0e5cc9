// SPDX-License-Identifier: GPL-3.0-or-later
// The FSR shoes' serial line protocol (engine/io/sensors/ShoeProtocol.h): the input is a
// stream of lines, fed as the serial reader feeds them (over-long lines counted, not parsed).
// The parser never throws; a rejected line must come with a reason naming its line number.
#include "FuzzSupport.h"
#include "engine/io/sensors/ShoeProtocol.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string t = fuzz::text(data, size);
    engine::ShoeLineParser parser;
    try {
        std::size_t pos = 0;
        while (pos < t.size()) {
            const std::size_t eol = std::min(t.find('\n', pos), t.size());
            const std::string_view line(t.data() + pos, eol - pos);
            pos = eol + 1;
            if (line.size() > engine::kShoeMaxLineBytes) {
                parser.lineTooLong(line.size());
                continue;
            }
            engine::ShoeFrame frame;
            const auto kind = parser.parse(line, frame);
            if (kind == engine::ShoeLineKind::Rejected) {
                if (parser.error().find("line ") == std::string::npos)
                    fuzz::fail("rejection without a line number: " + parser.error());
            } else if (kind == engine::ShoeLineKind::Frame) {
                std::string why;
                (void)parser.gapBefore(frame.deviceMs, why);
            }
        }
    } catch (const std::exception& e) {
        fuzz::fail(std::string("the shoe line parser threw: ") + e.what());
    }
    return 0;
}
