#pragma once
// `vrdeform study analyse` (docs/study.md): a study's answers read from its data folder, described
// per item and per dimension, each pair of conditions compared with the Wilcoxon signed-rank test,
// the order of the conditions checked for an effect, and everything written as tidy CSV files and a
// Markdown report.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "vrdeform/metrics/wilcoxon.h"
#include "vrdeform/study/study_spec.h"

namespace vrd {

/// An answer to a free-text item (free_text.json).
struct FreeTextAnswer {
  std::size_t item = 0;                  ///< index into study.freeTexts
  std::optional<std::size_t> condition;  ///< for an item asked after each condition
  std::string text;
};

/// One participant's answers: folder P<k> of the data folder (docs/study.md's layout).
struct ParticipantAnswers {
  std::size_t number = 0;  ///< k, from the folder's name; their order of the conditions follows from it
  std::string id;          ///< the folder's name, e.g. "P03"
  /// answers[condition][question]: 1..points, or nullopt where the participant gave none.
  std::vector<std::vector<std::optional<int>>> answers;
  /// comparisons[comparison]: the rating in -range..range, or nullopt where none was given.
  std::vector<std::optional<int>> comparisons;
  std::vector<FreeTextAnswer> freeText;  ///< in the file's order
};

/// Reads every participant folder (P1, P02, ...) of `dataDir`: answers.csv (`condition,item,answer`),
/// comparisons.csv (`item,rating`) and free_text.json (an array of {"item", "condition" for the
/// items asked after each condition, "text"}), any of which may be missing. Throws vrd::Error naming
/// the file and line (or entry) of an unknown condition or item, an answer outside 1..points, a
/// repeated answer or a malformed line, and when no participant folder is there.
std::vector<ParticipantAnswers> readStudyAnswers(const StudySpec& study, const std::filesystem::path& dataDir);

/// Mean, sample standard deviation (n - 1), median and quartiles (linear interpolation between
/// closest ranks, numpy's default) of one condition's values.
struct Description {
  std::size_t n = 0;
  double mean = 0, sd = 0, median = 0, q1 = 0, q3 = 0;
};
Description describe(std::vector<double> values);

/// The values of one item (a question's answers) or one dimension (each participant's mean over the
/// dimension's questions they answered) in one condition, per participant (nullopt: none).
struct Measure {
  std::string name;  ///< question id or dimension name
  bool dimension = false;
  std::vector<std::vector<std::optional<double>>> byCondition;  ///< [condition][participant]
};

struct PairedTest {
  std::string measure;
  bool dimension = false;
  std::size_t a = 0, b = 0;  ///< conditions, or positions for an order test
  std::size_t pairs = 0;     ///< participants with a value in both
  WilcoxonResult result;
};

struct StudyAnalysis {
  std::vector<Measure> measures;  ///< every question, then every dimension
  /// Per measure and condition.
  std::vector<std::vector<Description>> descriptions;
  /// Every measure for every pair of conditions (a < b).
  std::vector<PairedTest> tests;
  /// Per dimension: the condition each participant met first against the one they met second.
  std::vector<PairedTest> orderTests;
  /// Per direct comparison: its ratings described, and tested against no difference (0).
  std::vector<Description> comparisons;
  std::vector<PairedTest> comparisonTests;
};

StudyAnalysis analyseStudy(const StudySpec& study, const std::vector<ParticipantAnswers>& participants);

/// Writes tidy.csv (participant, position, condition, item, dimension, answer: one row per answer),
/// descriptive.csv, tests.csv, order.csv, comparisons.csv, free_text.csv (participant, position,
/// condition, item, text; RFC 4180 quoting), the figures dimensions (box plots per
/// dimension and condition), items (each item's mean difference for every pair of conditions) and
/// comparisons (the direct comparisons' ratings), each as .svg and .png, and report.md into
/// `outDir`, each file complete or not at all. Throws vrd::Error.
void writeStudyAnalysis(const StudySpec& study, const std::vector<ParticipantAnswers>& participants,
                        const StudyAnalysis& analysis, const std::filesystem::path& outDir);

}  // namespace vrd
