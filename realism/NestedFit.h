// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The nested estimate with refitted presets. A verdict of the listener (Listener.h) on renders
/// of presets fitted to the same recordings it was trained on is not evidence: the fit has seen
/// the test data. Here, for every recording source S, the presets are fitted again without S
/// (analysis by synthesis, Fit.h) and judged by a listener trained without S, so neither the
/// synthesis nor the judge has heard S (nested cross-validation, Varma and Simon 2006).
///
/// A preset is refitted for S only when S recorded its material and another source did too; a
/// preset of a material S did not record keeps its all-source fit (the shipped preset), since
/// its own recordings are the same without S (only the fit's contrast term, which pushes the
/// render away from other materials, saw S's recordings of those). A preset with a `base`
/// inherits its base's refit (it is rendered from a copy of the surfaces folder in which the
/// base is replaced). The refit starts from the shipped preset, whose knobs were themselves
/// fitted once; solids' modes are re-estimated from the remaining recordings (modal seed).
#include "realism/Fit.h"
#include "realism/Listener.h"

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace underfoot::realism {

/// `recordings` without those of `source`.
std::vector<Recording> withoutSource(const std::vector<Recording>& recordings,
                                     const std::string& source);

/// One fit of the nested estimate: `surface` fitted to `own` (its material's recordings
/// without `heldOut`), pushed away from `others` (every other material's, without `heldOut`).
struct RefitJob {
    std::string surface, material, heldOut;
    std::vector<Recording> own, others;
};

/// The fits the nested estimate needs, sorted by surface then held-out source: for every
/// (surface id, material) of `fittable` and every source of `recordings` that recorded the
/// material while another source did too, one job.
std::vector<RefitJob> refitJobs(const std::vector<std::pair<std::string, std::string>>& fittable,
                                const std::vector<Recording>& recordings);

/// The bundled surfaces that can be refitted: a recorded material and layers of their own (no
/// `base`), as (id, material), in listSurfaces order.
std::vector<std::pair<std::string, std::string>>
fittableSurfaces(const std::vector<Recording>& recordings);

struct NestedRefitOptions {
    FitOptions fit;    ///< each job's fit (ownMaterial and others are set per job)
    int threads = 1;   ///< fits run at once
    RenderSpec render; ///< the renders the listener judges
    ListenerOptions listener;
    /// Called (from the calling thread's workers, serialised) after each fit: fits done, total.
    std::function<void(std::size_t, std::size_t, const RefitJob&, const FitResult&)> progress;
};

struct NestedRefit {
    std::vector<RefitJob> jobs;
    std::vector<FitResult> fits;       ///< in job order
    std::vector<std::string> surfaces; ///< the surfaces judged (every bundled one with a step)
    /// heard[S][i]: the material heard in surfaces[i] rendered from the presets fitted without
    /// S, by a listener trained without S.
    std::map<std::string, std::vector<std::string>> heard;
};

/// Runs the nested estimate over `recordings` (two sources or more), whose listener examples
/// `examples` were described with `analysis`. Deterministic: every fit and render is seeded.
/// Throws as fitSurface and heardWithoutSource do.
NestedRefit nestedRefit(const std::vector<Recording>& recordings,
                        const std::vector<Example>& examples, const AnalysisOptions& analysis,
                        const NestedRefitOptions& options);

} // namespace underfoot::realism
