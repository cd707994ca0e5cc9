// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Comparing a surface's render with recordings, and the report (HTML with SVG pictures).
#include "engine/io/AudioFile.h"
#include "realism/Distance.h"
#include "realism/Recordings.h"

#include <cstdint>
#include <string>
#include <vector>

namespace underfoot::realism {

/// How the synthetic side is rendered: the virtual walker through the offline renderer.
struct RenderSpec {
    std::string walker = "cadence=100";
    double seconds = 10;
    std::uint64_t seed = 7;
    double rateHz = 48000;
};

/// Renders a surface (id or .toml) as `underfoot render` would. Throws on a bad surface.
engine::AudioBuffer renderForComparison(const std::string& surface, const RenderSpec& spec);

struct SurfaceComparison {
    std::string surface, material;
    std::vector<std::string> realFiles;
    AnalysisOptions options; ///< with the shared band limit
    Comparison comparison;
    std::vector<StepDescriptors> syntheticSteps, realSteps;
    std::vector<float> syntheticExample, realExample; ///< one step of each, for pictures
};

/// Renders the surface and compares it with the recordings, on the band both share.
/// Throws std::runtime_error when the recordings hold no step or the render none.
SurfaceComparison compareSurface(const std::string& surface, const std::vector<Recording>& real,
                                 const RenderSpec& spec);
/// The same with an already rendered buffer.
SurfaceComparison compareAudio(const std::string& surface, const engine::AudioBuffer& synthetic,
                               const std::vector<Recording>& real);

/// Third-octave profiles (median over steps) of both sides as an SVG line plot.
std::string bandPlotSvg(const SurfaceComparison& c);
/// A spectrogram of one step as an SVG (log frequency up to maxHz, 60 dB range).
std::string spectrogramSvg(const std::vector<float>& step, double fs, double maxHz,
                           const std::string& title);
/// The descriptor table as HTML.
std::string descriptorTableHtml(const SurfaceComparison& c);
/// The descriptor table as plain text (for the terminal).
std::string descriptorTableText(const SurfaceComparison& c);

} // namespace underfoot::realism
