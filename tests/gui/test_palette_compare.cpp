// SPDX-License-Identifier: GPL-3.0-or-later
// The sound palette's "compare with a recording" and "fit to recording", driven on
// Qt's offscreen platform. The "recordings" are renders written to temporary WAV files, so the
// expected answers are known: a surface against its own render is at distance ~0, against
// another surface's render far; the level of a recording does not matter; a parameter change
// recomputes the distance (stale results dropped: what is shown is the final settings'); a fit
// with a small budget reports its progress, is applied and saved with its [provenance]; Cancel
// stops it after the evaluation under way; missing or silent recordings give a clear message.
#include "app/gui/MainWindow.h"
#include "app/gui/PaletteCompare.h"
#include "app/gui/PaletteView.h"
#include "engine/io/AudioFile.h"
#include "engine/surfaces/Surface.h"
#include "realism/Compare.h"
#include "realism/Distance.h"
#include "realism/Recordings.h"

#include <QApplication>
#include <QDir>
#include <QFile>
#include <QProgressBar>
#include <QSignalSpy>
#include <QTemporaryDir>
#include <QTest>

#include <cmath>
#include <fstream>
#include <memory>

using namespace underfoot;

namespace {
constexpr double kSeconds = 3.0; // short renders keep the test within seconds

// Distance of a surface's render (id or .toml) to the reference's dry steps.
double dryDistance(const std::string& surface, const realism::RenderSpec& spec,
                   const gui::PaletteReference& ref) {
    const auto steps =
        realism::describeSteps(realism::renderForComparison(surface, spec), ref.options);
    return realism::compareSteps(steps, ref.steps).distance;
}

double directDistance(const QString& presetText, const realism::RenderSpec& spec,
                      const gui::PaletteReference& ref, const QString& scratch) {
    const std::string path = QDir(scratch).filePath("direct.toml").toStdString();
    std::ofstream(path) << presetText.toStdString();
    return dryDistance(path, spec, ref);
}
} // namespace

class PaletteCompareTest : public QObject {
    Q_OBJECT
    QTemporaryDir home_;
    QString woodWav_, woodQuietWav_, metalWav_, silentWav_;

    std::unique_ptr<gui::PaletteView> makePalette() {
        auto p = std::make_unique<gui::PaletteView>(home_.filePath("data"));
        p->resize(1280, 800);
        p->show();
        p->compareView()->setRenderSeconds(kSeconds);
        return p;
    }
    /// Waits for the reference to load and the first comparison after it.
    static bool useAndCompare(gui::PaletteCompare* c, const QStringList& files) {
        QSignalSpy compared(c, &gui::PaletteCompare::compared);
        if (!c->useFiles(files)) return false;
        return compared.wait(60000);
    }

  private slots:
    void initTestCase() {
        QVERIFY(home_.isValid());
        // The "recordings": renders with the palette's default walker and the compare's spec.
        gui::PaletteView probe(home_.filePath("data"));
        probe.compareView()->setRenderSeconds(kSeconds);
        const auto spec = probe.compareView()->renderSpec();
        QCOMPARE(QString::fromStdString(spec.walker),
                 QString::fromStdString(engine::WalkerParameters{}.toString()));
        auto wood = realism::renderForComparison("wood", spec);
        woodWav_ = home_.filePath("wood.wav");
        engine::writeAudioFile(woodWav_.toStdString(), wood, engine::SampleFormat::Float32);
        for (auto& s : wood.samples) s *= 0.1f; // -20 dB
        woodQuietWav_ = home_.filePath("wood_quiet.wav");
        engine::writeAudioFile(woodQuietWav_.toStdString(), wood, engine::SampleFormat::Float32);
        metalWav_ = home_.filePath("metal.wav");
        engine::writeAudioFile(metalWav_.toStdString(), realism::renderForComparison("metal", spec),
                               engine::SampleFormat::Float32);
        engine::AudioBuffer silence;
        silence.sampleRateHz = 48000;
        silence.channels = 1;
        silence.samples.assign(48000, 0.0f);
        silentWav_ = home_.filePath("silent.wav");
        engine::writeAudioFile(silentWav_.toStdString(), silence, engine::SampleFormat::Float32);
    }

