// SPDX-License-Identifier: GPL-3.0-or-later
// The helpers of realism/Recordings.h that read audio. Kept apart from Recordings.cpp (the
// manifest and the material catalogue, plain text only) so that the manifest's fuzz target
// builds that file alone, without the descriptors, the fit and the modal estimate.
#include "realism/Recordings.h"

#include <algorithm>

namespace underfoot::realism {

std::vector<StepDescriptors> describeFile(const std::string& path, const AnalysisOptions& o) {
    return describeSteps(engine::readAudioFile(path), o);
}

double sharedMaxHz(const std::vector<Recording>& recordings, double otherRateHz) {
    double minRate = otherRateHz;
    for (const auto& r : recordings)
        minRate = std::min(minRate, engine::readAudioFile(r.path).sampleRateHz);
    return std::min(16000.0, 0.95 * 0.5 * minRate);
}

} // namespace underfoot::realism
