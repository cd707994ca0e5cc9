// SPDX-License-Identifier: GPL-3.0-or-later
// The trial flow shared by the console, the terminal and the web front end: the answer draft,
// validation, lock rule, laps and clips, and what the participant's screen may show.
#include "TestSupport.h"
#include "experiment/TrialFlow.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

using namespace underfoot::experiment;
using namespace underfoot::experiment::test;

namespace {
class FakePlayer : public StimulusPlayer {
  public:
    StimulusStart start(const Stimulus& s, std::uint64_t plannedSeed) override {
        ++starts;
        last = s.id;
        return {plannedSeed, std::nullopt};
    }
    void stop() override {}
    int starts = 0;
    std::string last;
};

const char* kNotes = "EXPERIMENTER NOTES: group B hears mismatching soundscapes";

std::string protocolText(const std::string& lock) {
    return miniProtocol("[[questions.scales]]\nid = \"quality\"\nprompt = \"Quality\"\nmin = 0\n"
                        "max = 10\nanchors = { 0 = \"bad\", 10 = \"excellent\" }\n"
                        "[rules]\nlock = \"" +
                            lock + "\"\n",
                        "repetitions = 2\nno_immediate_repeat = true\n");
}

StudyStore makeStudy(const TempDir& dir, const std::string& lock) {
    std::string text = protocolText(lock);
    // The protocol's description is the experimenter's notes.
    text.insert(text.find("[design]"), std::string("description = \"") + kNotes + "\"\n");
    StudyStore store = StudyStore::create(dir.file("s.db"), parseProtocol(text, "mini.toml"),
                                          {"S", "lab", 7, "t"});
    store.registerParticipant({"P1", {}, "", "", "", {}, ""});
    return store;
}

/// Every text the participant's screen holds.
std::string screenText(const ParticipantScreen& s) {
    std::string all = s.heading + "\n" + s.text + "\n";
    for (const auto& sec : s.sections) {
        all += sec.prompt + "\n";
        for (const auto& o : sec.options) all += std::string(1, o.letter) + " " + o.label + "\n";
        if (sec.scale)
            for (const auto& a : anchorTexts(*sec.scale)) all += a + "\n";
    }
    return all;
}
/// The study, player, session and flow most tests open with: participant P1 of the mini
/// protocol, lock rule `lock`, in the briefing.
class TrialFlowTest : public ::testing::Test {
  protected:
    explicit TrialFlowTest(const std::string& lock = "next_trial")
        : store(makeStudy(dir, lock)), session(store, "P1", player, {}), flow(store, session) {}
    /// Ends the briefing and starts the draft of the first trial.
    void briefed() {
        session.finishBriefing();
        flow.reset();
    }
    TempDir dir;
    StudyStore store;
    FakePlayer player;
    Session session;
    TrialFlow flow;
};

/// The same with the lock rule "answer" (an answer is final once committed).
class TrialFlowAnswerLockTest : public TrialFlowTest {
  protected:
    TrialFlowAnswerLockTest() : TrialFlowTest("answer") {}
};
} // namespace

