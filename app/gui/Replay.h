// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Re-rendering a stored trial (what `underfoot replay` does), for the Results view: the
/// stored stimulus, render seed and GRF recording (or the stimulus's virtual walker), with the
/// soundscape mixed in. Runs on a worker thread; opens its own connection to the study file.
#include <QString>

namespace underfoot::gui {

struct ReplayResult {
    QString error;       ///< empty on success; otherwise what went wrong and what to do
    QString description; ///< what was rendered (surface, soundscape, source, seed)
    double seconds = 0;  ///< length of the rendered audio
};

/// Renders trial `trialIndex` (0-based, as stored) of `participant` in `studyPath` into the WAV
/// file `output`; a walker-driven trial walks for `walkSeconds`.
ReplayResult renderTrial(const QString& studyPath, const QString& participant, int trialIndex,
                         const QString& output, double walkSeconds = 8.0,
                         double sampleRateHz = 48000.0);

} // namespace underfoot::gui
