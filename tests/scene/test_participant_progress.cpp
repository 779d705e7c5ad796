// A participant's way through a study (study/participant_progress.h): the steps in the order they
// are met, each finished one on disk whole, a resume from any point, and answers checked against
// the study's scales before anything is written.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "test_support.h"
#include "vrdeform/error.h"
#include "vrdeform/study/participant_progress.h"
#include "vrdeform/study/study_analysis.h"
#include "vrdeform/study/study_file.h"
#include "vrdeform/study/task_end.h"
#include "vrdeform/study/trial_events.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;

// Two conditions, one task of two trials each, a rest between, every kind of question.
constexpr const char* kWalkedStudy = R"(format = 1
name = "walk"
trials = 2
rest = 60
points = 5
comparison_range = 2
[practice]
seconds = 0.5
[[condition]]
name = "A"
scene = "liver"
[[condition]]
name = "B"
scene = "liver"
force = "baseline"
[[task]]
name = "poke"
seconds = 1
[[question]]
id = "H1"
dimension = "haptic"
text = "The force grew as I pressed."
[[question]]
id = "V1"
dimension = "visual"
text = "It looked soft."
[[comparison]]
id = "D1"
text = "Which felt more natural?"
[[free_text]]
id = "F1"
text = "What did you feel?"
[[free_text]]
id = "F2"
text = "Which felt best?"
after = "study"
)";

using Kind = StudyStepKind;

// Does next()'s trial as a front end would: a file in the scratch folder, then the record.
void doTrial(ParticipantProgress& p) {
  const fs::path scratch = p.beginTrial();
  { std::ofstream(scratch / "forces.csv") << "step\n1\n"; }
  p.finishTrial({60, 1.0, std::nullopt});
}

TEST(ParticipantProgress, WalksPracticeTrialsQuestionsAndRestsInTheParticipantsOrder) {
  const StudySpec study = parseStudy(kWalkedStudy, "walk.toml", ".");
  testing::TempDir data;
  ParticipantProgress p(study, data.path(), 2, false);
  const std::vector<std::size_t> order = study.orderOf(2);
  ASSERT_EQ(order, (std::vector<std::size_t>{1, 0}));  // Williams' square, row 2: B first
  std::vector<Kind> kinds;
  for (StudyStep s = p.next(); s.kind != Kind::Done; s = p.next()) {
    kinds.push_back(s.kind);
    if (s.kind == Kind::Trial) {
      EXPECT_EQ(s.condition, order[s.position]);
      EXPECT_EQ(p.trialFolder(s), p.folder() / "trials" / fmt::format("{}-1-{}", s.position + 1, s.trial));
    }
    switch (s.kind) {
      case Kind::Practice:
      case Kind::Trial:
        doTrial(p);
        break;
      case Kind::Rest:
        p.finishRest();
        break;
      case Kind::ConditionQuestions:
        p.answer(ConditionAnswers{{s.condition == 0 ? 5 : 2, 4}, {fmt::format("felt {}", s.position)}});
        break;
      case Kind::StudyQuestions:
        p.answer(FinalAnswers{{-2}, {"A, clearly"}});
        break;
      case Kind::Done:
        break;
    }
  }
  EXPECT_EQ(kinds, (std::vector<Kind>{Kind::Practice, Kind::Trial, Kind::Trial, Kind::ConditionQuestions, Kind::Rest,
                                      Kind::Trial, Kind::Trial, Kind::ConditionQuestions, Kind::StudyQuestions}));
  const nlohmann::json trial =
      nlohmann::json::parse(testing::readBytes(p.folder() / "trials" / "1-1-2" / "trial.json"));
  EXPECT_EQ(trial["condition"], "B");
  EXPECT_EQ(trial["force"], "baseline");
  EXPECT_EQ(trial["steps"], 60);
  EXPECT_TRUE(fs::is_regular_file(p.folder() / "practice" / "forces.csv"));
  EXPECT_EQ(nlohmann::json::parse(testing::readBytes(p.folder() / "participant.json"))["order"],
            nlohmann::json::array({"B", "A"}));
  // What the analysis reads, in the participant's order.
  EXPECT_EQ(testing::readBytes(p.folder() / "answers.csv"), "condition,item,answer\nB,H1,2\nB,V1,4\nA,H1,5\nA,V1,4\n");
  EXPECT_EQ(testing::readBytes(p.folder() / "comparisons.csv"), "item,rating\nD1,-2\n");
  const std::vector<ParticipantAnswers> people = readStudyAnswers(study, data.path());
  ASSERT_EQ(people.size(), 1u);
  ASSERT_EQ(people[0].freeText.size(), 3u);
  EXPECT_EQ(people[0].freeText[0].text, "felt 0");
  EXPECT_EQ(people[0].freeText[0].condition, std::optional<std::size_t>(1));
  EXPECT_EQ(people[0].freeText[2].text, "A, clearly");
  EXPECT_EQ(people[0].comparisons[0], -2);
}

