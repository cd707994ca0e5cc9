// SPDX-License-Identifier: GPL-3.0-or-later
// The parts are independent libraries (the experiment validates protocols, the analysis scores
// answers, the engine renders, the soundscapes library plays backgrounds); the surfaces and
// soundscapes they know come from one catalogue generated from the preset files
// (base/Catalogue.h, tools/catalogue/catalogue.py). They must name the same things, and a preset
// file must be all a new surface needs.
#include "analysis/model/Catalog.h"
#include "base/Catalogue.h"
#include "engine/surfaces/Surface.h"
#include "experiment/Catalogue.h"
#include "soundscapes/Library.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <unistd.h>

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

namespace {
namespace fs = std::filesystem;

std::string readText(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

/// Runs the catalogue generator on `surfaces` (and the shipped soundscapes) into `output`;
/// returns its exit status, its messages in `errors`.
int generate(const fs::path& surfaces, const fs::path& output, std::string& errors) {
    const fs::path err = output.string() + ".err";
    const std::string command = std::string(UNDERFOOT_PYTHON) + " '" + UNDERFOOT_SOURCE_DIR +
                                "/tools/catalogue/catalogue.py' --surfaces '" + surfaces.string() +
                                "' --soundscapes '" + UNDERFOOT_SOURCE_DIR +
                                "/soundscapes/data' --output '" + output.string() + "' 2> '" +
                                err.string() + "'";
    const int status = std::system(command.c_str());
    errors = readText(err);
    return status;
}
} // namespace

TEST(Catalogues, EveryPresetFileIsInTheCatalogueAndNothingElse) {
    std::set<std::string> files;
    for (const auto& f :
         fs::directory_iterator(fs::path(UNDERFOOT_SOURCE_DIR) / "engine" / "data" / "surfaces"))
        if (f.path().extension() == ".toml") files.insert(f.path().stem().string());
    std::set<std::string> catalogue, codes;
    for (const auto& s : base::surfaces()) {
        catalogue.insert(std::string(s.id));
        if (!s.code.empty()) {
            EXPECT_TRUE(codes.insert(std::string(s.code)).second) << s.code;
        }
    }
    EXPECT_EQ(files, catalogue);
    // The labels are the presets' names, the same in every part.
    for (const auto& s : engine::listSurfaces()) {
        const auto a = analysis::findSurface(s.id);
        ASSERT_TRUE(a.has_value()) << s.id;
        EXPECT_EQ(a->label, s.name) << s.id;
        const auto* e = experiment::defaultCatalogue().surface(s.id);
        ASSERT_NE(e, nullptr) << s.id;
        EXPECT_EQ(e->label, s.name) << s.id;
        EXPECT_EQ(e->code, a->code) << s.id;
    }
    // Codes and base surfaces as the published tables read them.
    EXPECT_EQ(analysis::findSurface("WR")->id, "wood_reverb");
    EXPECT_EQ(analysis::baseSurfaceId("wood_reverb"), "wood");
    EXPECT_EQ(analysis::baseSurfaceId("creaking_wood"), "creaking_wood");
    EXPECT_EQ(analysis::surfaceCatalog().front().code, "BS");
}

TEST(Catalogues, ANewPresetFileIsAllANewSurfaceNeeds) {
    const fs::path dir =
        fs::temp_directory_path() / ("underfoot_catalogue_" + std::to_string(getpid()));
    const fs::path surfaces = dir / "surfaces";
    fs::create_directories(surfaces);
    for (const auto& f :
         fs::directory_iterator(fs::path(UNDERFOOT_SOURCE_DIR) / "engine" / "data" / "surfaces"))
        fs::copy_file(f.path(), surfaces / f.path().filename());
    std::ofstream(surfaces / "moss.toml") << "id = \"moss\"\nname = \"Moss\"\ncode = \"MO\"\n"
                                             "category = \"aggregate\"\n";
    std::string errors;
    ASSERT_EQ(generate(surfaces, dir / "Catalogue.cpp", errors), 0) << errors;
    const std::string generated = readText(dir / "Catalogue.cpp");
    const auto moss = generated.find(R"({"moss", "Moss", "MO", "moss", "aggregate"})");
    EXPECT_NE(moss, std::string::npos) << generated;
    // After the surfaces of the published tables, which keep their order.
    EXPECT_LT(generated.find(R"({"carpet", "Carpet", "CP")"), moss);
    EXPECT_LT(generated.find(R"({"beach_sand", "Beach sand", "BS")"),
              generated.find(R"({"gravel", "Gravel", "GL")"));

    // A preset the catalogue cannot take is refused, naming the file and what was expected.
    std::ofstream(surfaces / "moss.toml") << "id = \"moss\"\nname = \"Moss\"\ncode = \"BS\"\n"
                                             "category = \"aggregate\"\n";
    EXPECT_NE(generate(surfaces, dir / "Bad.cpp", errors), 0);
    EXPECT_NE(errors.find("moss.toml: code 'BS' is already beach_sand's"), std::string::npos)
        << errors;
    std::ofstream(surfaces / "moss.toml")
        << "id = \"moss\"\nname = \"Moss\"\ncategory = \"soft\"\n";
    EXPECT_NE(generate(surfaces, dir / "Bad.cpp", errors), 0);
    EXPECT_NE(errors.find("moss.toml: category 'soft': expected one of"), std::string::npos)
        << errors;
    EXPECT_FALSE(fs::exists(dir / "Bad.cpp"));
    fs::remove_all(dir);
}