    void distanceIsZeroAgainstItselfLevelInvariantAndLargerAgainstAnotherSurface() {
        auto palette = makePalette();
        QVERIFY(palette->selectSurface("wood"));
        auto* c = palette->compareView();
        QVERIFY(std::isnan(c->distance()));
        QVERIFY(useAndCompare(c, {woodWav_}));
        const double self = c->distance();
        qInfo("wood vs its own render: %.6f", self);
        QVERIFY2(self < 1e-9, qPrintable(c->distanceText())); // the same samples
        QVERIFY(c->distanceText().contains("Distance to the reference"));
        QVERIFY(!c->syntheticPlot()->spectrogram().empty());
        QVERIFY(!c->referencePlot()->spectrogram().empty());
        QVERIFY(c->referencePlot()->spectrogram().maxHz <= 16000);

        QVERIFY(useAndCompare(c, {woodQuietWav_})); // the same recording 20 dB quieter
        qInfo("wood vs its own render at -20 dB: %.6f", c->distance());
        QVERIFY(std::abs(c->distance() - self) < 1e-3);

        QVERIFY(useAndCompare(c, {metalWav_}));
        const double other = c->distance();
        qInfo("wood vs a metal render: %.3f", other);
        QVERIFY2(other > 0.5 && other > self + 0.4, qPrintable(c->distanceText()));
        QVERIFY(c->distanceText().contains("Distance to the reference"));
    }

    // Settings with a room: the reference is heard through it, as `underfoot compare` does. Wood
    // with reverb is wood's layers in the wooden room, so its render is the wood render (the
    // reference here) plus the room: in the room the distance is ~0, and the text says so.
    void aSurfaceWithARoomIsComparedWithTheReferenceInThatRoom() {
        auto palette = makePalette();
        QVERIFY(palette->selectSurface("wood_reverb"));
        auto* c = palette->compareView();
        QVERIFY(useAndCompare(c, {woodWav_}));
        const double inRoom = c->distance();
        qInfo("wood with reverb vs the wood render in its room: %.4f", inRoom);
        QVERIFY2(inRoom < 0.05, qPrintable(c->distanceText()));
        QVERIFY(c->distanceText().contains("wooden_room"));
        // A second comparison in the same room (the reference's steps in the room are reused):
        // a level change leaves the distance where it was.
        double gain = 0;
        for (const auto& p : engine::Surface::loadById("wood_reverb")->parameters())
            if (p.path == "gain_db") gain = p.value;
        QSignalSpy again(c, &gui::PaletteCompare::compared);
        QVERIFY(palette->setParameter("gain_db", gain - 6));
        QVERIFY(again.wait(60000));
        qInfo("in the room again, 6 dB quieter: %.4f", c->distance());
        QVERIFY(std::abs(c->distance() - inRoom) < 1e-3);
        QVERIFY(c->distanceText().contains("wooden_room"));
        // The same reference without a room: charged to the sound.
        const double dry = dryDistance("wood_reverb", c->renderSpec(), *c->reference());
        qInfo("wood with reverb vs the dry wood render: %.4f", dry);
        QVERIFY(dry > inRoom + 0.2);
    }

    void changingAParameterUpdatesTheDistanceAndStaleResultsAreDropped() {
        auto palette = makePalette();
        QVERIFY(palette->selectSurface("wood"));
        auto* c = palette->compareView();
        QVERIFY(useAndCompare(c, {metalWav_}));
        const double before = c->distance();
        const auto wood = engine::Surface::loadById("wood");
        QString t60, gain;
        for (const auto& p : wood->parameters()) {
            if (t60.isEmpty() && p.path.ends_with("t60_s")) t60 = QString::fromStdString(p.path);
            if (p.path == "gain_db") gain = QString::fromStdString(p.path);
        }
        QVERIFY(!t60.isEmpty() && !gain.isEmpty());
        double gainValue = 0;
        for (const auto& p : wood->parameters())
            if (p.path == "gain_db") gainValue = p.value;

        // Level only: the distance stays (every descriptor is level-invariant).
        QSignalSpy compared(c, &gui::PaletteCompare::compared);
        QVERIFY(palette->setParameter(gain, gainValue - 12));
        QVERIFY(compared.wait(60000));
        qInfo("gain -12 dB: %.6f (was %.6f)", c->distance(), before);
        QVERIFY(std::abs(c->distance() - before) < 1e-3);

        // The first mode rings 4x as long: the distance changes. A comparison started at once
        // and a second change while it runs: only the final settings' distance is shown.
        compared.clear();
        const auto* p0 = [&] {
            for (const auto& p : wood->parameters())
                if (QString::fromStdString(p.path) == t60) return &p;
            return static_cast<const engine::ParamInfo*>(nullptr);
        }();
        QVERIFY(palette->setParameter(t60, std::min(p0->maxValue, p0->value * 2)));
        c->compareNow();
        QVERIFY(palette->setParameter(t60, std::min(p0->maxValue, p0->value * 4)));
        QVERIFY(compared.wait(60000));
        QTest::qWait(700); // a stale result would arrive after the debounce
        QCOMPARE(compared.count(), 1);
        const double after = c->distance();
        qInfo("first mode's T60 x4: %.4f (was %.4f)", after, before);
        QVERIFY(std::abs(after - before) > 1e-3);
        const double expected = directDistance(palette->currentPresetText("check", "check"),
                                               c->renderSpec(), *c->reference(), home_.path());
        QVERIFY2(std::abs(after - expected) < 1e-9,
                 qPrintable(QString("%1 vs %2").arg(after).arg(expected)));
    }

