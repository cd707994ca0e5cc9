// SPDX-License-Identifier: GPL-3.0-or-later
// The parts are independent libraries, each with its own list of surfaces and soundscapes (the
// experiment validates protocols, the analysis scores answers, the engine renders, the
// soundscapes library plays backgrounds). They must name the same things.
#include "analysis/io/TrialCsv.h"
#include "analysis/model/Catalog.h"
#include "engine/surfaces/Surface.h"
#include "experiment/Catalogue.h"
#include "experiment/Export.h"
#include "soundscapes/Library.h"

#include <gtest/gtest.h>

#include <set>

using namespace underfoot;

TEST(Catalogues, EngineExperimentAndAnalysisKnowTheSameSurfaces) {
    std::set<std::string> engine;
    for (const auto& s : engine::listSurfaces()) engine.insert(s.id);
    std::set<std::string> exp;
    for (const auto& s : experiment::defaultCatalogue().surfaces) exp.insert(s.id);
    std::set<std::string> ana;
    for (const auto& s : analysis::surfaceCatalog()) ana.insert(s.id);
    EXPECT_EQ(engine, exp);
    EXPECT_EQ(engine, ana);
}

TEST(Catalogues, SurfaceCategoriesAgreeBetweenEngineAndAnalysis) {
    for (const auto& s : engine::listSurfaces()) {
        const auto a = analysis::findSurface(s.id);
        ASSERT_TRUE(a.has_value()) << s.id;
        EXPECT_EQ(std::string(analysis::categoryName(a->category)), engine::toString(s.category))
            << s.id;
    }
}

TEST(Catalogues, SoundscapesAgreeEverywhere) {
    const auto ids = soundscapes::builtinSoundscapeIds();
    std::set<std::string> lib(ids.begin(), ids.end());
    std::set<std::string> exp;
    for (const auto& s : experiment::defaultCatalogue().soundscapes) exp.insert(s.id);
    std::set<std::string> ana;
    for (const auto& s : analysis::soundscapeCatalog()) ana.insert(s.id);
    EXPECT_EQ(lib, exp);
    EXPECT_EQ(lib, ana);
}

TEST(Catalogues, TheAnalysisReadsExactlyTheColumnsTheExperimentExports) {
    // The long-format trials CSV is the contract between the two parts.
    const auto& read = analysis::trialCsvColumns();
    ASSERT_EQ(read.size(), experiment::kTrialColumns.size());
    for (std::size_t i = 0; i < read.size(); ++i)
        EXPECT_EQ(read[i], std::string(experiment::kTrialColumns[i])) << "column " << i + 1;
}
