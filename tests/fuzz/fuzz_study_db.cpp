// SPDX-License-Identifier: GPL-3.0-or-later
// A study file (experiment/Store.h: StudyStore::open, then every table `underfoot export`
// writes, and the journal, whose event names are read back strictly). Refusal: StoreError naming
// the file; SQLite's own errors on a damaged file (SQLite::Exception) are tolerated as refusals
// here.
#include "FuzzSupport.h"
#include "experiment/Export.h"
#include "experiment/Store.h"

#include <SQLiteCpp/Exception.h>

#include <sstream>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path dir = fuzz::scratchDir();
    fs::remove(dir / "study.db-wal", ec);
    fs::remove(dir / "study.db-shm", ec);
    fs::remove(dir / "study.db-journal", ec);
    const std::string path = fuzz::writeInput("study.db", data, size);
    try {
        auto store = experiment::StudyStore::open(path);
        std::ostringstream out;
        (void)experiment::writeTrialsCsv(store, out, experiment::ExportScope::All);
        (void)experiment::writeRatingsCsv(store, out, experiment::ExportScope::All);
        (void)experiment::writeParticipantsCsv(store, out);
        (void)experiment::writeScalesCsv(store, out);
        (void)experiment::writeAudioCsv(store, out, experiment::ExportScope::All);
        experiment::writeCodebook(store, out);
        (void)store.events();
    } catch (const experiment::StoreError& e) {
        fuzz::expectNamed(e, path);
    } catch (const SQLite::Exception&) {
        // SQLite refused the damaged file.
    } catch (const std::exception& e) {
        fuzz::fail(std::string("unexpected exception ") + typeid(e).name() + ": " + e.what());
    }
    return 0;
}
