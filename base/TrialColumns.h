// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The columns of the long-format trials CSV (`trials.csv` of `underfoot export`), in order: the
/// contract between the exporter that writes it (experiment/Export.cpp) and the analysis that
/// reads it (analysis/io/TrialCsv.cpp). Their meanings are in the codebook that `underfoot
/// export` writes beside the file (experiment::writeCodebook) and in docs/reference/codebook.md;
/// tests/experiment/test_export.cpp proves both list exactly these columns in this order.
#include <array>
#include <string_view>

namespace underfoot::base {

inline constexpr std::array<std::string_view, 36> kTrialColumns = {"study",
                                                                   "site",
                                                                   "protocol_id",
                                                                   "protocol_hash",
                                                                   "participant",
                                                                   "group",
                                                                   "session",
                                                                   "trial_index",
                                                                   "block",
                                                                   "practice",
                                                                   "stimulus_id",
                                                                   "surface",
                                                                   "soundscape",
                                                                   "modalities",
                                                                   "reverb",
                                                                   "repetition",
                                                                   "render_seed",
                                                                   "answer",
                                                                   "answer_label",
                                                                   "correct",
                                                                   "realism",
                                                                   "quality",
                                                                   "soundscape_answer",
                                                                   "soundscape_correct",
                                                                   "response_time_s",
                                                                   "excluded",
                                                                   "exclusion_reason",
                                                                   "comment",
                                                                   "started_at",
                                                                   "answered_at",
                                                                   "trial",
                                                                   "simulated",
                                                                   "clip_file",
                                                                   "clip_frames",
                                                                   "clip_rate",
                                                                   "clip_sha256"};

} // namespace underfoot::base