    void fitReportsProgressAndIsAppliedAndSaved() {
        auto palette = makePalette();
        QVERIFY(palette->selectSurface("wood"));
        auto* c = palette->compareView();
        QVERIFY(useAndCompare(c, {metalWav_}));
        QSignalSpy progress(c, &gui::PaletteCompare::fitProgress);
        QSignalSpy finished(c, &gui::PaletteCompare::fitFinished);
        QVERIFY2(c->startFit(8), qPrintable(c->message()));
        QVERIFY(c->fitRunning());
        QVERIFY(!c->startFit(8)); // one fit at a time
        QVERIFY(finished.wait(120000));
        QVERIFY2(finished.front().front().toBool(), qPrintable(c->message()));
        QVERIFY(!progress.isEmpty());
        int last = 0;
        // A solid is refined from three starting points (its own modes, and its recorded modes
        // from the signal and from its first difference, realism/Fit.h): the budget is 8 per
        // start.
        const int budget = progress.front().at(1).toInt();
        QVERIFY(budget == 8 || budget == 24);
        for (const auto& args : progress) {
            QCOMPARE(args.at(1).toInt(), budget);
            QVERIFY(args.at(0).toInt() > last); // evaluation k of N, increasing
            last = args.at(0).toInt();
        }
        const auto& fit = *c->lastFit();
        QVERIFY(!fit.cancelled);
        QCOMPARE(fit.result.evaluations, last);
        QVERIFY(last <= budget);
        qInfo("fit wood to a metal render: %d evaluations, %.3f -> %.3f in %.1f s",
              fit.result.evaluations, fit.result.distanceBefore, fit.result.distanceAfter,
              fit.result.seconds);
        QVERIFY(std::abs(fit.result.distanceBefore - c->distance()) < 1e-6); // same render spec
        QVERIFY(fit.result.distanceAfter <= fit.result.distanceBefore + 1e-3);
        QVERIFY(fit.result.presetText.find("[provenance]") != std::string::npos);

        QSignalSpy compared(c, &gui::PaletteCompare::compared);
        QVERIFY2(c->applyFit(), qPrintable(c->message()));
        const auto fitted = engine::loadSurfaceFromString(fit.result.presetText, "fitted");
        const QString text = palette->currentPresetText("applied", "applied");
        const auto applied = engine::loadSurfaceFromString(text.toStdString(), "applied");
        QCOMPARE(applied->parameters().size(), fitted->parameters().size());
        for (std::size_t i = 0; i < fitted->parameters().size(); ++i) {
            const double want = fitted->parameters()[i].value, got = applied->parameters()[i].value;
            QVERIFY2(std::abs(got - want) <= 1e-3 * std::abs(want) + 1e-12,
                     qPrintable(QString::fromStdString(fitted->parameters()[i].path)));
        }
        QVERIFY(compared.wait(60000)); // the applied values are compared again
        qInfo("after applying: %.3f (fit reported %.3f)", c->distance(), fit.result.distanceAfter);
        QVERIFY(std::abs(c->distance() - fit.result.distanceAfter) < 0.05);

        const QString saved = home_.filePath("data/presets/wood_fitted.toml");
        QVERIFY2(c->saveFit(saved), qPrintable(c->message()));
        const auto loaded = engine::Surface::load(saved.toStdString());
        QCOMPARE(loaded->info().id, std::string("wood_fitted"));
        QFile f(saved);
        QVERIFY(f.open(QIODevice::ReadOnly));
        const QString content = QString::fromUtf8(f.readAll());
        QVERIFY(content.contains("[provenance]") && content.contains("distance_after"));
        QVERIFY(content.contains("metal.wav"));
    }

