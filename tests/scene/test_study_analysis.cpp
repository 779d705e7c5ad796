// `vrdeform study analyse` (study/study_analysis.h): answers read from a data folder, described and
// tested. The figures are worked by hand from the answers the tests write.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "test_support.h"
#include "vrdeform/core/write_file.h"
#include "vrdeform/error.h"
#include "vrdeform/study/study_analysis.h"
#include "vrdeform/study/study_file.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;

constexpr const char* kStudy = R"(format = 1
name = "two"
[[condition]]
name = "A"
scene = "liver"
[[condition]]
name = "B"
scene = "liver"
force = "baseline"
[[task]]
name = "poke"
[[question]]
id = "H1"
dimension = "haptic"
text = "It felt soft."
[[question]]
id = "H2"
dimension = "haptic"
text = "It felt smooth."
[[question]]
id = "V1"
dimension = "visual"
text = "It looked soft."
[[comparison]]
id = "D1"
text = "Which was better?"
)";

struct DataFolder {
  fs::path path;
  DataFolder()
      : path(fs::temp_directory_path() /
             ("vrdeform_study_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
              ::testing::UnitTest::GetInstance()->current_test_info()->name())) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~DataFolder() { fs::remove_all(path); }
};

// Five participants: H1 in A is 2 above B for everyone but P5 (equal), H2 1 below for P1 and P2,
// V1 unanswered by P3 in B. D1 leans to A.
void writeData(const fs::path& dir) {
  const int h1a[] = {6, 7, 5, 6, 4}, h1b[] = {4, 5, 3, 4, 4};
  const int h2a[] = {4, 4, 5, 6, 7}, h2b[] = {5, 5, 5, 6, 7};
  const int v1a[] = {5, 5, 5, 5, 5}, v1b[] = {6, 4, 0, 7, 3};
  const int d1[] = {-3, -2, -1, 0, -2};
  for (int k = 0; k < 5; ++k) {
    const fs::path p = testing::participantFolder(dir, k + 1);
    fs::create_directories(p);
    std::string answers = "condition,item,answer\n";
    answers += "A,H1," + std::to_string(h1a[k]) + "\nB,H1," + std::to_string(h1b[k]) + "\n";
    answers += "A,H2," + std::to_string(h2a[k]) + "\nB,H2," + std::to_string(h2b[k]) + "\n";
    answers += "A,V1," + std::to_string(v1a[k]) + "\n";
    if (v1b[k] > 0) answers += "B,V1," + std::to_string(v1b[k]) + "\n";
    writeFile(p / "answers.csv", answers);
    writeFile(p / "comparisons.csv", "item,rating\nD1," + std::to_string(d1[k]) + "\n");
  }
}

