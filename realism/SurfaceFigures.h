// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The figures a surface's realism is judged by, per surface and render seed, in one table
/// (`underfoot compare --figures`, docs/explanation/realism.md, "The current result"):
///  - the nested listener (Listener.h, heardWithoutEachSource): for every recording source S
///    that recorded the surface's material, whether a listener
///    trained without S hears the render in its category and as its material, beside how that
///    listener hears S's own recordings of the material (heldOutRecordings): the bar a render
///    faithful to S's recordings can reach;
///  - the distance (Distance.h) to the recordings of its own material and to the nearest other
///    material's, exactly as `underfoot compare --all` computes them (a surface with a room is
///    compared with recordings heard through that room);
///  - spectral flatness and centroid of the render (median over its steps) against the
///    recordings of its material (median and quartiles), the descriptors with their noise floor;
///  - the cost of the render: CPU time per rendered frame in this run (walker, layers, room,
///    limiter), a figure to compare within one run, not across machines.
#include "realism/Compare.h"
#include "realism/Distance.h"
#include "realism/Listener.h"
#include "realism/Recordings.h"

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace underfoot::realism {

/// A surface to judge: an id or preset file, the material its recordings have ("" when none)
/// and its category ("solid", "aggregate", "liquid").
struct SurfaceUnderTest {
    std::string surface, material, category;
};

/// Every bundled surface (engine::listSurfaces) with its material and category.
std::vector<SurfaceUnderTest> bundledSurfaces();

/// How one held-out source heard one render.
struct HeldOutVerdict {
    std::string source, heard;
    bool scored = false;     ///< the source recorded the surface's material: counted in the figures
    JudgedCounts recordings; ///< the source's own recordings of the material, same listener
};

struct SurfaceFigures {
    std::string surface, material, category;
    std::uint64_t seed = 0;
    /// Nested listener: the held-out sources that recorded the material, and of those how many
    /// heard the render in its category, as its material (as `compare --listener` counts them: a
    /// source that alone recorded the material counts, though its listener cannot name it).
    int sources = 0, categoryRight = 0, materialRight = 0;
    std::vector<HeldOutVerdict> heardWithout; ///< every held-out source, in source order
    /// Distance to the own material's recordings; nearest other material and its distance.
    /// Left at 0 (hasRecordings false) without recordings of the material.
    bool hasRecordings = false;
    double ownDistance = 0, nearestOtherDistance = 0;
    std::string nearestOther;
    DescriptorComparison flatness, centroid; ///< against the own material's recordings
    double nanosecondsPerFrame = 0;          ///< CPU time of the render (this run)
};

struct SurfaceFiguresOptions {
    RenderSpec spec; ///< walker, length, rate (the seed is each of seeds)
    std::vector<std::uint64_t> seeds{3, 7, 11};
    bool dryRecordings = false; ///< compare surfaces with a room with the dry recordings
    ListenerOptions listener;
};

/// The figures of every surface for every seed (seed-major, surfaces in the given order).
/// `recordings` need two sources or more. Throws std::invalid_argument for no surface, no seed
/// or fewer than two sources, engine::FileError for an unreadable recording, engine::PresetError
/// for a bad preset.
std::vector<SurfaceFigures> surfaceFigures(const std::vector<SurfaceUnderTest>& surfaces,
                                           const std::vector<Recording>& recordings,
                                           const SurfaceFiguresOptions& options);

/// Per surface (index into `surfaces`), how the held-out sources heard it: `heard[S][i]` is the
/// material source S's listener heard in render i (heardWithoutEachSource); `recorded[S]` the
/// materials S recorded. Fills surface, material, category, sources, categoryRight,
/// materialRight and heardWithout of out[i] (out holds one element per surface).
void scoreNested(const std::vector<SurfaceUnderTest>& surfaces,
                 const std::map<std::string, std::vector<std::string>>& heard,
                 const std::map<std::string, std::set<std::string>>& recorded,
                 std::vector<SurfaceFigures>& out);

/// Fills heardWithout[].recordings of every scored verdict from heldOutRecordings' counts.
void addHeldOutRecordings(const std::map<std::string, std::map<std::string, JudgedCounts>>& own,
                          std::vector<SurfaceFigures>& figures);

/// One surface's nested verdicts over every seed, per held-out source that recorded its material.
struct HeldOutOverSeeds {
    std::string source;
    int seeds = 0, seedsInCategory = 0; ///< renders of the surface this source's listener judged
    JudgedCounts recordings;            ///< the source's own recordings of the material
    /// The render is heard in its category at least as often (as a share) as the recordings.
    bool atLeastAsOftenAsRecordings() const {
        return std::int64_t(seedsInCategory) * recordings.files >=
               std::int64_t(recordings.categoryRight) * seeds;
    }
};

struct SurfaceOverSeeds {
    std::string surface;
    std::vector<HeldOutOverSeeds> sources;   ///< empty: no source recorded the material
    bool alwaysInCategory() const;           ///< every source, every seed
    bool atLeastAsOftenAsRecordings() const; ///< for every source
};

/// The surfaces of `figures` (any number of seeds each), in order of first appearance.
std::vector<SurfaceOverSeeds> overSeeds(const std::vector<SurfaceFigures>& figures);

} // namespace underfoot::realism
