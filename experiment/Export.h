// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// Long-format export (one row per trial) and its codebook.
///
/// Column order is a contract with analysis/ (which reads exactly these columns):
/// base/TrialColumns.h. RFC 4180 quoting, empty cell = missing, booleans 0/1, ISO 8601 UTC times.
#include "base/TrialColumns.h"
#include "experiment/Store.h"

#include <array>
#include <map>
#include <ostream>
#include <string_view>

namespace underfoot::experiment {

/// The columns of the long-format trials CSV, in order (the one list, base/TrialColumns.h).
using base::kTrialColumns;

/// Which trials are written.
enum class ExportScope { Answered, All };
/// Whether the rows of simulated participants (`underfoot session --simulate`) are written.
enum class SimulatedRows { Include, Exclude };

/// One CSV cell: RFC 4180 quoting and formula-leading text made inert (base/CsvCell.h).
std::string csvField(std::string_view value);

/// Writes the trials CSV; returns the number of rows.
int writeTrialsCsv(const StudyStore& store, std::ostream& out,
                   ExportScope scope = ExportScope::Answered,
                   SimulatedRows simulated = SimulatedRows::Include);
/// Writes every rating of every scale in long format (study, participant, group, trial_index,
/// stimulus_id, practice, excluded, one column per factor, scale, value); returns the rows.
int writeRatingsCsv(const StudyStore& store, std::ostream& out,
                    ExportScope scope = ExportScope::Answered,
                    SimulatedRows simulated = SimulatedRows::Include);
/// Writes one row per participant: participant, group, status, age, gender, shoes, hearing, then
/// one column per [[participant_fields]] item of the protocol (in protocol order); returns rows.
int writeParticipantsCsv(const StudyStore& store, std::ostream& out,
                         SimulatedRows simulated = SimulatedRows::Include);
/// Writes the protocol's scales: scale, prompt, min, max, anchors ("value=label; ..."),
/// stimuli (space-separated; empty = every stimulus); returns rows.
int writeScalesCsv(const StudyStore& store, std::ostream& out);
/// The columns of the audio CSV (one row per started trial), in order.
inline constexpr std::array<std::string_view, 21> kAudioColumns = {"study",
                                                                   "participant",
                                                                   "trial_index",
                                                                   "stimulus_id",
                                                                   "session",
                                                                   "answered",
                                                                   "excluded",
                                                                   "sample_rate_hz",
                                                                   "block_size",
                                                                   "frames",
                                                                   "xruns",
                                                                   "average_load_percent",
                                                                   "max_load_percent",
                                                                   "max_block_ms",
                                                                   "dropped_grf_frames",
                                                                   "grf_recording",
                                                                   "sensor_log",
                                                                   "interruptions",
                                                                   "interruption_reason",
                                                                   "started_at",
                                                                   "answered_at"};
/// Writes the audio CSV: per started trial, what the audio engine measured while its stimulus
/// played last (rate, block size, frames, xruns, loads, worst block, dropped GRF frames; empty
/// for players without a live output), its recordings and its sensor-fault interruptions.
/// Kept apart from trials.csv, whose columns are a contract with analysis/. Returns the rows.
int writeAudioCsv(const StudyStore& store, std::ostream& out,
                  ExportScope scope = ExportScope::Answered);
/// Writes the codebook (Markdown): every column, its type and meaning, and the value labels
/// (answer options, groups, stimuli, scales) of this study's protocol.
void writeCodebook(const StudyStore& store, std::ostream& out);

/// What people read for each stimulus id of a protocol: its label; the id when it has none; when
/// several stimuli share a label (those of one
/// [[factorial]]), the label with the stimulus's factor levels ("synthesized wading (algorithm
/// v1, cadence 27)"), or with the id when the levels do not tell them apart.
std::map<std::string, std::string> stimulusDisplayLabels(const Protocol& protocol);

} // namespace underfoot::experiment