TEST(StudyAnalysis, DescribesAndTestsEveryItemAndDimension) {
  DataFolder data;
  writeData(data.path);
  const StudySpec study = parseStudy(kStudy, "two.toml", ".");
  const std::vector<ParticipantAnswers> people = readStudyAnswers(study, data.path);
  ASSERT_EQ(people.size(), 5u);
  const StudyAnalysis a = analyseStudy(study, people);
  ASSERT_EQ(a.measures.size(), 5u);  // H1, H2, V1, haptic, visual
  EXPECT_EQ(a.measures[3].name, "haptic");
  EXPECT_TRUE(a.measures[3].dimension);

  // H1 in A: 4 5 6 6 7 -> mean 5.6, sd sqrt(5.2 / 4), median 6, quartiles 5 and 6 (type 7).
  const Description& h1a = a.descriptions[0][0];
  EXPECT_EQ(h1a.n, 5u);
  EXPECT_DOUBLE_EQ(h1a.mean, 5.6);
  EXPECT_NEAR(h1a.sd, std::sqrt(5.2 / 4.0), 1e-12);
  EXPECT_DOUBLE_EQ(h1a.median, 6.0);
  EXPECT_DOUBLE_EQ(h1a.q1, 5.0);
  EXPECT_DOUBLE_EQ(h1a.q3, 6.0);
  // V1 in B: 6 4 7 3 (P3 gave none) -> n 4, quartiles of 3 4 6 7 at h = 0.75 and 2.25: 3.75, 6.25.
  EXPECT_EQ(a.descriptions[2][1].n, 4u);
  EXPECT_DOUBLE_EQ(a.descriptions[2][1].q1, 3.75);
  EXPECT_DOUBLE_EQ(a.descriptions[2][1].q3, 6.25);

  // H1, A - B: +2 four times, 0 once (dropped): four tied ranks of 2.5, W+ = 10, n 4; ties, so the
  // normal approximation: z = (10 - 4 5 / 4) / sqrt(4 5 9 / 24 - (4^3 - 4) / 48) = 5 / sqrt(6.25) = 2.
  const PairedTest& h1 = a.tests[0];
  EXPECT_EQ(h1.measure, "H1");
  EXPECT_EQ(h1.pairs, 5u);
  EXPECT_EQ(h1.result.n, 4u);
  EXPECT_DOUBLE_EQ(h1.result.wPlus, 10.0);
  EXPECT_FALSE(h1.result.exact);
  EXPECT_NEAR(h1.result.z, 2.0, 1e-12);
  // V1 pairs only where both were answered: 4.
  EXPECT_EQ(a.tests[2].pairs, 4u);
  // The haptic dimension: each participant's mean of H1 and H2 per condition.
  const PairedTest& haptic = a.tests[3];
  std::vector<double> ha, hb;
  const int h1av[] = {6, 7, 5, 6, 4}, h1bv[] = {4, 5, 3, 4, 4}, h2av[] = {4, 4, 5, 6, 7}, h2bv[] = {5, 5, 5, 6, 7};
  for (int k = 0; k < 5; ++k) {
    ha.push_back((h1av[k] + h2av[k]) / 2.0);
    hb.push_back((h1bv[k] + h2bv[k]) / 2.0);
  }
  const WilcoxonResult expected = wilcoxonSignedRank(ha, hb);
  EXPECT_EQ(haptic.result.wPlus, expected.wPlus);
  EXPECT_EQ(haptic.result.p, expected.p);

  // Order: P1, P3, P5 met A first (Latin square, 2 conditions), P2 and P4 B first.
  ASSERT_EQ(a.orderTests.size(), 2u);
  std::vector<double> first, second;
  for (int k = 0; k < 5; ++k) {
    const bool aFirst = k % 2 == 0;
    first.push_back(aFirst ? ha[k] : hb[k]);
    second.push_back(aFirst ? hb[k] : ha[k]);
  }
  EXPECT_EQ(a.orderTests[0].result.wPlus, wilcoxonSignedRank(first, second).wPlus);

  // D1: -3 -2 -1 0 -2 against 0: mean -1.6, median -2; the zero dropped, the four others negative:
  // W+ 0 (two tied 2s, so the normal approximation).
  ASSERT_EQ(a.comparisons.size(), 1u);
  EXPECT_DOUBLE_EQ(a.comparisons[0].mean, -1.6);
  EXPECT_DOUBLE_EQ(a.comparisons[0].median, -2.0);
  EXPECT_EQ(a.comparisonTests[0].result.n, 4u);
  EXPECT_EQ(a.comparisonTests[0].result.wPlus, 0.0);

  writeStudyAnalysis(study, people, a, data.path / "out");
  for (const char* f :
       {"tidy.csv", "descriptive.csv", "tests.csv", "order.csv", "comparisons.csv", "report.md", "dimensions.svg",
        "items.svg", "comparisons.svg", "dimensions.png", "items.png", "comparisons.png"})
    EXPECT_TRUE(fs::is_regular_file(data.path / "out" / f)) << f;
  std::ifstream tidy(data.path / "out" / "tidy.csv");
  std::string line;
  int rows = 0;
  std::getline(tidy, line);
  EXPECT_EQ(line, "participant,position,condition,item,dimension,answer");
  std::getline(tidy, line);
  EXPECT_EQ(line, "P1,1,A,H1,haptic,6");
  for (rows = 1; std::getline(tidy, line);) ++rows;
  EXPECT_EQ(rows, 5 * 6 - 1);  // every answer once
}

std::string analysisError(const fs::path& dir, const std::string& answers) {
  writeFile(dir / "P1" / "answers.csv", answers);
  try {
    readStudyAnswers(parseStudy(kStudy, "two.toml", "."), dir);
  } catch (const Error& e) {
    const std::string what = e.what();
    return what.substr(what.find("answers.csv"));
  }
  return "no error";
}

