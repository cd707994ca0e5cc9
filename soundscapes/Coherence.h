// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Which soundscape is coherent with which surface, and the incoherent pairings of a study
/// (Nordahl, Turchet & Serafin, IEEE TVCG 17(9), 2011, experiment 2), as data (soundscapes/data/coherence.toml):
///
/// ```toml
/// [[coherent]]
/// surface = "beach_sand"
/// soundscape = "beach_summer"
///
/// [[incoherent]]                   # the pairs the study used for group 3
/// surface = "beach_sand"
/// soundscapes = ["forest", "ski_slope"]
/// ```
/// A surface has at most one coherent soundscape (several surfaces may share one: deep and
/// frozen snow both belong on the ski slope); an incoherent soundscape is never the surface's
/// coherent one.
#include <optional>
#include <string>
#include <vector>

namespace underfoot::soundscapes {

/// One surface and its soundscapes.
struct CoherenceEntry {
    std::string surface;
    std::optional<std::string> coherent;
    std::vector<std::string> incoherent; ///< the study's incoherent soundscapes, in file order
};

class CoherenceTable {
  public:
    /// Reads a coherence file. Throws DefinitionError (file:line:column and what was expected).
    static CoherenceTable load(const std::string& path);
    /// Parses coherence text (`sourceName` appears in error messages).
    static CoherenceTable parse(const std::string& text, const std::string& sourceName);
    /// The table shipped in soundscapes/data/coherence.toml (read once; throws on a broken file).
    static const CoherenceTable& builtin();

    /// The coherent soundscape for a surface, if there is one.
    std::optional<std::string> coherentSoundscapeFor(const std::string& surface) const;
    /// The study's incoherent soundscapes for a surface (empty when none were declared).
    std::vector<std::string> incoherentSoundscapesFor(const std::string& surface) const;
    /// The surfaces for which a soundscape is the coherent one.
    std::vector<std::string> surfacesCoherentWith(const std::string& soundscape) const;
    /// True when the pair is declared coherent.
    bool isCoherent(const std::string& surface, const std::string& soundscape) const;
    /// Every soundscape id the table mentions (sorted, unique).
    std::vector<std::string> soundscapes() const;
    const std::vector<CoherenceEntry>& entries() const noexcept { return entries_; }

  private:
    const CoherenceEntry* find(const std::string& surface) const;
    std::vector<CoherenceEntry> entries_;
};

} // namespace underfoot::soundscapes
