// SPDX-License-Identifier: GPL-3.0-or-later
#include "experiment/HeadphoneCheck.h"

#include "experiment/Random.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace underfoot::experiment {

namespace {

constexpr double kToneHz = 200.0;
constexpr double kLevel = 0.1;        // peak of the loud tones (full scale = 1)
constexpr double kQuietGain = 0.5012; // -6 dB
constexpr double kRampSeconds = 0.1;  // raised linear on/off ramps

int toneFrames() {
    return static_cast<int>(
        std::lround(HeadphoneCheck::kToneSeconds * HeadphoneCheck::kSampleRateHz));
}
int gapFrames() {
    return static_cast<int>(
        std::lround(HeadphoneCheck::kGapSeconds * HeadphoneCheck::kSampleRateHz));
}

void put16(std::string& out, std::uint16_t v) {
    out.push_back(static_cast<char>(v & 0xff));
    out.push_back(static_cast<char>(v >> 8));
}
void put32(std::string& out, std::uint32_t v) {
    put16(out, static_cast<std::uint16_t>(v & 0xffff));
    put16(out, static_cast<std::uint16_t>(v >> 16));
}

} // namespace

int HeadphoneCheck::tripletFrames() {
    return 3 * toneFrames() + 2 * gapFrames();
}

double HeadphoneCheck::tripletSeconds() {
    return static_cast<double>(tripletFrames()) / kSampleRateHz;
}

std::vector<HeadphoneCheck::Triplet> HeadphoneCheck::layout(std::uint64_t seed, int triplets) {
    Rng rng(seed);
    std::vector<Triplet> out;
    for (int i = 0; i < triplets; ++i) {
        Triplet t;
        t.quiet = static_cast<int>(rng.below(3));
        const int other = static_cast<int>(rng.below(2));
        // The antiphase tone is one of the two loud ones.
        t.antiphase = (t.quiet + 1 + other) % 3;
        out.push_back(t);
    }
    return out;
}

std::vector<std::int16_t> HeadphoneCheck::render(const Triplet& t) {
    const int tone = toneFrames();
    const int gap = gapFrames();
    const int ramp = static_cast<int>(std::lround(kRampSeconds * kSampleRateHz));
    std::vector<std::int16_t> out(static_cast<std::size_t>(tripletFrames()) * 2, 0);
    for (int k = 0; k < 3; ++k) {
        const double level = k == t.quiet ? kLevel * kQuietGain : kLevel;
        const double sign = k == t.antiphase ? -1.0 : 1.0;
        const std::size_t start =
            static_cast<std::size_t>(k) * static_cast<std::size_t>(tone + gap);
        for (int i = 0; i < tone; ++i) {
            const double env = std::min(
                {1.0, static_cast<double>(i) / ramp, static_cast<double>(tone - 1 - i) / ramp});
            const double v =
                level * env * std::sin(2.0 * std::numbers::pi * kToneHz * i / kSampleRateHz);
            const auto s = static_cast<std::int16_t>(std::lround(v * 32767.0));
            const std::size_t f = (start + static_cast<std::size_t>(i)) * 2;
            out[f] = s;
            out[f + 1] = static_cast<std::int16_t>(std::lround(sign * v * 32767.0));
        }
    }
    return out;
}

std::string HeadphoneCheck::wav(const Triplet& t) {
    const std::vector<std::int16_t> pcm = render(t);
    const auto dataBytes = static_cast<std::uint32_t>(pcm.size() * 2);
    std::string out;
    out.reserve(44 + dataBytes);
    out += "RIFF";
    put32(out, 36 + dataBytes);
    out += "WAVEfmt ";
    put32(out, 16);
    put16(out, 1); // PCM
    put16(out, 2); // stereo
    put32(out, kSampleRateHz);
    put32(out, kSampleRateHz * 4);
    put16(out, 4);
    put16(out, 16);
    out += "data";
    put32(out, dataBytes);
    for (const std::int16_t s : pcm) put16(out, static_cast<std::uint16_t>(s));
    return out;
}

HeadphoneCheck::HeadphoneCheck(std::uint64_t seed, double minResponseSeconds)
    : seed_(seed), minResponse_(minResponseSeconds), layout_(layout(seed)) {}

std::optional<std::string> HeadphoneCheck::answer(int index, int choice,
                                                  std::optional<double> secondsSinceTones) {
    if (done()) return "every triplet is answered already";
    if (index != next())
        return fmt::format("triplet {} refused; the triplet waiting for an answer is {}", index,
                           next());
    if (choice < 1 || choice > 3)
        return fmt::format("choice {} refused; expected 1, 2 or 3", choice);
    if (!secondsSinceTones)
        return fmt::format("triplet {} refused; its tones were not fetched", index);
    if (*secondsSinceTones < minResponse_)
        return fmt::format("triplet {} refused; answered {:.2f} s after its tones were served, "
                           "expected at least {:.2f} s (the tones must be heard first)",
                           index, *secondsSinceTones, minResponse_);
    choices_.push_back(choice);
    return std::nullopt;
}

int HeadphoneCheck::correct() const {
    int n = 0;
    for (std::size_t i = 0; i < choices_.size(); ++i)
        if (choices_[i] - 1 == layout_[i].quiet) ++n;
    return n;
}

} // namespace underfoot::experiment