TEST_F(TrialFlowTest, DraftLettersDigitsValidationAndCommit) {
    EXPECT_TRUE(flow.sections().empty()) << "no questions during the briefing";
    EXPECT_EQ(flow.start().refusal, Refusal::NotInTrial);
    session.finishBriefing();
    flow.reset();
    ASSERT_EQ(flow.sections().size(), 3u); // surface, realism 1-7, quality 0-10
    EXPECT_EQ(flow.sections()[0].kind, SectionKind::Surface);
    EXPECT_EQ(flow.sections()[2].scale->id, "quality");

    EXPECT_EQ(flow.commit().refusal, Refusal::NotStarted);
    EXPECT_EQ(flow.chooseLetter('z').refusal, Refusal::NotAllowed);
    EXPECT_TRUE(flow.chooseLetter('B'));
    EXPECT_EQ(flow.draft().answer, "gravel");
    EXPECT_EQ(flow.activeSection(), 1) << "a chosen answer moves on to the next question";
    EXPECT_EQ(flow.typeDigit(9).refusal, Refusal::OutOfRange) << "realism is 1-7";
    EXPECT_TRUE(flow.typeDigit(6));
    EXPECT_EQ(flow.activeSection(), 2);
    EXPECT_TRUE(flow.typeDigit(1));
    EXPECT_TRUE(flow.typeDigit(0));
    EXPECT_EQ(flow.draft().ratings.at("quality"), 10) << "'1' '0' types 10 on a 0-10 scale";
    flow.adjust(-1);
    EXPECT_EQ(flow.draft().ratings.at("quality"), 9);
    flow.adjust(+5);
    EXPECT_EQ(flow.draft().ratings.at("quality"), 10) << "Right stops at the scale's end";
    EXPECT_EQ(flow.setRating("quality", 11).refusal, Refusal::OutOfRange);
    EXPECT_EQ(flow.setRating("speed", 3).refusal, Refusal::NotAllowed);

    ASSERT_TRUE(flow.start());
    EXPECT_EQ(flow.start().refusal, Refusal::AlreadyStarted);
    TrialAnswer saved = flow.draft();
    flow.reset();
    flow.setActive(1);
    EXPECT_TRUE(flow.typeDigit(4));
    const FlowResult incomplete = flow.commit();
    EXPECT_EQ(incomplete.refusal, Refusal::Incomplete);
    EXPECT_NE(incomplete.message.find("quality"), std::string::npos) << incomplete.message;
    EXPECT_EQ(session.answeredCount(), 0);
    EXPECT_TRUE(flow.choose(SectionKind::Surface, 'a'));
    EXPECT_TRUE(flow.setRating("quality", 3));
    const int index = session.current().index;
    ASSERT_TRUE(flow.commit());
    EXPECT_TRUE(flow.draft().ratings.empty()) << "a fresh draft follows the commit";
    const auto stored = store.trials("P1")[static_cast<std::size_t>(index)];
    EXPECT_TRUE(stored.answered);
    EXPECT_EQ(stored.answer.answer, "wood");
    EXPECT_EQ(stored.answer.ratings.at("realism"), 4);
    EXPECT_EQ(stored.answer.ratings.at("quality"), 3);
    (void)saved;
}

TEST_F(TrialFlowTest, LockRuleNextTrialAllowsChangeUntilTheNextStimulus) {
    briefed();
    EXPECT_EQ(flow.revisePrevious().refusal, Refusal::NoPrevious);
    ASSERT_TRUE(flow.start());
    flow.chooseLetter('a');
    flow.typeDigit(2);
    flow.typeDigit(5);
    const int first = session.current().index;
    ASSERT_TRUE(flow.commit());
    ASSERT_TRUE(flow.revisePrevious());
    EXPECT_EQ(flow.revising(), first);
    EXPECT_EQ(flow.draft().answer, "wood") << "the stored answer is loaded";
    EXPECT_EQ(flow.start().refusal, Refusal::Locked) << "no stimulus while a change is open";
    flow.chooseLetter('c');
    ASSERT_TRUE(flow.commit()) << "commit stores the change";
    EXPECT_FALSE(flow.revising());
    EXPECT_EQ(store.trials("P1")[static_cast<std::size_t>(first)].answer.answer, "metal");
    EXPECT_EQ(session.answeredCount(), 1) << "the current trial is still unanswered";
    ASSERT_TRUE(flow.start());
    EXPECT_EQ(flow.revisePrevious().refusal, Refusal::Locked) << "the next stimulus started";
    std::string why;
    EXPECT_EQ(flow.exclusionTarget(true, &why), first);
    EXPECT_EQ(flow.exclusionTarget(false), session.current().index);
}

