// Study files (study/study_file.h): the paper's study reads as written, the orders follow the
// balanced Latin square, and every mistake is named with its file, line and key.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "vrdeform/error.h"
#include "vrdeform/metrics/latin_square.h"
#include "vrdeform/scene/scene_library.h"
#include "vrdeform/study/study_file.h"

namespace vrd {
namespace {

const std::filesystem::path kStudies = std::filesystem::path(VRDEFORM_TEST_DATA_DIR) / ".." / "studies";

constexpr const char* kSmall = R"(format = 1
name = "small"
[[condition]]
name = "A"
scene = "liver"
[[condition]]
name = "B"
scene = "liver"
force = "baseline"
[[condition]]
name = "C"
scene = "jelly"
[[task]]
name = "poke"
[[question]]
id = "H1"
dimension = "haptic"
text = "It felt soft."
[[comparison]]
id = "D1"
text = "Which was better?"
between = ["C", "A"]
)";

std::string studyError(const std::string& text) {
  try {
    parseStudy(text, "s.toml", ".");
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(StudyFile, ThePapersStudyReadsAsWritten) {
  const StudySpec s = loadStudy(kStudies / "paper.toml");
  ASSERT_EQ(s.conditions.size(), 2u);
  EXPECT_EQ(s.conditions[0].force, StudyForce::Multipliers);
  EXPECT_EQ(s.conditions[1].force, StudyForce::Baseline);
  EXPECT_EQ(s.tasks.size(), 2u);
  EXPECT_EQ(s.trials, 3);
  EXPECT_DOUBLE_EQ(s.restSeconds, 600.0);
  EXPECT_EQ(s.questions.size(), 12u);
  EXPECT_EQ(s.dimensions(), (std::vector<std::string>{"visual", "haptic", "congruence", "stability"}));
  ASSERT_EQ(s.comparisons.size(), 4u);
  EXPECT_EQ(s.comparisons[3].a, 0u);
  EXPECT_EQ(s.comparisons[3].b, 1u);
  EXPECT_EQ(s.comparisonRange, 3);
}

TEST(StudyFile, OrdersFollowTheBalancedLatinSquare) {
  StudySpec s = parseStudy(kSmall, "s.toml", ".");
  ASSERT_EQ(s.conditions.size(), 3u);
  for (std::size_t k = 1; k <= 12; ++k) EXPECT_EQ(s.orderOf(k), latinSquareOrder(3, k - 1)) << "participant " << k;
  EXPECT_NE(s.orderOf(1), s.orderOf(2));
  EXPECT_EQ(s.comparisons[0].a, 2u);  // between = ["C", "A"]
  EXPECT_EQ(s.comparisons[0].b, 0u);
  s.order = Counterbalancing::Fixed;
  EXPECT_EQ(s.orderOf(5), (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_THROW(s.orderOf(0), Error);
}

TEST(StudyFile, FreeTextItemsAreAskedAfterEachConditionOrOnce) {
  const StudySpec s = parseStudy(std::string(kSmall) +
                                     "[[free_text]]\nid = \"F1\"\ntext = \"What did you feel?\"\n"
                                     "[[free_text]]\nid = \"F2\"\ntext = \"Anything else?\"\nafter = \"study\"\n",
                                 "s.toml", ".");
  ASSERT_EQ(s.freeTexts.size(), 2u);
  EXPECT_EQ(s.freeTexts[0].id, "F1");
  EXPECT_EQ(s.freeTexts[0].text, "What did you feel?");
  EXPECT_TRUE(s.freeTexts[0].perCondition);
  EXPECT_FALSE(s.freeTexts[1].perCondition);
  EXPECT_EQ(studyError(std::string(kSmall) + "[[free_text]]\nid = \"D1\"\ntext = \"x\"\n"),
            "s.toml:24: free_text[1].id: 'D1' is the id of an earlier entry too");
  EXPECT_EQ(studyError(std::string(kSmall) + "[[free_text]]\nid = \"F1\"\ntext = \"x\"\nafter = \"trial\"\n"),
            "s.toml:26: free_text[1].after: unknown value 'trial' (expected one of: condition, study)");
  EXPECT_EQ(studyError(std::string(kSmall) + "[[free_text]]\nid = \"F1\"\n"), "s.toml:23: free_text[1].text: missing");
}

// A practice trial on the first condition's scene unless it names its own.
TEST(StudyFile, APracticeTrialComesFirst) {
  EXPECT_FALSE(parseStudy(kSmall, "s.toml", ".").practice);
  const StudySpec s =
      parseStudy(std::string(kSmall) + "[practice]\nseconds = 30\ninstructions = \"Try it.\"\n", "s.toml", ".");
  ASSERT_TRUE(s.practice);
  EXPECT_EQ(s.practice->condition.scene, "liver");
  EXPECT_EQ(s.practice->condition.force, StudyForce::Multipliers);
  EXPECT_EQ(s.practice->task.seconds, 30.0);
  EXPECT_EQ(s.practice->task.instructions, "Try it.");
  EXPECT_EQ(parseStudy(std::string(kSmall) + "[practice]\nscene = \"jelly\"\nforce = \"baseline\"\n", "s.toml", ".")
                .practice->condition.scene,
            "jelly");
  EXPECT_EQ(studyError(std::string(kSmall) + "[practice]\nscene = \"jely\"\n").substr(0, 40),
            "s.toml:24: practice.scene: no built-in s");
  EXPECT_EQ(
      studyError(std::string(kSmall) + "[practice]\ntrials = 2\n"),
      "s.toml:24: practice.trials: unknown key (expected one of: scene, force, device, osc, seconds, instructions, "
      "solver, "
      "haptics)");
  // On the first condition's scene, its solver keys over the condition's.
  const StudySpec tuned = parseStudy(std::string(kSmall) + "[practice.solver]\niterations = 2\n", "s.toml", ".");
  ASSERT_TRUE(tuned.practice);
  EXPECT_EQ(tuned.practice->condition.spec.solver.iterations, 2);
  EXPECT_EQ(tuned.practice->condition.spec.solver.substeps, tuned.conditions[0].spec.solver.substeps);
}

// A condition's [condition.solver] and [condition.haptics] go over its scene's settings: the keys it
// gives change, the rest stay the scene's, and a mistake there is named as in a scene file.
TEST(StudyFile, AConditionSetsItsOwnSolverAndHapticSettings) {
  const std::string small = kSmall;
  const auto with = [&](const std::string& table) {
    std::string text = small;
    const std::string after = "force = \"baseline\"\n";  // condition B, the lines 7-9
    text.insert(text.find(after) + after.size(), table);
    return text;
  };
  const StudySpec s =
      parseStudy(with("[condition.solver]\nsubsteps = 16\n[condition.haptics]\nalpha = 0.5\n"), "s.toml", ".");
  const SceneSpec liver = loadSceneByName("liver");
  ASSERT_EQ(s.conditions.size(), 3u);
  const SceneSpec &a = s.conditions[0].spec, &b = s.conditions[1].spec;
  EXPECT_EQ(a.name, "liver");
  EXPECT_EQ(a.solver.substeps, liver.solver.substeps);
  EXPECT_EQ(a.haptics.settings.signal.alphaT, liver.haptics.settings.signal.alphaT);
  EXPECT_EQ(b.solver.substeps, 16);
  EXPECT_NE(liver.solver.substeps, 16);
  EXPECT_EQ(b.solver.iterations, liver.solver.iterations);
  EXPECT_EQ(b.solver.timeStep, liver.solver.timeStep);
  EXPECT_EQ(b.haptics.settings.signal.alphaT, 0.5f);
  EXPECT_NE(liver.haptics.settings.signal.alphaT, 0.5f);
  EXPECT_EQ(b.haptics.calibrate, liver.haptics.calibrate);
  EXPECT_EQ(s.conditions[2].spec.name, "jelly");

  EXPECT_EQ(studyError(with("[condition.solver]\nsubsteps = 0\n")),
            "s.toml:11: condition[2].solver.substeps: must be in 1..1000, got 0");
  EXPECT_EQ(studyError(with("[condition.haptics]\nalpah = 0.5\n")),
            "s.toml:11: condition[2].haptics.alpah: unknown key (did you mean 'alpha'?)");
  EXPECT_EQ(studyError(with("[condition.output]\nplots = false\n")),
            "s.toml:10: condition[2].output: unknown key (expected one of: name, scene, force, device, osc, solver, "
            "haptics)");
}

// Where each condition's force goes, and when a task's trial ends.
TEST(StudyFile, ConditionsNameTheirDeviceAndTasksTheirEnd) {
  std::string text = kSmall;
  const std::string afterB = "force = \"baseline\"\n";  // condition B, line 9
  text.insert(text.find(afterB) + afterB.size(), "device = \"osc\"\nosc = \"127.0.0.1:9000\"\n");
  const std::string afterC = "scene = \"jelly\"\n";
  text.insert(text.find(afterC) + afterC.size(), "device = \"none\"\n");
  const std::string afterTask = "name = \"poke\"\n";
  text.insert(text.find(afterTask) + afterTask.size(), "end = \"release\"\nseconds = 20\n");
  const StudySpec s = parseStudy(text, "s.toml", ".");
  EXPECT_EQ(s.conditions[0].device, StudyDevice::Glove);
  EXPECT_EQ(s.conditions[1].device, StudyDevice::Osc);
  EXPECT_EQ(s.conditions[1].osc, "127.0.0.1:9000");
  EXPECT_EQ(s.conditions[2].device, StudyDevice::None);
  EXPECT_EQ(s.tasks[0].end, TaskEnd::Release);
  EXPECT_EQ(s.tasks[0].seconds, 20.0);

  const auto with = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    t.replace(t.find(from), from.size(), to);
    return studyError(t);
  };
  EXPECT_EQ(with("osc = \"127.0.0.1:9000\"\n", ""),
            "s.toml:6: condition[2].osc: device = \"osc\" needs osc = \"HOST:PORT\"");
  EXPECT_EQ(with("127.0.0.1:9000", "127.0.0.1"),
            "s.toml:11: condition[2].osc: \"127.0.0.1\": expected HOST:PORT or [IPv6]:PORT");
  EXPECT_EQ(with("device = \"osc\"", "device = \"glove\""), "s.toml:11: condition[2].osc: only for device = \"osc\"");
  EXPECT_EQ(with("device = \"none\"", "device = \"haptx\""),
            "s.toml:15: condition[3].device: unknown value 'haptx' (expected one of: glove, none, osc)");
  EXPECT_EQ(with("end = \"release\"", "end = \"lift\""),
            "s.toml:18: task[1].end: unknown value 'lift' (expected one of: time, release, grasp_release)");
}

TEST(StudyFile, MistakesAreNamedWithLineAndKey) {
  const std::string small = kSmall;
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string text = small;
    text.replace(text.find(from), from.size(), to);
    return studyError(text);
  };
  EXPECT_EQ(with("name = \"small\"", "name = \"small\"\ntrails = 3"),
            "s.toml:3: trails: unknown key (did you mean 'trials'?)");
  EXPECT_EQ(with("format = 1", "format = 2"), "s.toml:1: format: unknown format 2 (this vrdeform reads format 1)");
  EXPECT_EQ(with("scene = \"jelly\"", "scene = \"jely\""),
            "s.toml:12: condition[3].scene: no built-in scene 'jely' (built in: balloon, bear, drape, flag, furball, "
            "jelly, jelly_stack, liver, liver_pad; a scene file's path has a '/' or ends in .toml)");
  EXPECT_EQ(with("name = \"C\"", "name = \"A\""),
            "s.toml:11: condition[3].name: 'A' is the name of an earlier entry too");
  EXPECT_EQ(with("id = \"D1\"", "id = \"H1\""), "s.toml:20: comparison[1].id: 'H1' is the id of an earlier entry too");
  EXPECT_EQ(with("id = \"H1\"", "id = \"H,1\""),
            "s.toml:16: question[1].id: must not contain a comma, a quote or a line break (the data files hold it as a "
            "CSV field)");
  EXPECT_EQ(with("[\"C\", \"A\"]", "[\"C\", \"Z\"]"), "s.toml:22: comparison[1].between[2]: no condition 'Z'");
  EXPECT_EQ(with("[\"C\", \"A\"]", "[\"C\", \"C\"]"), "s.toml:22: comparison[1].between: names one condition twice");
  EXPECT_EQ(with("force = \"baseline\"", "force = \"vendor\""),
            "s.toml:9: condition[2].force: unknown value 'vendor' (expected one of: multipliers, baseline)");
  EXPECT_EQ(with("name = \"small\"", "name = \"small\"\npoints = 1"), "s.toml:3: points: must be in 2..11, got 1");
  EXPECT_EQ(studyError("format = 1\nname = \"x\"\n[[condition]]\nname = \"A\"\nscene = \"liver\"\n"),
            "s.toml:3: condition: a within-subject study needs two or more [[condition]]s");
  EXPECT_EQ(
      studyError("format = 1\nname = \"x\"\n[[condition]]\nname = \"A\"\nscene = \"liver\"\n[[condition]]\nname = "
                 "\"B\"\nscene = \"liver\"\n"),
      "s.toml:1: task: needs at least one [[task]]");
  EXPECT_EQ(studyError("format = 1\nname = \"x\"\n[[condition]]\nname = \"A\"\nscene = \"nope/s.toml\"\n"),
            "s.toml:5: condition[1].scene: no such file '" +
                (std::filesystem::current_path() / "nope/s.toml").lexically_normal().string() + "'");
  EXPECT_EQ(studyError("format = 1\nname = [\n"),
            "s.toml:2: TOML syntax: Error while parsing array: encountered end-of-file");
}

}  // namespace
}  // namespace vrd