    void aBasePresetIsFittedThroughItsFlatCopyAndApplied() {
        auto palette = makePalette();
        QVERIFY(palette->selectSurface("wood_reverb")); // base = "wood", plus a reverb
        auto* c = palette->compareView();
        QVERIFY(useAndCompare(c, {metalWav_}));
        QSignalSpy finished(c, &gui::PaletteCompare::fitFinished);
        QVERIFY(c->startFit(8));
        QVERIFY(finished.wait(120000));
        QVERIFY2(finished.front().front().toBool(), qPrintable(c->message()));
        const auto& fit = *c->lastFit();
        qInfo("fit wood_reverb to a metal render: %.3f -> %.3f", fit.result.distanceBefore,
              fit.result.distanceAfter);
        QVERIFY(fit.result.distanceAfter <= fit.result.distanceBefore + 1e-3);
        QVERIFY2(c->applyFit(), qPrintable(c->message()));
        const auto fitted = engine::loadSurfaceFromString(fit.result.presetText, "fitted");
        QVERIFY(fitted->info().reverb.has_value());
        const auto applied = engine::loadSurfaceFromString(
            palette->currentPresetText("applied", "applied").toStdString(), "applied");
        QCOMPARE(applied->parameters().size(), fitted->parameters().size());
        for (std::size_t i = 0; i < fitted->parameters().size(); ++i) {
            const double want = fitted->parameters()[i].value, got = applied->parameters()[i].value;
            QVERIFY2(std::abs(got - want) <= 1e-3 * std::abs(want) + 1e-12,
                     qPrintable(QString::fromStdString(fitted->parameters()[i].path)));
        }
    }

    void cancelStopsTheFitWithinOneEvaluation() {
        auto palette = makePalette();
        QVERIFY(palette->selectSurface("wood"));
        auto* c = palette->compareView();
        QVERIFY(useAndCompare(c, {metalWav_}));
        int cancelledAt = 0;
        connect(c, &gui::PaletteCompare::fitProgress, this, [&](int k, int, double) {
            if (cancelledAt == 0) {
                cancelledAt = k;
                c->cancelFit();
            }
        });
        QSignalSpy finished(c, &gui::PaletteCompare::fitFinished);
        QVERIFY(c->startFit(200));
        QVERIFY(finished.wait(120000));
        const auto& fit = *c->lastFit();
        QVERIFY(fit.error.isEmpty());
        QVERIFY(fit.cancelled);
        qInfo("cancelled at evaluation %d, stopped after %d of 200", cancelledAt,
              fit.result.evaluations);
        QVERIFY(cancelledAt >= 1);
        QVERIFY(fit.result.evaluations <= cancelledAt + 1);
        QVERIFY(!c->fitRunning());
    }

    void noRecordingGivesAClearMessage() {
        auto palette = makePalette();
        QVERIFY(palette->selectSurface("wood"));
        auto* c = palette->compareView();
        QVERIFY(!c->startFit(4));
        QVERIFY2(c->message().contains("Choose reference recordings first"),
                 qPrintable(c->message()));
        QTemporaryDir emptyCache;
        c->setRecordingsCache(emptyCache.path());
        QVERIFY(!c->useMaterial("wood"));
        QVERIFY2(c->message().contains("manifest.csv") &&
                     c->message().contains("fetch-recordings.sh"),
                 qPrintable(c->message()));
        QVERIFY(!c->useFiles({home_.filePath("nowhere.wav")}));
        QVERIFY2(c->message().contains("nowhere.wav") && c->message().contains("no such file"),
                 qPrintable(c->message()));
        QSignalSpy failed(c, &gui::PaletteCompare::referenceFailed);
        QVERIFY(c->useFiles({silentWav_}));
        QVERIFY(failed.wait(60000));
        QVERIFY2(c->message().contains("No footstep found"), qPrintable(c->message()));
        QVERIFY(!c->hasReference());
        QVERIFY(!c->startFit(4));

        // A broken preset in the palette: the fit says what to do instead of running.
        QDir().mkpath(home_.filePath("data/presets"));
        QFile bad(home_.filePath("data/presets/broken.toml"));
        QVERIFY(bad.open(QIODevice::WriteOnly));
        bad.write("id = \"broken\"\nname = \"Broken\"\n[[layer]]\ntype = 'impact'\nmodes = 3\n");
        bad.close();
        auto again = makePalette();
        QVERIFY(useAndCompare(again->compareView(), {metalWav_}));
        QVERIFY(!again->selectSurface(home_.filePath("data/presets/broken.toml")));
        QVERIFY(!again->compareView()->startFit(4));
        QVERIFY2(again->compareView()->message().contains("Pick a surface first"),
                 qPrintable(again->compareView()->message()));
    }

