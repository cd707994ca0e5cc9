// SPDX-License-Identifier: GPL-3.0-or-later
// Child process of the crash test: simulates participants of an existing study and prints
// "ack CODE TRIAL" on stdout after each answer is committed (the parent SIGKILLs it at random).
//   experiment_session_child STUDY.db MATRIX.csv PARTICIPANTS
#include "experiment/Simulation.h"
#include "experiment/Store.h"

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <unistd.h>

int main(int argc, char** argv) {
    using namespace underfoot::experiment;
    if (argc != 4) {
        std::fprintf(stderr, "usage: %s STUDY.db MATRIX.csv PARTICIPANTS\n", argv[0]);
        return 2;
    }
    try {
        StudyStore store = StudyStore::open(argv[1]);
        MatrixByGroup matrices;
        matrices[""] = loadConfusionMatrix(argv[2]);
        simulateStudy(
            store, matrices, std::atoi(argv[3]), {}, "S", [](const std::string& code, int index) {
                // One write(2) per line: nothing buffered is lost at SIGKILL, and the
                // line is only written after the commit returned.
                const std::string line = "ack " + code + " " + std::to_string(index) + "\n";
                if (::write(STDOUT_FILENO, line.data(), line.size()) < 0) std::abort();
            });
        std::fputs("done\n", stdout);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "session_child: %s\n", e.what());
        return 1;
    }
    return 0;
}