TEST_F(TrialFlowAnswerLockTest, LockRuleAnswerRefusesEveryChange) {
    briefed();
    ASSERT_TRUE(flow.start());
    flow.chooseLetter('a');
    flow.typeDigit(2);
    flow.typeDigit(5);
    ASSERT_TRUE(flow.commit());
    const FlowResult r = flow.revisePrevious();
    EXPECT_EQ(r.refusal, Refusal::Locked);
    EXPECT_NE(r.message.find("lock = \"answer\""), std::string::npos) << r.message;
}

TEST_F(TrialFlowTest, ParticipantScreenNeverShowsStimulusOrderOrNotes) {
    const auto plan = store.trials("P1");
    ParticipantScreen s = flow.participantScreen();
    EXPECT_EQ(s.page, ParticipantScreen::Page::Briefing);
    EXPECT_EQ(screenText(s).find("EXPERIMENTER"), std::string::npos) << screenText(s);
    EXPECT_NE(s.text.find("6 trials"), std::string::npos) << s.text;
    EXPECT_NE(s.text.find("Realism"), std::string::npos) << "the questions are announced";
    session.finishBriefing();
    flow.reset();
    std::string firstBody;
    for (int n = 1; session.phase() != SessionPhase::Finished; ++n) {
        const TrialRecord& t = session.current();
        s = flow.participantScreen();
        EXPECT_EQ(s.heading, "Trial " + std::to_string(n) + " of 6") << "1-based, for people";
        EXPECT_FALSE(s.answering) << "no answers before the stimulus";
        ASSERT_TRUE(flow.start());
        s = flow.participantScreen();
        EXPECT_TRUE(s.answering);
        const std::string text = screenText(s);
        // Nothing that depends on the stimulus: the body is the same on every trial.
        const std::string body = text.substr(text.find('\n'));
        if (firstBody.empty()) firstBody = body;
        EXPECT_EQ(body, firstBody) << "trial " << n << " (" << t.stimulus.id << ")";
        for (const auto& p : plan) {
            EXPECT_EQ(text.find(p.stimulus.id), std::string::npos) << p.stimulus.id;
            EXPECT_EQ(text.find("hall"), std::string::npos) << "reverb of a stimulus";
        }
        EXPECT_EQ(text.find("EXPERIMENTER"), std::string::npos);
        flow.chooseLetter('a');
        flow.typeDigit(3);
        flow.typeDigit(7);
        ASSERT_TRUE(flow.commit());
    }
    s = flow.participantScreen();
    EXPECT_EQ(s.page, ParticipantScreen::Page::Finished);
    EXPECT_EQ(s.answered, 6);
}

TEST(TrialFlow, LapsAndClipsOfTheShippedProtocols) {
    {
        TempDir dir;
        StudyStore store = StudyStore::create(dir.file("laps.db"),
                                              loadProtocol(shipped("wading_interactive.toml")),
                                              {"W", "lab", 3, "t"});
        store.registerParticipant({"P1", {}, "", "", "", {}, ""});
        FakePlayer player;
        Session session(store, "P1", player, {});
        session.finishBriefing();
        TrialFlow flow(store, session);
        EXPECT_EQ(flow.completeLap().refusal, Refusal::NotStarted);
        ASSERT_TRUE(flow.start());
        const int laps = session.lapCount();
        ASSERT_GT(laps, 1);
        for (int lap = 1; lap <= laps; ++lap) {
            EXPECT_NE(flow.participantScreen().text.find("Lap " + std::to_string(lap) + " of"),
                      std::string::npos);
            EXPECT_EQ(flow.commit().refusal, Refusal::LapsPending);
            ASSERT_TRUE(flow.completeLap());
        }
        EXPECT_EQ(flow.completeLap().refusal, Refusal::NotAllowed);
        EXPECT_TRUE(flow.participantScreen().answering);
        EXPECT_NE(flow.experimenterStatus().front().find("done"), std::string::npos);
    }
    {
        TempDir dir;
        StudyStore store =
            StudyStore::create(dir.file("clips.db"), loadProtocol(shipped("wading_listening.toml")),
                               {"L", "lab", 3, "t"});
        store.registerParticipant({"P1", {}, "", "", "", {}, ""});
        FakePlayer player;
        Session session(store, "P1", player, {});
        session.finishBriefing();
        TrialFlow flow(store, session);
        ASSERT_EQ(flow.sections().size(), 1u) << "one scale per block";
        ASSERT_TRUE(flow.start());
        ASSERT_TRUE(flow.start()) << "Space again replays the clip";
        ASSERT_TRUE(flow.replay());
        EXPECT_EQ(session.replayCount(), 2);
        EXPECT_EQ(player.starts, 3);
        EXPECT_NE(flow.experimenterStatus().front().find("replays: 2"), std::string::npos);
        // The participant sees the scale and its anchors, not which clip plays.
        const std::string text = screenText(flow.participantScreen());
        EXPECT_EQ(text.find(player.last), std::string::npos) << text;
        EXPECT_NE(text.find(flow.sections()[0].prompt), std::string::npos);
    }
}

