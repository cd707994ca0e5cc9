// SPDX-License-Identifier: GPL-3.0-or-later
// Any audio file libsndfile reads (engine/io/AudioFile.h: readAudioFile(path, 48000), the read
// and the resampling to the engine rate that lab clips, wading recordings, cooked envelopes and
// soundscape layers go through; the file has no extension, libsndfile goes by its bytes);
// refusal: FileError naming the file. Allocation and work are bounded by the documented limits.
#include "FuzzSupport.h"
#include "engine/io/AudioFile.h"

#include <cmath>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string path = fuzz::writeInput("audio", data, size);
    fuzz::expectReadOrRefusal<engine::FileError>(path, [&] {
        const auto audio = engine::readAudioFile(path, 48000.0);
        if (audio.sampleRateHz != 48000.0) fuzz::fail("not resampled to 48 kHz");
        for (float v : audio.samples)
            if (!std::isfinite(v)) fuzz::fail("a non-finite sample after resampling");
    });
    return 0;
}