TEST(ParticipantProgress, AResumeGoesOnFromTheFirstStepNotFinished) {
  const StudySpec study = parseStudy(kWalkedStudy, "walk.toml", ".");
  testing::TempDir data;
  {
    ParticipantProgress p(study, data.path(), 1, false);
    doTrial(p);  // practice
    doTrial(p);
    p.beginTrial();  // killed during the second trial: its scratch folder is left
  }
  {
    ParticipantProgress p(study, data.path(), 1, false);
    EXPECT_EQ(p.trialsKept(), 2u);
    EXPECT_EQ(p.next().kind, Kind::Trial);
    EXPECT_EQ(p.next().trial, 2);
    doTrial(p);
    EXPECT_FALSE(fs::exists(p.folder() / "trials" / "1-1-2.partial"));
    p.answer(ConditionAnswers{{3, 3}, {"ok"}});
    EXPECT_EQ(p.next().kind, Kind::Rest);
    p.finishRest();
    doTrial(p);  // the second condition begun
  }
  // Its rest was taken before it began: not due again; the answers so far are kept.
  ParticipantProgress p(study, data.path(), 1, false);
  EXPECT_EQ(p.trialsKept(), 4u);
  EXPECT_EQ(p.next().kind, Kind::Trial);
  EXPECT_EQ(p.next().position, 1u);
  EXPECT_EQ(p.next().trial, 2);
  EXPECT_EQ(testing::readBytes(p.folder() / "answers.csv"), "condition,item,answer\nA,H1,3\nA,V1,3\n");
}

TEST(ParticipantProgress, AnswersOffTheScaleOrMissingAreRefusedAndNothingIsWritten) {
  const StudySpec study = parseStudy(kWalkedStudy, "walk.toml", ".");
  testing::TempDir data;
  ParticipantProgress p(study, data.path(), 1, false);
  EXPECT_THROW(p.answer(ConditionAnswers{{3, 3}, {"too early"}}), Error);
  for (int i = 0; i < 3; ++i) doTrial(p);
  const auto refused = [&](const ConditionAnswers& a, const std::string& why) {
    try {
      p.answer(a);
      ADD_FAILURE() << "accepted: " << why;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  };
  refused({{6, 3}, {""}}, "H1: 6 is not on the scale 1..5");
  refused({{3, 0}, {""}}, "V1: 0 is not on the scale 1..5");
  refused({{3}, {""}}, "Likert answers: 1, the study asks 2");
  refused({{3, 3}, {}}, "free-text answers: 0, the study asks 1");
  EXPECT_FALSE(fs::exists(p.folder() / "answers.csv"));
  EXPECT_EQ(p.next().kind, Kind::ConditionQuestions);
}

TEST(ParticipantProgress, ABrokenRecordIsNamedBeforeAnyWork) {
  const StudySpec study = parseStudy(kWalkedStudy, "walk.toml", ".");
  testing::TempDir data;
  {
    ParticipantProgress p(study, data.path(), 1, false);
    for (int i = 0; i < 3; ++i) doTrial(p);
    p.answer(ConditionAnswers{{3, 3}, {"ok"}});
  }
  const fs::path answered = data.path() / "P1" / "questionnaires" / "1.json";
  ASSERT_TRUE(fs::is_regular_file(answered));
  { std::ofstream(answered) << R"({"likert": {"H1": 3}, "free_text": {"F1": "ok"}})"; }  // V1 lost
  try {
    ParticipantProgress p(study, data.path(), 1, false);
    ADD_FAILURE() << "a questionnaire without V1 was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("1.json: not a finished questionnaire's record"), std::string::npos)
        << e.what();
  }
}

// A poke ends half a second after the hand let go; a grasp task when the grasp lets go; a lift
// between two presses does not end a poke.
TEST(TaskEndWatch, EndsAPokeOnReleaseAndAGraspWhenItLetsGo) {
  TaskEndWatch time(TaskEnd::Time), poke(TaskEnd::Release), grasp(TaskEnd::GraspRelease);
  const double dt = 0.01;
  int pokeEnded = -1, graspEnded = -1;
  for (int k = 0; k < 400; ++k) {
    const double t = k * dt;
    // Touching 0.5-1.0 s, lifted 0.3 s, touching again 1.3-2.0 s (a grasp 1.5-1.8 s), then free.
    const bool grasping = t >= 1.5 && t < 1.8;
    const bool contact = (t >= 0.5 && t < 1.0) || (t >= 1.3 && t < 2.0);
    EXPECT_FALSE(time.update(contact, grasping, t));
    if (poke.update(contact, grasping, t) && pokeEnded < 0) pokeEnded = k;
    if (grasp.update(contact, grasping, t) && graspEnded < 0) graspEnded = k;
  }
  EXPECT_EQ(pokeEnded, 249);   // the last contact at step 199 (1.99 s), half a second later
  EXPECT_EQ(graspEnded, 180);  // the first step without the grasp
}

// Each finger's touches and the grasps, at the step they begin and end; absent fingers say nothing.
TEST(TrialEvents, NameEachTouchAndGraspAtItsStep) {
  TrialEvents events;
  for (std::uint64_t k = 1; k <= 8; ++k) {
    HapticSample s;
    s.step = k;
    s.time = 0.5 * double(k);
    s.present = {true, true, true, false, false};
    s.contacts[1] = k >= 3 && k <= 5 ? 2u : 0u;  // index
    s.contacts[0] = k >= 4 && k <= 6 ? 1u : 0u;  // thumb
    s.contacts[3] = 7;                           // ring: not on this hand
    s.grasp = k >= 4 && k <= 5;
    events.send(s);
  }
  EXPECT_EQ(events.csv(),
            "step,time_s,event,finger\n3,1.5,touch,index\n4,2,touch,thumb\n4,2,grasp,\n6,3,untouch,index\n"
            "6,3,ungrasp,\n7,3.5,untouch,thumb\n");
}

}  // namespace
}  // namespace vrd