// Free text goes into free_text.csv as RFC 4180 quotes it (commas, quotes and line breaks kept)
// and into the report, per item; answers that do not fit the study are named with their file.
TEST(StudyAnalysis, FreeTextIsKeptAsWritten) {
  const StudySpec study = parseStudy(std::string(kStudy) +
                                         "[[free_text]]\nid = \"F1\"\ntext = \"What did you feel?\"\n"
                                         "[[free_text]]\nid = \"F2\"\ntext = \"Anything else?\"\nafter = \"study\"\n",
                                     "two.toml", ".");
  DataFolder data;
  writeData(data.path);
  writeFile(data.path / "P2" / "free_text.json",
            R"([{"item": "F1", "condition": "B", "text": "Firm, then \"stepped\"\nat the end"},
                {"item": "F2", "text": "No"}])");
  const std::vector<ParticipantAnswers> people = readStudyAnswers(study, data.path);
  ASSERT_EQ(people[1].freeText.size(), 2u);
  EXPECT_EQ(people[1].freeText[0].condition, 1u);
  EXPECT_EQ(people[1].freeText[0].text, "Firm, then \"stepped\"\nat the end");
  const fs::path out = data.path / "analysis";
  writeStudyAnalysis(study, people, analyseStudy(study, people), out);
  std::ifstream csv(out / "free_text.csv");
  const std::string text{std::istreambuf_iterator<char>(csv), {}};
  // P2 met B first (the Latin square's second row).
  EXPECT_EQ(text,
            "participant,position,condition,item,text\nP2,1,B,F1,\"Firm, then \"\"stepped\"\"\nat the end\"\n"
            "P2,,,F2,No\n");
  std::ifstream md(out / "report.md");
  const std::string report{std::istreambuf_iterator<char>(md), {}};
  EXPECT_NE(report.find("### F1: What did you feel?\n\n- P2 (B): Firm, then \"stepped\" at the end\n"),
            std::string::npos)
      << report;
  EXPECT_NE(report.find("### F2: Anything else?\n\n- P2: No\n"), std::string::npos);

  const auto bad = [&](const std::string& json) {
    writeFile(data.path / "P2" / "free_text.json", json);
    try {
      readStudyAnswers(study, data.path);
    } catch (const Error& e) {
      const std::string what = e.what();
      return what.substr(what.find("free_text.json"));
    }
    return std::string("no error");
  };
  EXPECT_EQ(bad("{"), "free_text.json: expected a JSON array of free-text answers");
  EXPECT_EQ(bad(R"([{"item": "F9", "text": "x"}])"), "free_text.json: answer 1: no free-text item 'F9' in the study");
  EXPECT_EQ(bad(R"([{"item": "F1", "text": "x"}])"),
            "free_text.json: answer 1: F1 is asked after each condition: the answer needs its \"condition\"");
  EXPECT_EQ(bad(R"([{"item": "F2", "condition": "A", "text": "x"}])"),
            "free_text.json: answer 1: F2 is asked once, after all conditions");
  EXPECT_EQ(bad(R"([{"item": "F1", "condition": "C", "text": "x"}])"),
            "free_text.json: answer 1: no condition 'C' in the study");
  EXPECT_EQ(bad(R"([{"item": "F2", "text": "x"}, {"item": "F2", "text": "y"}])"),
            "free_text.json: answer 2: a second answer to F2");
  EXPECT_EQ(bad(R"([{"item": "F2", "text": 3}])"),
            "free_text.json: answer 1: expected an object with the strings \"item\" and \"text\"");
}

TEST(StudyAnalysis, BadAnswersAreNamedWithFileAndLine) {
  DataFolder data;
  fs::create_directories(data.path / "P1");
  EXPECT_EQ(analysisError(data.path, "condition,item,answer\nA,H1,8\n"),
            "answers.csv:2: answer '8' is not an integer in 1..7");
  EXPECT_EQ(analysisError(data.path, "condition,item,answer\nA,H9,3\n"),
            "answers.csv:2: no question 'H9' in the study");
  EXPECT_EQ(analysisError(data.path, "condition,item,answer\nC,H1,3\n"),
            "answers.csv:2: no condition 'C' in the study");
  EXPECT_EQ(analysisError(data.path, "condition,item,answer\nA,H1,3\n\nA,H1,4\n"),
            "answers.csv:4: a second answer to H1 in condition A");
  EXPECT_EQ(analysisError(data.path, "condition,item\nA,H1\n"),
            "answers.csv:1: expected 3 comma-separated fields (condition,item,answer), got 2");
  EXPECT_EQ(analysisError(data.path, "item,condition,answer\n"),
            "answers.csv:1: expected the header 'condition,item,answer'");
  writeFile(data.path / "P1" / "answers.csv", "condition,item,answer\n");
  writeFile(data.path / "P1" / "comparisons.csv", "item,rating\nD1,4\n");
  EXPECT_THROW(readStudyAnswers(parseStudy(kStudy, "two.toml", "."), data.path), Error);
  fs::remove_all(data.path / "P1");
  fs::create_directories(data.path / "notes");
  EXPECT_THROW(readStudyAnswers(parseStudy(kStudy, "two.toml", "."), data.path), Error);  // no participant folder
}

}  // namespace
}  // namespace vrd
