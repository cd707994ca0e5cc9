// SPDX-License-Identifier: GPL-3.0-or-later
#include "app/gui/Replay.h"

#include "app/gui/WalkerPlayer.h"
#include "engine/control/GrfFile.h"
#include "engine/render/Renderer.h"
#include "experiment/Store.h"
#include "soundscapes/Library.h"
#include "soundscapes/Renderer.h"

#include <QDir>
#include <QFileInfo>

#include <vector>

namespace underfoot::gui {

namespace eng = underfoot::engine;
namespace exp = underfoot::experiment;

ReplayResult renderTrial(const QString& studyPath, const QString& participant, int trialIndex,
                         const QString& output, double walkSeconds, double sampleRateHz) {
    ReplayResult result;
    try {
        const auto store = exp::StudyStore::open(studyPath.toStdString());
        const auto info = store.trialForReplay(participant.toStdString(), trialIndex);
        const auto& s = info.stimulus;
        eng::GrfSignal grf;
        QString source;
        if (info.grfRecording) {
            QString path = QString::fromStdString(*info.grfRecording);
            if (QFileInfo(path).isRelative()) path = QFileInfo(studyPath).dir().filePath(path);
            eng::GrfLoadOptions options;
            options.targetRateHz = sampleRateHz;
            grf = eng::loadGrfFile(path.toStdString(), options);
            source = QObject::tr("recorded GRF %1").arg(path);
        } else if (s.input.kind == exp::InputKind::Walker) {
            const auto walker = walkerParametersOf(s);
            grf = eng::walkerGrf(walker, walkSeconds, sampleRateHz, info.renderSeed);
            source =
                QObject::tr("virtual walker %1").arg(QString::fromStdString(walker.toString()));
        } else {
            result.error = QObject::tr("Trial %1 of %2 was driven by a live sensor and no GRF "
                                       "recording is stored for it, so what was heard cannot be "
                                       "re-rendered exactly.")
                               .arg(trialIndex + 1)
                               .arg(participant);
            return result;
        }
        eng::RenderOptions options;
        options.sampleRateHz = sampleRateHz;
        options.seed = info.renderSeed;
        options.tailSeconds = 1.0;
        if (s.reverb) options.scene.impulseResponse = *s.reverb;
        auto r = eng::renderSurface(s.surface, grf, options);
        if (s.soundscape) {
            soundscapes::SoundscapeRenderer ambience(soundscapes::loadSoundscape(*s.soundscape));
            ambience.prepare({sampleRateHz, 1024});
            ambience.reset(info.renderSeed);
            const std::size_t n = r.audio.frames();
            std::vector<float> l(n), rr(n);
            ambience.process(l.data(), rr.data(), static_cast<int>(n));
            for (std::size_t i = 0; i < n; ++i) {
                r.audio.samples[2 * i] += l[i];
                r.audio.samples[2 * i + 1] += rr[i];
            }
        }
        eng::writeAudioFile(output.toStdString(), r.audio, eng::SampleFormat::Float32);
        result.seconds = static_cast<double>(r.audio.frames()) / sampleRateHz;
        result.description =
            QObject::tr("%1 trial %2: %3%4 from %5, render seed %6")
                .arg(participant)
                .arg(trialIndex + 1)
                .arg(QString::fromStdString(s.surface),
                     s.soundscape ? " + " + QString::fromStdString(*s.soundscape) : QString(),
                     source)
                .arg(info.renderSeed);
    } catch (const std::exception& e) {
        result.error = QString::fromStdString(e.what());
    }
    return result;
}

} // namespace underfoot::gui
