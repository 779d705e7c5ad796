// Simulated participants (study/study_simulation.h): a whole study runs headless, each participant
// in their Latin-square order, and a run stopped part-way resumes without losing a finished trial.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "test_support.h"
#include "vrdeform/error.h"
#include "vrdeform/metrics/latin_square.h"
#include "vrdeform/scene/scene_library.h"
#include "vrdeform/study/study_analysis.h"
#include "vrdeform/study/study_file.h"
#include "vrdeform/study/study_simulation.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;

// The liver's poke (4.3 s with its release) under each condition, one trial each.
constexpr const char* kSimulatedStudy = R"(format = 1
name = "poke"
trials = 1
[[condition]]
name = "A"
scene = "liver"
[[condition]]
name = "B"
scene = "liver"
force = "baseline"
[[task]]
name = "poke"
seconds = 4.5
[[question]]
id = "V1"
dimension = "visual"
text = "It looked soft."
[[question]]
id = "H1"
dimension = "haptic"
text = "The force grew as I pressed."
[[question]]
id = "H2"
dimension = "haptic"
text = "The force felt smooth."
[[comparison]]
id = "D1"
text = "Which force felt more natural?"
[[free_text]]
id = "F1"
text = "What did you feel?"
[[free_text]]
id = "F2"
text = "Which felt best?"
after = "study"
)";

struct RunFolder {
  fs::path path;
  explicit RunFolder(const std::string& name) : path(fs::temp_directory_path() / ("vrdeform_study_sim_" + name)) {
    fs::remove_all(path);
  }
  ~RunFolder() { fs::remove_all(path); }
};

using testing::readBytes;

// Participant k's record of the trial in trials/<dir> (position-task-trial).
nlohmann::json trialJson(const fs::path& data, int k, const std::string& dir) {
  return nlohmann::json::parse(readBytes(testing::participantFolder(data, k) / "trials" / dir / "trial.json"));
}

bool anyPartial(const fs::path& dir) {
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename().string().ends_with(".partial")) return true;
  return false;
}

TEST(StudySimulation, FourParticipantsRunTheStudyInTheirOrders) {
  const StudySpec study = parseStudy(kSimulatedStudy, "poke.toml", ".");
  RunFolder data("four");
  for (std::size_t k = 1; k <= 4; ++k) {
    StudyRunSettings s;
    s.dataDir = data.path;
    s.participant = k;
    const StudyRunResult r = runSimulatedParticipant(study, s);
    EXPECT_EQ(r.trialsRun, 2u);
    EXPECT_EQ(r.trialsKept, 0u);
    const nlohmann::json who =
        nlohmann::json::parse(readBytes(testing::participantFolder(data.path, k) / "participant.json"));
    const std::vector<std::size_t> order = latinSquareOrder(2, k - 1);
    ASSERT_EQ(who["order"].size(), 2u);
    for (std::size_t pos = 0; pos < 2; ++pos) {
      EXPECT_EQ(who["order"][pos], study.conditions[order[pos]].name) << "P" << k << " position " << pos + 1;
      const nlohmann::json trial = trialJson(data.path, int(k), std::to_string(pos + 1) + "-1-1");
      EXPECT_EQ(trial["condition"], study.conditions[order[pos]].name);
    }
  }
  EXPECT_FALSE(anyPartial(data.path));
  const std::vector<ParticipantAnswers> people = readStudyAnswers(study, data.path);
  ASSERT_EQ(people.size(), 4u);
  for (const ParticipantAnswers& p : people) {
    for (const auto& condition : p.answers)
      for (const auto& answer : condition) EXPECT_TRUE(answer.has_value()) << p.id;
    EXPECT_TRUE(p.comparisons[0].has_value()) << p.id;
    // F1 after each condition, F2 once: what was felt, in words (B's baseline steps up at first contact).
    ASSERT_EQ(p.freeText.size(), 3u) << p.id;
    for (const FreeTextAnswer& f : p.freeText) {
      EXPECT_EQ(f.condition.has_value(), f.item == 0) << p.id;
      if (f.condition) {
        EXPECT_NE(f.text.find(*f.condition == 0 ? "grew smoothly" : "jumped"), std::string::npos) << f.text;
      }
    }
    EXPECT_EQ(p.freeText.back().text, "A felt best.") << p.id;
  }
  // What was felt decides the felt items: A's force rises with the indentation, B's baseline is
  // flat while loading (a step), so every participant rates the haptic dimension higher under A.
  const StudyAnalysis a = analyseStudy(study, people);
  const Measure& haptic = a.measures[4];  // V1, H1, H2, then the dimensions visual and haptic
  ASSERT_EQ(haptic.name, "haptic");
  for (std::size_t k = 0; k < 4; ++k) EXPECT_GT(*haptic.byCondition[0][k], *haptic.byCondition[1][k]) << "P" << k + 1;
  EXPECT_LT(a.comparisons[0].mean, 0.0) << "D1 favours A";
}