TEST_F(TrialFlowTest, RefusedDoneTellsTheParticipantWhichQuestionsAreOpen) {
    briefed();
    ASSERT_TRUE(flow.start());
    EXPECT_TRUE(flow.participantScreen().notice.empty()) << "nothing refused yet";
    flow.chooseLetter('a');
    EXPECT_EQ(flow.unansweredSections(), (std::vector<int>{1, 2}));
    ASSERT_EQ(flow.commit().refusal, Refusal::Incomplete);
    ParticipantScreen s = flow.participantScreen();
    EXPECT_EQ(s.unanswered, (std::vector<int>{1, 2}));
    // The participant reads how many questions are open (or the open one's prompt), never the
    // store's wording (scale ids).
    EXPECT_EQ(s.notice, "Please answer the 2 questions still open first.");
    flow.typeDigit(3);
    s = flow.participantScreen();
    EXPECT_EQ(s.unanswered, (std::vector<int>{2})) << "the list follows the draft";
    EXPECT_EQ(s.notice, "Please answer this question first: " + flow.sections()[2].prompt);
    flow.setRating("quality", 4);
    EXPECT_TRUE(flow.participantScreen().notice.empty()) << "complete: nothing to say";
    ASSERT_TRUE(flow.commit());
    EXPECT_TRUE(flow.participantScreen().notice.empty()) << "a new trial starts clean";
}

TEST_F(TrialFlowTest, ExperimenterPauseHoldsEverythingAndIsJournaled) {
    EXPECT_EQ(flow.pause().refusal, Refusal::NotInTrial) << "only a trial is paused";
    session.finishBriefing();
    flow.reset();
    ASSERT_TRUE(flow.start());
    ASSERT_TRUE(flow.pause());
    EXPECT_TRUE(flow.held());
    EXPECT_EQ(flow.pause().refusal, Refusal::NotAllowed);
    EXPECT_EQ(flow.chooseLetter('a').refusal, Refusal::Paused);
    EXPECT_EQ(flow.typeDigit(3).refusal, Refusal::Paused);
    EXPECT_EQ(flow.setRating("quality", 3).refusal, Refusal::Paused);
    flow.adjust(1);
    EXPECT_TRUE(flow.draft().answer.empty() && flow.draft().ratings.empty());
    EXPECT_EQ(flow.commit().refusal, Refusal::Paused);
    flow.reset(); // a redraw by the front end keeps the pause
    ParticipantScreen s = flow.participantScreen();
    EXPECT_FALSE(s.answering);
    EXPECT_EQ(s.text, "Please wait a moment.");
    ASSERT_TRUE(flow.resume());
    EXPECT_EQ(flow.resume().refusal, Refusal::NotAllowed);
    EXPECT_TRUE(flow.participantScreen().answering);
    EXPECT_TRUE(flow.chooseLetter('a'));
    // A sensor fault holds the draft the same way.
    session.sensorFault("FSR shoes unplugged");
    const FlowResult faulted = flow.typeDigit(4);
    EXPECT_EQ(faulted.refusal, Refusal::Paused);
    EXPECT_NE(faulted.message.find("FSR shoes unplugged"), std::string::npos) << faulted.message;
    EXPECT_FALSE(flow.participantScreen().answering);
    session.resumeAfterFault();
    int paused = 0, resumed = 0;
    for (const auto& e : store.events()) {
        paused += e.kind == "paused";
        resumed += e.kind == "resumed";
    }
    EXPECT_EQ(paused, 1);
    EXPECT_EQ(resumed, 1);
}

