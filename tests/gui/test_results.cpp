// SPDX-License-Identifier: GPL-3.0-or-later
// The Results view on the demo study (QTest, offscreen): protocol labels instead of ids, the
// heat map with counts and row percentages, ratings per condition as means with 95 % CIs (the
// t quantile computed here independently with Boost.Math) and the individual answers, the
// tests in words, and every figure saved as SVG and as PNG at 300 dpi. Also: the setup pages
// (Study, Run, Setup) fit a 1280x800 window without cutting a text off.
#include "analysis/stats/Tests.h"
#include "app/gui/DemoStudy.h"
#include "app/gui/Figures.h"
#include "app/gui/HeatMap.h"
#include "app/gui/MainWindow.h"
#include "app/gui/PaletteView.h"
#include "app/gui/RatingsPlot.h"
#include "app/gui/ResultsView.h"
#include "app/gui/RunView.h"
#include "app/gui/StudyContext.h"

#include <QAbstractButton>
#include <QComboBox>
#include <QFile>
#include <QImage>
#include <QLabel>
#include <QRegularExpression>
#include <QTableWidget>
#include <QTemporaryDir>
#include <QTest>
#include <QTextDocument>

#include <boost/math/distributions/students_t.hpp>

#include <cmath>

using namespace underfoot;

class ResultsTest : public QObject {
    Q_OBJECT
  private:
    QTemporaryDir home_;
    std::unique_ptr<gui::MainWindow> window() {
        gui::MainWindow::Options o;
        o.dataDir = home_.filePath("data");
        o.createDemo = true;
        o.startAudio = false;
        auto w = std::make_unique<gui::MainWindow>(o);
        w->resize(1280, 800);
        w->show();
        return w;
    }

  private slots:
    void initTestCase() {
        QVERIFY(home_.isValid());
        qputenv("XDG_CONFIG_HOME", home_.filePath("config").toUtf8());
        qputenv("XDG_DATA_HOME", home_.filePath("share").toUtf8());
        QCoreApplication::setApplicationName("underfoot-gui-test");
    }

    void testsInWords() {
        // R: chisq.test(matrix(c(8, 18, 12, 2), 2)) -> X-squared = 8.9011, df = 1, p = 0.002849
        const auto chi = analysis::chisqTest({{8, 12}, {18, 2}});
        QCOMPARE(gui::testInWords(chi), QString::fromUtf8("\u03c7\u00b2(1) = 8.90, p = 0.003"));
        analysis::TestResult t;
        t.statisticName = "t";
        t.statistic = -2.3456;
        t.df = {11.83};
        t.p = 0.0004;
        QCOMPARE(gui::testInWords(t), QString("t(11.8) = -2.35, p < 0.001"));
        t.error = "not enough observations";
        QCOMPARE(gui::testInWords(t), QString("not enough observations"));
    }

    void labelsFiguresAndExports() {
        auto w = window();
        QVERIFY(w->context().hasStudy());
        w->showView(2);
        auto* results = w->resultsView();
        results->refresh();
        const auto& m = results->heatMap()->matrix();
        QVERIFY(!m.rows.empty());
        // Labels, not ids: "beach sand", not "beach_sand".
        bool labelled = false;
        for (std::size_t r = 0; r < m.rows.size(); ++r) {
            const QString label = results->heatMap()->rowLabel(r);
            QVERIFY(!label.contains('_'));
            labelled |= label != QString::fromStdString(m.rows[r].surfaceId);
        }
        QVERIFY(labelled);
        for (std::size_t c = 0; c < m.columns.options.size(); ++c)
            QCOMPARE(results->heatMap()->columnLabel(c),
                     QString::fromStdString(m.columns.options[c].label));
        QVERIFY(!results->groupBox()->currentText().contains('_'));
        for (int r = 0; r < results->summaryTable()->rowCount(); ++r)
            QVERIFY2(!results->summaryTable()->item(r, 1)->text().contains('_'),
                     qPrintable(results->summaryTable()->item(r, 1)->text()));

        // Tests in words beside the numbers, agreeing with them.
        auto* tests = results->testsTable();
        QVERIFY(tests->rowCount() > 0);
        int chi = 0;
        for (int r = 0; r < tests->rowCount(); ++r) {
            const QString words = tests->item(r, 5)->text();
            const QString stat = tests->item(r, 7)->text();
            if (!words.startsWith(QString::fromUtf8("\u03c7\u00b2("))) continue;
            ++chi;
            QVERIFY2(
                words.contains(QString(" = %1, p ").arg(QString::number(stat.toDouble(), 'f', 2))),
                qPrintable(words + " vs " + stat));
        }
        QVERIFY2(chi > 0, "the demo study's between-group chi-square tests");

        // The mixed models beside them: glmer, and lmer and clmm for every rating comparison,
        // with the sentence on which to cite.
        auto* models = results->modelsTable();
        int glmer = 0, clmm = 0;
        for (int r = 0; r < models->rowCount(); ++r) {
            const QString model = models->item(r, 3)->text();
            glmer += model.startsWith("glmer") ? 1 : 0;
            clmm += model.startsWith("clmm") ? 1 : 0;
        }
        QVERIFY2(glmer > 0 && clmm > 0,
                 qPrintable(QString("glmer %1, clmm %2").arg(glmer).arg(clmm)));
        QVERIFY(results->modelAdvice().contains("cite the cumulative link mixed model"));

        // Ratings per condition: mean and 95 % t interval of the stored answers.
        QVERIFY(results->scaleBox()->count() >= 1);
        results->scaleBox()->setCurrentIndex(0);
        const auto& series = results->ratingsPlot()->series();
        QVERIFY(!series.conditions.empty());
        int withCi = 0;
        for (const auto& c : series.conditions) {
            QVERIFY(!c.label.contains('_'));
            double sum = 0, sq = 0;
            for (double v : c.values) sum += v;
            const double n = static_cast<double>(c.values.size());
            const double mean = sum / n;
            QVERIFY(std::fabs(c.mean - mean) < 1e-12);
            if (c.values.size() < 2) continue;
            for (double v : c.values) sq += (v - mean) * (v - mean);
            const double sd = std::sqrt(sq / (n - 1));
            if (sd == 0) continue;
            const boost::math::students_t dist(n - 1);
            const double half = boost::math::quantile(dist, 0.975) * sd / std::sqrt(n);
            QVERIFY2(std::fabs(c.ciLow - (mean - half)) < 1e-9, qPrintable(c.label));
            QVERIFY2(std::fabs(c.ciHigh - (mean + half)) < 1e-9, qPrintable(c.label));
            ++withCi;
        }
        QVERIFY(withCi > 0);

        // Every figure as SVG and PNG at print resolution.
        const QString svg = home_.filePath("matrix.svg");
        const QString png = home_.filePath("matrix.png");
        QCOMPARE(results->saveHeatMap(svg), QString());
        QCOMPARE(results->saveHeatMap(png), QString());
        QFile f(svg);
        QVERIFY(f.open(QIODevice::ReadOnly));
        const QString text = QString::fromUtf8(f.readAll());
        QVERIFY(text.contains("<svg"));
        QVERIFY2(text.contains(results->heatMap()->rowLabel(0).toHtmlEscaped()),
                 "the row labels are text in the SVG");
        const QImage image(png);
        QVERIFY(!image.isNull());
        QVERIFY2(std::abs(image.dotsPerMeterX() - 11811) <= 1, "300 dpi");
        QVERIFY(image.width() > 2000);
        QCOMPARE(results->saveRatingsPlot(home_.filePath("ratings.svg")), QString());
        QCOMPARE(results->saveRatingsPlot(home_.filePath("ratings.png")), QString());
        QVERIFY(QImage(home_.filePath("ratings.png")).width() > 1500);
        QVERIFY(results->saveHeatMap(home_.filePath("matrix.bmp")).contains("use .svg or .png"));
    }

