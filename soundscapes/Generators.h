// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Procedural sound generators of the soundscapes: the catalogue (names, kinds, parameters with
/// defaults and ranges, one-line descriptions) and the two real-time interfaces.
///
/// A *bed* generator renders a continuous stereo texture (sea, wind, traffic, babble...). An
/// *event voice* renders one mono event (a gull's series of calls, a dog's barks...) from
/// `start()` until it returns fewer frames than asked. Both are deterministic from their seeds,
/// allocate only in `prepare()`, and never throw, lock or allocate in `process()`.
#include "engine/dsp/ProcessSpec.h"
#include "engine/dsp/Random.h"

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace underfoot::soundscapes {

/// Continuous texture or scheduled events.
enum class LayerKind { Bed, Event };

/// One numeric parameter of a generator.
struct ParamInfo {
    std::string name;
    double defaultValue = 0.0;
    double minValue = 0.0;
    double maxValue = 0.0;
    std::string description;
};

/// What the catalogue says about one generator.
struct GeneratorInfo {
    std::string name;
    LayerKind kind = LayerKind::Bed;
    std::string description; ///< the synthesis model, in one or two sentences
    std::vector<ParamInfo> params;
};

/// Every procedural generator, sorted by name.
const std::vector<GeneratorInfo>& generatorCatalogue();
/// The generator of that name, or nullptr.
const GeneratorInfo* findGenerator(std::string_view name);

/// Resolved parameter values of one generator (defaults filled in by the definition loader).
class ParamSet {
  public:
    /// Sets a value (no validation: the loader checks names and ranges against the catalogue).
    void set(const std::string& name, double value) { values_[name] = value; }
    /// The value of a parameter; the default from the catalogue when it was never set.
    double get(std::string_view name) const;
    /// Attaches the generator whose defaults `get` falls back to.
    void setGenerator(const GeneratorInfo* info) { info_ = info; }
    const std::map<std::string, double, std::less<>>& values() const { return values_; }

  private:
    std::map<std::string, double, std::less<>> values_;
    const GeneratorInfo* info_ = nullptr;
};

/// A continuous stereo texture.
class BedGenerator {
  public:
    virtual ~BedGenerator() = default;
    /// Allocates whatever the generator needs for this rate and block size.
    virtual void prepare(const engine::ProcessSpec& spec) = 0;
    /// Restarts deterministically from a seed.
    virtual void reset(std::uint64_t seed) noexcept = 0;
    /// Writes (not adds) n frames to left and right.
    virtual void process(float* left, float* right, int n) noexcept = 0;
};

/// One mono event at a time (a voice of an event layer).
class EventVoice {
  public:
    virtual ~EventVoice() = default;
    /// Allocates whatever the voice needs for this rate and block size.
    virtual void prepare(const engine::ProcessSpec& spec) = 0;
    /// Restarts deterministically: `layerSeed` is shared by the voices of one layer (e.g. the
    /// repertoire of the songbirds of a forest), so voices sound like one population;
    /// `voiceSeed` seeds this voice's own noise.
    virtual void reset(std::uint64_t layerSeed, std::uint64_t voiceSeed) noexcept = 0;
    /// Begins a new event; its random choices are drawn from `rng`.
    virtual void start(engine::Random& rng) noexcept = 0;
    /// Writes up to n frames of the current event; returns how many were written (fewer than n
    /// when the event ended inside this block, 0 when it had already ended).
    virtual int process(float* out, int n) noexcept = 0;
};

/// Makes a bed generator (name must be a Bed entry of the catalogue; std::invalid_argument
/// otherwise).
std::unique_ptr<BedGenerator> makeBedGenerator(std::string_view name, const ParamSet& params);
/// Makes an event voice (name must be an Event entry of the catalogue; std::invalid_argument
/// otherwise).
std::unique_ptr<EventVoice> makeEventVoice(std::string_view name, const ParamSet& params);

} // namespace underfoot::soundscapes