// The practice trial runs first, into its own folder, is kept on a second run and is not analysed.
TEST(StudySimulation, ThePracticeTrialComesFirstAndIsKept) {
  const StudySpec study =
      parseStudy(std::string(kSimulatedStudy) + "[practice]\nscene = \"jelly\"\nseconds = 0.5\n", "practice.toml", ".");
  RunFolder data("practice");
  StudyRunSettings s;
  s.dataDir = data.path;
  std::vector<std::string> log;
  s.log = [&](const std::string& line) { log.push_back(line); };
  EXPECT_EQ(runSimulatedParticipant(study, s).trialsRun, 3u);
  ASSERT_FALSE(log.empty());
  EXPECT_EQ(log.front(), "P1: practice");
  const nlohmann::json trial = nlohmann::json::parse(readBytes(data.path / "P1" / "practice" / "trial.json"));
  EXPECT_EQ(trial["condition"], "practice");
  EXPECT_EQ(trial["scene"], "jelly");
  EXPECT_EQ(trial["steps"], 30);
  const StudyRunResult again = runSimulatedParticipant(study, s);
  EXPECT_EQ(again.trialsRun, 0u);
  EXPECT_EQ(again.trialsKept, 3u);
  EXPECT_EQ(readStudyAnswers(study, data.path).size(), 1u);
}

// Each trial runs its condition's scene with the condition's own solver settings, and says so.
TEST(StudySimulation, EachConditionRunsWithItsOwnSolverSettings) {
  std::string text = kSimulatedStudy;
  const std::string afterB = "force = \"baseline\"\n";
  text.insert(text.find(afterB) + afterB.size(), "[condition.solver]\niterations = 2\n");
  text.replace(text.find("seconds = 4.5"), 13, "seconds = 0.5");
  const StudySpec study = parseStudy(text, "solver.toml", ".");
  RunFolder data("solver");
  StudyRunSettings s;
  s.dataDir = data.path;
  EXPECT_EQ(runSimulatedParticipant(study, s).trialsRun, 2u);
  const std::vector<std::size_t> order = study.orderOf(1);
  for (std::size_t pos = 0; pos < 2; ++pos) {
    const StudyCondition& c = study.conditions[order[pos]];
    const nlohmann::json trial = trialJson(data.path, 1, std::to_string(pos + 1) + "-1-1");
    EXPECT_EQ(trial["condition"], c.name);
    EXPECT_EQ(trial["iterations"], c.name == "B" ? 2 : loadSceneByName("liver").solver.iterations);
    EXPECT_EQ(trial["substeps"], loadSceneByName("liver").solver.substeps);
  }
}

