// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
// The participant-visible contract, for the tests of every front end: walk a whole session of
// a participant through experiment::TrialFlow, render each screen of its participant screen
// model as text, and search it for what a participant must never read (the experimenter's
// notes, group names, the current stimulus's id, label, surface, soundscape, reverb and factor
// levels, clip file names, seeds, the correct answer outside the answer list).
//
// Header-only so that the web and console tests can include it: a front end's test renders its
// own page for the same moment (the walker hands it the flow) and passes that text to leaks().
#include "experiment/Protocol.h"
#include "experiment/Session.h"
#include "experiment/Store.h"
#include "experiment/TrialFlow.h"

#include <cctype>
#include <functional>
#include <string>
#include <vector>

namespace underfoot::experiment::test {

/// Every text of a participant screen except its answer lists (heading, text, notice, part,
/// prompts, scale anchors), as a front end would show it.
inline std::string screenFreeText(const ParticipantScreen& s) {
    std::string all = s.heading + "\n" + s.text + "\n" + s.notice + "\n" + s.part + "\n";
    for (const auto& sec : s.sections) {
        all += sec.prompt + "\n";
        if (sec.scale)
            for (const auto& a : anchorTexts(*sec.scale)) all += a + "\n";
    }
    return all;
}

/// The answer lists of a screen ("a Wood\nb Gravel\n..."): the same on every trial of a
/// protocol, so they tell nothing about the stimulus.
inline std::string screenOptions(const ParticipantScreen& s) {
    std::string all;
    for (const auto& sec : s.sections)
        for (const auto& o : sec.options) all += std::string(1, o.letter) + " " + o.label + "\n";
    return all;
}

/// One string a participant must not read, and what it is ("notes", "stimulus id").
struct Forbidden {
    std::string what;
    std::string text;
    /// Searched as a whole word, case-sensitive (ids); otherwise as a substring.
    bool word = true;
    /// Searched only in what changes from screen to screen (heading, text), not in the
    /// protocol's own prompts and anchors: factor levels are ordinary words ("real" in "how
    /// real did it sound"), and a surface every stimulus shares ("water") tells nothing.
    bool varyingOnly = false;
};

/// What changes from screen to screen apart from the protocol's own wording: heading and text
/// (the notice after a refused Done quotes the prompts, so it is searched with the prompts).
inline std::string screenVaryingText(const ParticipantScreen& s) {
    return s.heading + "\n" + s.text + "\n";
}

/// Whether `needle` occurs in `hay` (as a whole word: not inside a longer identifier).
inline bool contains(const std::string& hay, const std::string& needle, bool word) {
    if (needle.empty()) return false;
    const auto isWordChar = [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
    };
    for (std::size_t at = hay.find(needle); at != std::string::npos;
         at = hay.find(needle, at + 1)) {
        if (!word) return true;
        const bool before = at == 0 || !isWordChar(hay[at - 1]);
        const std::size_t end = at + needle.size();
        const bool after = end >= hay.size() || !isWordChar(hay[end]);
        if (before && after) return true;
    }
    return false;
}

/// What the participant must not read: always the notes (each sentence of 20 characters or
/// more) and the group ids and labels of a between design; while `trial` is current also its
/// stimulus's id, label, surface, soundscape, reverb, factor levels, clip file, seeds and the
/// correct answer's label.
inline std::vector<Forbidden> forbiddenStrings(const Protocol& p, const TrialRecord* trial) {
    std::vector<Forbidden> out;
    std::string sentence;
    for (const char c : p.notes + ".") {
        if (c == '.' || c == '\n' || c == ';') {
            while (!sentence.empty() && std::isspace(static_cast<unsigned char>(sentence[0])))
                sentence.erase(0, 1);
            if (sentence.size() >= 20) out.push_back({"notes", sentence, false});
            sentence.clear();
        } else {
            sentence += c;
        }
    }
    if (p.design == DesignKind::Between)
        for (const auto& g : p.groups) {
            out.push_back({"group id", g.id, true});
            if (!g.label.empty()) out.push_back({"group label", g.label, false});
        }
    if (!trial) return out;
    const Stimulus& s = trial->stimulus;
    out.push_back({"stimulus id", s.id, true});
    if (!s.label.empty()) out.push_back({"stimulus label", s.label, false});
    bool shared = true; // every stimulus walks on this surface
    for (const auto& other : p.stimuli) shared = shared && other.surface == s.surface;
    out.push_back({"surface id", s.surface, true, shared});
    if (s.soundscape) out.push_back({"soundscape id", *s.soundscape, true});
    if (s.reverb) out.push_back({"reverb", *s.reverb, true});
    for (const auto& [factor, level] : s.factors)
        if (level.size() >= 3 && !std::isdigit(static_cast<unsigned char>(level[0])))
            out.push_back({"factor level", level, true, true});
    out.push_back({"clip file", clipPath(s, ""), false});
    if (s.clip) out.push_back({"clip file", *s.clip, false});
    out.push_back({"planned seed", std::to_string(trial->plannedSeed), true});
    if (trial->renderSeed) out.push_back({"render seed", std::to_string(*trial->renderSeed), true});
    for (const auto& o : p.questions.surfaceOptions)
        if (o.id != kDontKnow && answerIsCorrect(o.id, s.surface))
            out.push_back({"correct answer", o.label, false});
    return out;
}

/// The forbidden strings found in a front end's rendering of one moment ("stimulus id 'GL'"),
/// empty when none: `text` is everything it shows but the answer lists, `varying` the part that
/// changes from screen to screen (searched for the varyingOnly strings).
inline std::vector<std::string> leaks(const std::string& text, const std::string& varying,
                                      const std::vector<Forbidden>& forbidden) {
    std::vector<std::string> found;
    for (const auto& f : forbidden)
        if (contains(f.varyingOnly ? varying : text, f.text, f.word))
            found.push_back(f.what + " '" + f.text + "'");
    return found;
}

/// A player that plays nothing: the plan's seed, and for listening tests the clip's name.
class SilentScreenPlayer final : public StimulusPlayer {
  public:
    explicit SilentScreenPlayer(const Protocol& p) : protocol_(p) {}
    StimulusStart start(const Stimulus& s, std::uint64_t plannedSeed) override {
        StimulusStart started{plannedSeed, std::nullopt};
        if (protocol_.clips.enabled)
            started.clip = PlayedClip{clipPath(s, ""), protocol_.clips.seconds,
                                      static_cast<std::uint64_t>(protocol_.clips.seconds * 48000),
                                      48000.0, ""};
        return started;
    }
    void stop() override {}