    void settingsTheEngineRefusesGiveAMessage() {
        auto palette = makePalette();
        QVERIFY(palette->selectSurface("creaking_wood"));
        auto* c = palette->compareView();
        QVERIFY(useAndCompare(c, {woodWav_}));
        QString dynamic;
        const auto creaking = engine::Surface::loadById("creaking_wood");
        for (const auto& p : creaking->parameters())
            if (p.path.ends_with("dynamic_coefficient")) dynamic = QString::fromStdString(p.path);
        QVERIFY(!dynamic.isEmpty());
        // Dynamic friction above static (0.55): in range alone, refused by the friction layer.
        QSignalSpy failed(c, &gui::PaletteCompare::compareFailed);
        QVERIFY(palette->setParameter(dynamic, 0.9));
        QVERIFY(failed.wait(60000));
        QVERIFY2(c->message().contains("dynamic_coefficient"), qPrintable(c->message()));
        QVERIFY(std::isnan(c->distance()));
        QSignalSpy finished(c, &gui::PaletteCompare::fitFinished);
        QVERIFY(c->startFit(4));
        QVERIFY(finished.wait(60000));
        QVERIFY(!finished.front().front().toBool());
        QVERIFY2(c->message().startsWith("Fit failed") &&
                     c->message().contains("dynamic_coefficient"),
                 qPrintable(c->message()));
        QVERIFY(!c->applyFit());
    }

    void screenshotOfThePaletteComparingWithRecordings() {
        qputenv("XDG_CONFIG_HOME", home_.filePath("config").toUtf8());
        gui::MainWindow::Options o;
        o.dataDir = home_.filePath("screenshot_data"); // no presets saved by the other tests
        o.createDemo = false;
        o.startAudio = false;
        gui::MainWindow w(o);
        w.resize(1280, 800);
        w.show();
        w.showView(3);
        auto* palette = w.paletteView();
        QVERIFY(palette->selectSurface("wood"));
        auto* c = palette->compareView();
        c->setRenderSeconds(kSeconds);
        // The recordings cache when there is one (the docs' picture), else the metal render.
        QSignalSpy compared(c, &gui::PaletteCompare::compared);
        QSignalSpy failed(c, &gui::PaletteCompare::referenceFailed);
        if (!c->useMaterial("wood")) QVERIFY(c->useFiles({metalWav_}));
        QVERIFY(compared.wait(120000));
        QVERIFY(failed.isEmpty());
        // With a short fit done: its before/after distance and the apply/save buttons.
        QSignalSpy finished(c, &gui::PaletteCompare::fitFinished);
        QVERIFY(c->startFit(10));
        QVERIFY(finished.wait(120000));
        QVERIFY2(finished.front().front().toBool(), qPrintable(c->message()));
        QApplication::processEvents();
        const QImage shot = w.grab().toImage();
        QCOMPARE(shot.size(), QSize(1280, 800));
        const QByteArray out = qgetenv("UNDERFOOT_PALETTE_SCREENSHOT");
        const QString file = out.isEmpty() ? home_.filePath("palette_compare.png") : QString(out);
        QVERIFY(shot.save(file));
        qInfo("screenshot: %s (%s)", qPrintable(file), qPrintable(c->reference()->label));
    }
};

QTEST_MAIN(PaletteCompareTest)
#include "test_palette_compare.moc"