    void paletteShowsLabelsNotPaths() {
        auto w = window();
        w->showView(3);
        auto* palette = w->paletteView();
        QVERIFY(palette->selectSurface("wood"));
        auto* table = palette->findChild<QTableWidget*>();
        QVERIFY(table && table->rowCount() > 3);
        for (int r = 0; r < table->rowCount(); ++r) {
            const QString label = table->item(r, 0)->text();
            QVERIFY2(!label.contains('[') && !label.contains('_') && !label.contains('.'),
                     qPrintable(label));
            QVERIFY2(!table->item(r, 0)->toolTip().isEmpty(), "help as tooltip");
        }
    }

    void setupPagesFitAt1280x800() {
        auto w = window();
        QVERIFY(w->minimumSizeHint().width() <= 1280);
        QVERIFY(w->minimumSizeHint().height() <= 800);
        for (int view : {0, 1, 4}) {
            w->showView(view);
            QApplication::processEvents();
            QTest::qWait(20);
            QCOMPARE(w->size(), QSize(1280, 800));
            QWidget* page = w->tabs()->currentWidget();
            int checked = 0;
            for (QLabel* l : page->findChildren<QLabel*>()) {
                if (!l->isVisible() || l->text().isEmpty()) continue;
                if (l->wordWrap()) {
                    // Wrapped text needs its height at the width it got.
                    const int need = l->heightForWidth(l->width());
                    QVERIFY2(l->height() >= need,
                             qPrintable(QString("view %1: wrapped label '%2' is %3 px high, "
                                                "needs %4")
                                            .arg(view)
                                            .arg(l->text().left(60))
                                            .arg(l->height())
                                            .arg(need)));
                    ++checked;
                    continue;
                }
                ++checked;
                if (l->textFormat() == Qt::RichText || Qt::mightBeRichText(l->text())) continue;
                QString shown = l->text().split('\n').first();
                shown.remove(QRegularExpression("&(?!&)")); // mnemonic marks are not drawn
                const int need = l->fontMetrics().horizontalAdvance(shown);
                QVERIFY2(l->contentsRect().width() >= need,
                         qPrintable(QString("view %1: label '%2' is %3 px wide, needs %4")
                                        .arg(view)
                                        .arg(l->text())
                                        .arg(l->contentsRect().width())
                                        .arg(need)));
            }
            QVERIFY(checked > 3);
            for (QAbstractButton* b : page->findChildren<QAbstractButton*>()) {
                if (!b->isVisible() || b->text().isEmpty()) continue;
                QVERIFY2(b->width() >= b->minimumSizeHint().width(),
                         qPrintable(QString("view %1: button '%2' is %3 px wide, needs %4")
                                        .arg(view)
                                        .arg(b->text())
                                        .arg(b->width())
                                        .arg(b->minimumSizeHint().width())));
            }
        }
    }
};

QTEST_MAIN(ResultsTest)
#include "test_results.moc"