// The protocol's rules are the trial core's: the answer the store would take as it is (see
// ExperimentStore.KeepsOnlyTheSchemaNotTheProtocol) is refused here, with every reason, and
// nothing is stored.
TEST(TrialFlow, ProtocolRulesAreTheTrialCoresNotTheStores) {
    TempDir dir;
    StudyStore store = StudyStore::create(
        dir.file("p.db"), loadProtocol(shipped("tvcg2011_exp2.toml")), {"P", "lab", 3, "t"});
    NewParticipant np{"P01", {}, "", "", "", {}, ""};
    np.groupOverride = "coherent";
    np.overrideReason = "test";
    store.registerParticipant(np);
    FakePlayer player;
    Session session(store, "P01", player, {});
    TrialFlow flow(store, session);
    session.finishBriefing();
    flow.reset();
    ASSERT_TRUE(flow.start());
    TrialAnswer bad;
    bad.answer = "lava";
    bad.ratings["realism"] = 8;
    const int index = session.current().index;
    const FlowResult r = flow.submit(bad);
    EXPECT_EQ(r.refusal, Refusal::Incomplete);
    for (const char* why :
         {"'lava' is not an option of the answer list", "rating 'realism' is 8; expected 1 to 7",
          "the rating 'quality' is missing", "the soundscape answer is missing"})
        EXPECT_NE(r.message.find(why), std::string::npos) << why << " in: " << r.message;
    EXPECT_FALSE(store.trial("P01", index).answered);
    EXPECT_TRUE(session.playing()) << "the trial stays current";
}

// The lock rule holds across sessions: once a later trial started (then the session was
// interrupted), the earlier answer is neither offered for a change nor stored as one.
TEST(TrialFlow, LockRuleCountsTrialsStartedInAnEarlierSession) {
    TempDir dir;
    StudyStore store = makeStudy(dir, "next_trial");
    FakePlayer player;
    {
        Session session(store, "P1", player, {});
        TrialFlow flow(store, session);
        session.finishBriefing();
        flow.reset();
        ASSERT_TRUE(flow.start());
        flow.chooseLetter('a');
        flow.typeDigit(2);
        flow.typeDigit(5);
        ASSERT_TRUE(flow.commit());
        ASSERT_TRUE(flow.start()); // the next trial's stimulus starts, then the session stops
        session.interrupt();
    }
    Session again(store, "P1", player, {});
    TrialFlow flow(store, again);
    ASSERT_TRUE(again.resumed());
    const FlowResult r = flow.revisePrevious();
    EXPECT_EQ(r.refusal, Refusal::Locked);
    EXPECT_NE(r.message.find("lock = \"next_trial\""), std::string::npos) << r.message;
}

