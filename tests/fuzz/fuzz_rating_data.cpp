// SPDX-License-Identifier: GPL-3.0-or-later
// The rating CSVs of `underfoot export` as `underfoot analyze` re-imports them
// (analysis/ratings/RatingData.h: parseRatingData): ratings, participants, scales. One input
// holds up to three files separated by lines `%%`; refusal: std::runtime_error naming one of them.
#include "FuzzSupport.h"
#include "analysis/ratings/RatingData.h"

#include <array>
#include <cmath>
#include <stdexcept>
#include <typeinfo>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string input = fuzz::text(data, size);
    std::array<std::string, 3> parts;
    std::size_t part = 0, pos = 0;
    while (pos <= input.size()) {
        std::size_t end = input.find('\n', pos);
        if (end == std::string::npos) end = input.size();
        const std::string_view line(input.data() + pos, end - pos);
        if (line == "%%" && part < 2)
            ++part;
        else
            parts[part].append(line).append(end < input.size() ? "\n" : "");
        pos = end + 1;
    }
    const std::array<std::string, 3> names = {"fuzz_ratings.csv", "fuzz_participants.csv",
                                              "fuzz_scales.csv"};
    try {
        const auto d =
            analysis::parseRatingData(parts[0], names[0], parts[1], names[1], parts[2], names[2]);
        for (const auto& o : d.ratings)
            if (!std::isfinite(o.value)) fuzz::fail("accepted a non-finite rating");
        for (const auto& s : d.scales)
            if (std::isnan(s.min) || std::isnan(s.max)) fuzz::fail("a scale range is NaN");
    } catch (const std::runtime_error& e) {
        const std::string what = e.what();
        bool named = false;
        for (const auto& n : names) named = named || what.find(n) != std::string::npos;
        if (!named) fuzz::fail("refusal does not name its file: " + what);
    } catch (const std::exception& e) {
        fuzz::fail(std::string("unexpected exception ") + typeid(e).name() + ": " + e.what());
    }
    return 0;
}