// A task that ends when the hand lets go: the liver's poke releases at 3-4 s, so the trial ends
// half a second after, not at its 8 s, and says so.
TEST(StudySimulation, ATrialEndsWhenItsTasksEndConditionIsMet) {
  std::string text = kSimulatedStudy;
  text.replace(text.find("seconds = 4.5"), 13, "seconds = 8\nend = \"release\"");
  const StudySpec study = parseStudy(text, "release.toml", ".");
  RunFolder data("release");
  StudyRunSettings s;
  s.dataDir = data.path;
  EXPECT_EQ(runSimulatedParticipant(study, s).trialsRun, 2u);
  for (const char* trialDir : {"1-1-1", "2-1-1"}) {
    const nlohmann::json trial = trialJson(data.path, 1, trialDir);
    EXPECT_EQ(trial["ended_by"], "release") << trialDir;
    EXPECT_GE(trial["steps"].get<int>(), 180) << trialDir;  // at least the approach and hold, 3 s
    EXPECT_LE(trial["steps"].get<int>(), 270) << trialDir;  // before the pinch at 4.5 s
    // The index touched the liver, then let go: the last event, half a second before the end.
    const std::string events = readBytes(testing::participantFolder(data.path, 1) / "trials" / trialDir / "events.csv");
    EXPECT_NE(events.find(",touch,index\n"), std::string::npos) << events;
    const std::size_t last = events.rfind(",untouch,index\n");
    ASSERT_NE(last, std::string::npos) << events;
    EXPECT_EQ(last + std::string(",untouch,index\n").size(), events.size()) << events;
  }
}

TEST(StudySimulation, AStoppedRunResumesKeepingEveryFinishedTrial) {
  const StudySpec study = parseStudy(kSimulatedStudy, "poke.toml", ".");
  RunFolder data("resumed"), whole("whole");
  StudyRunSettings s;
  s.dataDir = data.path;
  s.participant = 2;
  int trialsLogged = 0, polls = 0;
  s.log = [&](const std::string&) { ++trialsLogged; };
  s.stop = [&] { return trialsLogged >= 1 && ++polls > 100; };  // part-way into the second trial
  EXPECT_THROW(runSimulatedParticipant(study, s), Stopped);
  const fs::path first = data.path / "P2" / "trials" / "1-1-1";
  ASSERT_TRUE(fs::is_regular_file(first / "trial.json"));
  EXPECT_FALSE(fs::exists(data.path / "P2" / "trials" / "2-1-1"));
  EXPECT_FALSE(anyPartial(data.path));
  // The first condition's questionnaire was answered after its trial: its rows alone.
  const std::string firstAnswers = readBytes(data.path / "P2" / "answers.csv");
  EXPECT_EQ(std::count(firstAnswers.begin(), firstAnswers.end(), '\n'), 4) << firstAnswers;
  EXPECT_EQ(firstAnswers.find("\n" + study.conditions[study.orderOf(2)[1]].name + ","), std::string::npos);
  EXPECT_FALSE(fs::exists(data.path / "P2" / "comparisons.csv"));
  const std::string kept = readBytes(first / "trial.json");
  const fs::file_time_type keptTime = fs::last_write_time(first / "trial.json");

  s.stop = nullptr;
  const StudyRunResult r = runSimulatedParticipant(study, s);
  EXPECT_EQ(r.trialsKept, 1u);
  EXPECT_EQ(r.trialsRun, 1u);
  EXPECT_EQ(readBytes(first / "trial.json"), kept);
  EXPECT_EQ(fs::last_write_time(first / "trial.json"), keptTime);

  s.dataDir = whole.path;  // the same participant in one go answers the same
  runSimulatedParticipant(study, s);
  EXPECT_EQ(readBytes(data.path / "P2" / "answers.csv"), readBytes(whole.path / "P2" / "answers.csv"));
  EXPECT_EQ(readBytes(data.path / "P2" / "comparisons.csv"), readBytes(whole.path / "P2" / "comparisons.csv"));

  fs::remove(first / "trial.json");  // a broken record is named, not run over
  { std::ofstream(first / "trial.json") << "{\"felt\": 1}"; }
  try {
    runSimulatedParticipant(study, s = StudyRunSettings{data.path, 2, {}, nullptr, nullptr});
    ADD_FAILURE() << "a broken trial record should be refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not a finished trial's record"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace vrd