  private:
    const Protocol& protocol_;
};

/// One moment of a session: the screen, the flow, and the trial the session is on (nullptr
/// outside a trial).
using ScreenVisitor =
    std::function<void(const ParticipantScreen&, const TrialFlow&, const TrialRecord*)>;

/// Runs participant `code` of `store` from briefing to the end through a TrialFlow, visiting
/// every screen: the briefing, each trial before the stimulus, while laps are walked, after a
/// refused Done (the notice), answered, each break and the end. Answers with the first option
/// and each scale's minimum. Returns the number of screens visited.
inline int walkParticipantScreens(StudyStore& store, const std::string& code,
                                  const ScreenVisitor& visit) {
    SilentScreenPlayer player(store.protocol());
    Session session(store, code, player, SessionSettings{"screens", "none", "none", "test", false});
    TrialFlow flow(store, session);
    int screens = 0;
    const auto show = [&] {
        const bool in =
            session.phase() == SessionPhase::Trial || session.phase() == SessionPhase::Practice;
        visit(flow.participantScreen(), flow, in ? &session.current() : nullptr);
        ++screens;
    };
    for (int guard = 0; session.phase() != SessionPhase::Finished && guard < 100000; ++guard) {
        switch (session.phase()) {
        case SessionPhase::Briefing:
            show();
            session.finishBriefing();
            flow.reset();
            break;
        case SessionPhase::Break:
            show();
            session.finishBreak();
            flow.reset();
            break;
        case SessionPhase::Practice:
        case SessionPhase::Trial: {
            show(); // waiting for the stimulus
            if (!flow.start()) return screens;
            show();
            while (session.lapCount() > 0 && session.lapsDone() < session.lapCount()) {
                flow.completeLap();
                show();
            }
            if (!flow.sections().empty()) {
                (void)flow.commit(); // refused: nothing answered yet
                show();
            }
            for (const auto& sec : flow.sections()) {
                if (sec.kind == SectionKind::Scale)
                    flow.setRating(sec.scale->id, sec.scale->min);
                else if (!sec.options.empty())
                    flow.choose(sec.kind, sec.options.front().letter);
            }
            show();
            if (!flow.commit()) return screens;
            break;
        }
        case SessionPhase::Finished:
            break;
        }
    }
    show();
    return screens;
}

} // namespace underfoot::experiment::test
