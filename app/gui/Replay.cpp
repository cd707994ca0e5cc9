// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/Replay.h"

#include "app/wiring/Replay.h"

#include <QObject>

namespace underfoot::gui {

ReplayResult renderTrial(const QString& studyPath, const QString& participant, int trialIndex,
                         const QString& output, double walkSeconds) {
    ReplayResult result;
    try {
        wiring::ReplayRequest request;
        request.study = studyPath.toStdString();
        request.participant = participant.toStdString();
        request.trial = trialIndex;
        request.walkSeconds = walkSeconds;
        const wiring::ReplayRender r = wiring::renderTrialReplay(request);
        engine::writeAudioFile(output.toStdString(), r.audio, engine::SampleFormat::Float32);
        result.seconds = static_cast<double>(r.audio.frames()) / r.sampleRateHz;
        result.description = QString::fromStdString(r.description);
    } catch (const std::exception& e) {
        result.error = QString::fromStdString(e.what());
    }
    return result;
}

} // namespace underfoot::gui
