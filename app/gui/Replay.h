// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Re-rendering a stored trial for the Results view: app/wiring renderTrialReplay, the same
/// render as `underfoot replay` (stored stimulus, render seed, GRF or gait recording at the live
/// trial's rate and block size, soundscape mixed in). Runs on a worker thread; opens its own
/// connection to the study file.
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
                         const QString& output, double walkSeconds = 8.0);

} // namespace underfoot::gui
