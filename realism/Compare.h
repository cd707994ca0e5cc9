// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Comparing a surface's render with recordings, and the report (HTML with SVG pictures).
#include "engine/io/AudioFile.h"
#include "engine/surfaces/Surface.h"
#include "realism/Distance.h"
#include "realism/Listener.h"
#include "realism/Recordings.h"

#include <cstdint>
#include <optional>
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

/// A render as the listener hears it: `surface` (id or .toml) rendered as renderForComparison
/// does, its steps described with `o`, named `id` in source "synthetic" with the material of
/// surface `id` (materialOfSurface). Empty when the render holds no step.
std::optional<Example> renderExample(const std::string& id, const std::string& surface,
                                     const RenderSpec& spec, const AnalysisOptions& o);

struct SurfaceComparison {
    std::string surface, material;
    std::vector<std::string> realFiles;
    AnalysisOptions options; ///< with the shared band limit
    Comparison comparison;
    std::vector<StepDescriptors> syntheticSteps, realSteps;
    std::vector<float> syntheticExample, realExample; ///< one step of each, for pictures
    /// The room the recordings were heard through (the surface's own), if any.
    std::optional<engine::ReverbSpec> room;
};

/// A (dry) recording as it would sound in `room`: its channels mixed to mono, then the
/// renderer's mix of a surface with a [reverb], dry x gain_dry + the room's convolution x
/// gain_wet (stereo when the impulse response is), with the impulse response's length of silence
/// appended for the tail. The recording stands for the render's channel mean, whose two panned
/// voices are each at cos(panSpread pi / 4) of the plain sum the renderer feeds the room: the
/// room's input is scaled back by that factor, so that the channel mean of the result is the
/// channel mean the renderer would give (tested against the wood and wood-with-reverb renders).
/// The convolution runs at the recording's own rate (the impulse response resampled to it, as
/// the renderer does at its rate). Throws engine::FileError for an unreadable impulse response.
engine::AudioBuffer throughRoom(const engine::AudioBuffer& recording,
                                const engine::ReverbSpec& room);

/// Every recording's steps, in the recordings' order, each recording first heard through `room`
/// when one is given (throughRoom; the room's impulse response is read once for all of them).
/// Throws engine::FileError for an unreadable recording or impulse response.
std::vector<StepDescriptors> describeRecordings(const std::vector<Recording>& recordings,
                                                const AnalysisOptions& options,
                                                const std::optional<engine::ReverbSpec>& room);

/// The room a surface's render is heard in: its preset's [reverb], if it has one. Throws
/// engine::PresetError for a bad preset.
std::optional<engine::ReverbSpec> roomOfSurface(const std::string& surface);

/// Renders the surface and compares it with the recordings, on the band both share. With a
/// `room` (see roomOfSurface), every recording is first heard through it (throughRoom): a
/// surface rendered in a room is compared with recordings in the same room, since the shipped
/// recordings are dry; the room then weighs alike on every material.
/// Throws std::runtime_error when the recordings hold no step or the render none.
SurfaceComparison compareSurface(const std::string& surface, const std::vector<Recording>& real,
                                 const RenderSpec& spec,
                                 const std::optional<engine::ReverbSpec>& room = {});
/// The same with an already rendered buffer.
SurfaceComparison compareAudio(const std::string& surface, const engine::AudioBuffer& synthetic,
                               const std::vector<Recording>& real,
                               const std::optional<engine::ReverbSpec>& room = {});

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