// The text front end's model: the terminal prints these prompts and forwards typed lines, which
// the flow reads (a letter, a whole number on the scale) and refuses with what was expected.
TEST_F(TrialFlowTest, TextPromptsAndTypedLinesAreTheCores) {
    EXPECT_EQ(flow.startPrompt(), "") << "no trial during the briefing";
    session.finishBriefing();
    flow.reset();
    EXPECT_EQ(flow.startPrompt(), "Press Enter to start the stimulus. ");
    EXPECT_EQ(flow.lapPrompt(), "") << "a protocol without laps";
    ASSERT_TRUE(flow.start());
    EXPECT_EQ(flow.startPrompt(), "");
    const auto lines = flow.sectionLines(0);
    ASSERT_GE(lines.size(), 3u);
    EXPECT_EQ(lines[0], store.protocol().questions.surfacePrompt);
    EXPECT_EQ(lines[2], "  b. " + store.protocol().questions.surfaceOptions[1].label);
    EXPECT_EQ(flow.sectionInputPrompt(0), "letter> ");
    EXPECT_TRUE(flow.sectionLines(1).empty()) << "a scale's prompt is its input prompt";
    EXPECT_EQ(flow.sectionInputPrompt(2), "Quality [0 .. 10; 0 = bad, 10 = excellent]> ");

    EXPECT_NE(flow.typeLine(0, "wood").message.find("expected one of the letters a-"),
              std::string::npos);
    EXPECT_EQ(flow.typeLine(0, "z").refusal, Refusal::NotAllowed);
    EXPECT_FALSE(flow.sectionAnswered(0));
    ASSERT_TRUE(flow.typeLine(0, "b"));
    EXPECT_TRUE(flow.sectionAnswered(0));
    EXPECT_EQ(flow.draft().answer, "gravel");
    EXPECT_EQ(flow.typeLine(1, "5x").message, "expected a whole number from 1 to 7");
    EXPECT_EQ(flow.typeLine(1, "9").refusal, Refusal::OutOfRange);
    EXPECT_FALSE(flow.sectionAnswered(1));
    ASSERT_TRUE(flow.typeLine(1, "5"));
    ASSERT_TRUE(flow.typeLine(2, "10"));
    EXPECT_EQ(flow.draft().ratings.at("quality"), 10);
    EXPECT_EQ(flow.typeLine(2, "r").refusal, Refusal::NotAllowed) << "'r' only in listening tests";
    ASSERT_TRUE(flow.commit());
}

// The lap prompt follows the protocol's laps: 1 silent baseline lap and 2 with sound.
TEST(TrialFlow, LapPromptFollowsTheProtocolsLaps) {
    TempDir dir;
    std::string text;
    {
        std::ifstream in(shipped("wading_interactive.toml"));
        std::ostringstream s;
        s << in.rdbuf();
        text = s.str();
    }
    const auto at = text.find("baseline = 3\nfeedback = 3");
    ASSERT_NE(at, std::string::npos);
    text.replace(at, 25, "baseline = 1\nfeedback = 2");
    StudyStore store = StudyStore::create(dir.file("l.db"), parseProtocol(text, "laps.toml"),
                                          {"L", "lab", 3, "t"});
    store.registerParticipant({"P1", {}, "", "", "", {}, ""});
    FakePlayer player;
    Session session(store, "P1", player, {});
    TrialFlow flow(store, session);
    session.finishBriefing();
    flow.reset();
    EXPECT_EQ(flow.lapPrompt(), "") << "not started";
    ASSERT_TRUE(flow.start());
    std::vector<std::string> prompts;
    for (std::string p; !(p = flow.lapPrompt()).empty();) {
        prompts.push_back(p);
        ASSERT_TRUE(flow.completeLap());
    }
    EXPECT_EQ(prompts, (std::vector<std::string>{
                           "Lap 1 of 3 (silent baseline). Press Enter when it is walked. ",
                           "Lap 2 of 3 (with sound). Press Enter when it is walked. ",
                           "Lap 3 of 3 (with sound). Press Enter when it is walked. "}));
    EXPECT_EQ(flow.commentPrompt(), "comment (Enter for none)> ");
}
