#include "vrdeform/study/participant_progress.h"

#include <fmt/chrono.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <nlohmann/json.hpp>

#include "vrdeform/core/text_tokens.h"
#include "vrdeform/core/write_file.h"
#include "vrdeform/error.h"
#include "vrdeform/study/task_end.h"

namespace vrd {
namespace {

namespace fs = std::filesystem;

fs::path questionnaireFile(const fs::path& folder, std::size_t position) {
  return folder / "questionnaires" / fmt::format("{}.json", position + 1);
}
fs::path finalFile(const fs::path& folder) { return folder / "questionnaires" / "final.json"; }
// Where a trial's files are written while it runs.
fs::path scratchOf(const fs::path& trialFolder) {
  return trialFolder.parent_path() / (trialFolder.filename().string() + ".partial");
}

nlohmann::json readJson(const fs::path& file) { return nlohmann::json::parse(io::readFileBytes(file), nullptr, false); }

bool isNumber(const nlohmann::json& j, const char* key) { return j.contains(key) && j[key].is_number(); }

// A trial.json as finishTrial wrote it; anything else is refused, naming the folder to delete.
TrialRecord parseTrial(const fs::path& file) {
  const nlohmann::json j = readJson(file);
  if (!j.is_object() || !isNumber(j, "steps") || !isNumber(j, "wall_seconds"))
    throw Error(
        fmt::format("{}: not a finished trial's record; delete its folder to run the trial again", file.string()));
  TrialRecord r{j["steps"].get<std::uint64_t>(), j["wall_seconds"].get<double>(), std::nullopt,
                j.contains("ended_by") && j["ended_by"].is_string() && j["ended_by"] != "time"};
  if (isNumber(j, "felt_roughness") && isNumber(j, "felt_spearman") && isNumber(j, "felt_peak"))
    r.felt =
        FeltSignal{j["felt_roughness"].get<double>(), j["felt_spearman"].get<double>(), j["felt_peak"].get<double>()};
  return r;
}

// A questionnaire's record as answer() wrote it, every item of the study in it: after a condition
// {"likert": {id: n}, "free_text": {id: text}}, after all of them {"comparisons": ..., "free_text": ...}.
nlohmann::json readQuestionnaire(const fs::path& file, const StudySpec& s, bool perCondition) {
  const nlohmann::json j = readJson(file);
  const char* scored = perCondition ? "likert" : "comparisons";
  bool ok = j.is_object() && j.contains(scored) && j[scored].is_object() && j.contains("free_text") &&
            j["free_text"].is_object();
  const auto has = [&](const char* group, const std::string& id, bool text) {
    ok = ok && j[group].contains(id) && (text ? j[group][id].is_string() : j[group][id].is_number_integer());
  };
  if (perCondition)
    for (const StudyQuestion& q : s.questions) has(scored, q.id, false);
  else
    for (const StudyComparison& d : s.comparisons) has(scored, d.id, false);
  for (const StudyFreeText& f : s.freeTexts)
    if (f.perCondition == perCondition) has("free_text", f.id, true);
  if (!ok)
    throw Error(fmt::format("{}: not a finished questionnaire's record; delete it to answer again", file.string()));
  return j;
}

std::size_t countFreeText(const StudySpec& s, bool perCondition) {
  return std::size_t(std::count_if(s.freeTexts.begin(), s.freeTexts.end(),
                                   [&](const StudyFreeText& f) { return f.perCondition == perCondition; }));
}

void checkScale(int value, int lo, int hi, const std::string& id) {
  if (value < lo || value > hi)
    throw Error(fmt::format("answer to {}: {} is not on the scale {}..{}", id, value, lo, hi));
}

void checkCount(std::size_t got, std::size_t want, const char* what) {
  if (got != want) throw Error(fmt::format("{} answers: {}, the study asks {}", what, got, want));
}

}  // namespace

ParticipantProgress::ParticipantProgress(const StudySpec& study, const fs::path& dataDir, std::size_t participant,
                                         bool simulated, std::uint64_t seed)
    : study_(study),
      participant_(participant),
      order_(study.orderOf(participant)),
      folder_(dataDir / fmt::format("P{}", participant)) {
  prepareOutputFolder(folder_ / "trials");
  prepareOutputFolder(folder_ / "questionnaires");
  nlohmann::json who{{"participant", fmt::format("P{}", participant)},
                     {"number", participant},
                     {"simulated", simulated},
                     {"order", nlohmann::json::array()}};
  if (simulated) who["seed"] = seed;
  for (std::size_t c : order_) who["order"].push_back(study.conditions[c].name);
  writeFile(folder_ / "participant.json", who.dump(2) + "\n");
  // Every record kept is checked now: a broken one is named before any work, not found later.
  std::vector<StudyStep> trials;
  if (study.practice) trials.push_back({StudyStepKind::Practice, 0, 0, 0, 1});
  for (std::size_t pos = 0; pos < order_.size(); ++pos)
    for (std::size_t t = 0; t < study.tasks.size(); ++t)
      for (int r = 1; r <= study.trials; ++r) trials.push_back({StudyStepKind::Trial, pos, order_[pos], t, r});
  for (const StudyStep& s : trials)
    if (const fs::path file = trialFolder(s) / "trial.json"; fs::exists(file)) {
      parseTrial(file);
      ++kept_;
    }
  for (std::size_t pos = 0; pos < order_.size(); ++pos)
    if (fs::exists(questionnaireFile(folder_, pos))) readQuestionnaire(questionnaireFile(folder_, pos), study_, true);
  if (fs::exists(finalFile(folder_))) readQuestionnaire(finalFile(folder_), study_, false);
  advance();
}

const StudyCondition& ParticipantProgress::condition(const StudyStep& step) const {
  return step.kind == StudyStepKind::Practice ? study_.practice->condition : study_.conditions[step.condition];
}

const StudyTask& ParticipantProgress::task(const StudyStep& step) const {
  return step.kind == StudyStepKind::Practice ? study_.practice->task : study_.tasks[step.task];
}

std::uint64_t ParticipantProgress::trialSteps(const StudyStep& step) const {
  const SceneSpec& spec = condition(step).spec;
  const double seconds = task(step).seconds > 0.0 ? task(step).seconds : spec.seconds;
  return std::uint64_t(std::max(std::lround(seconds / spec.solver.timeStep), 1L));
}

fs::path ParticipantProgress::trialFolder(const StudyStep& step) const {
  if (step.kind == StudyStepKind::Practice) return folder_ / "practice";
  return folder_ / "trials" / fmt::format("{}-{}-{}", step.position + 1, step.task + 1, step.trial);
}

// The first step whose record is missing, in the order a participant meets them.
void ParticipantProgress::advance() {
  next_ = {};
  if (study_.practice && !fs::exists(trialFolder({StudyStepKind::Practice}) / "trial.json")) {
    next_ = {StudyStepKind::Practice, 0, 0, 0, 1};
    return;
  }
  const bool conditionQuestions = !study_.questions.empty() || countFreeText(study_, true) > 0;
  for (std::size_t pos = 0; pos < order_.size(); ++pos) {
    bool begun = false;
    for (std::size_t t = 0; t < study_.tasks.size(); ++t)
      for (int r = 1; r <= study_.trials; ++r) {
        const StudyStep trial{StudyStepKind::Trial, pos, order_[pos], t, r};
        if (fs::exists(trialFolder(trial) / "trial.json")) {
          begun = true;
          continue;
        }
        // A rest before every condition but the first, unless it was begun before a resume.
        if (pos > 0 && study_.restSeconds > 0.0 && !begun && restedBefore_ < pos)
          next_ = {StudyStepKind::Rest, pos, order_[pos], 0, 0};
        else
          next_ = trial;
        return;
      }
    if (conditionQuestions && !fs::exists(questionnaireFile(folder_, pos))) {
      next_ = {StudyStepKind::ConditionQuestions, pos, order_[pos], 0, 0};
      return;
    }
  }
  if ((!study_.comparisons.empty() || countFreeText(study_, false) > 0) && !fs::exists(finalFile(folder_)))
    next_ = {StudyStepKind::StudyQuestions};
}

fs::path ParticipantProgress::beginTrial() {
  if (next_.kind != StudyStepKind::Trial && next_.kind != StudyStepKind::Practice)
    throw Error("beginTrial: the next step is not a trial");
  const fs::path partial = scratchOf(trialFolder(next_));
  std::error_code error;
  fs::remove_all(partial, error);  // what a killed run left
  prepareOutputFolder(partial);
  return partial;
}

void ParticipantProgress::finishTrial(const TrialRecord& record) {
  if (next_.kind != StudyStepKind::Trial && next_.kind != StudyStepKind::Practice)
    throw Error("finishTrial: the next step is not a trial");
  const StudyCondition& c = condition(next_);
  nlohmann::json j{{"condition", c.name},
                   {"task", task(next_).name},
                   {"trial", next_.trial},
                   {"scene", c.scene},
                   {"force", c.force == StudyForce::Baseline ? "baseline" : "multipliers"},
                   {"device", c.device == StudyDevice::Glove  ? "glove"
                              : c.device == StudyDevice::None ? "none"
                                                              : "osc"},
                   {"substeps", c.spec.solver.substeps},
                   {"iterations", c.spec.solver.iterations},
                   {"steps", record.steps},
                   {"ended_by", record.endConditionMet ? taskEndName(task(next_).end) : "time"},
                   {"wall_seconds", record.wallSeconds},
                   {"finished_utc", fmt::format("{:%Y-%m-%dT%H:%M:%SZ}", fmt::gmtime(std::time(nullptr)))}};
  if (record.felt) {
    j["felt_roughness"] = record.felt->roughness;
    j["felt_spearman"] = record.felt->spearman;
    j["felt_peak"] = record.felt->peak;
  }
  const fs::path dir = trialFolder(next_), partial = scratchOf(dir);
  writeFile(partial / "trial.json", j.dump(2) + "\n");
  std::error_code error;
  fs::rename(partial, dir, error);  // the finished trial appears whole
  if (error)
    throw Error(fmt::format("{}: cannot move the finished trial into place: {}", dir.string(), error.message()));
  advance();
}

TrialRecord ParticipantProgress::trialRecord(const StudyStep& step) const {
  return parseTrial(trialFolder(step) / "trial.json");
}

void ParticipantProgress::finishRest() {
  if (next_.kind != StudyStepKind::Rest) throw Error("finishRest: the next step is not a rest");
  restedBefore_ = next_.position;
  advance();
}

void ParticipantProgress::answer(const ConditionAnswers& answers) {
  if (next_.kind != StudyStepKind::ConditionQuestions)
    throw Error("answer: the next step is not a condition's questions");
  checkCount(answers.likert.size(), study_.questions.size(), "Likert");
  checkCount(answers.freeText.size(), countFreeText(study_, true), "free-text");
  nlohmann::json j{{"condition", study_.conditions[next_.condition].name},
                   {"position", next_.position + 1},
                   {"likert", nlohmann::json::object()},
                   {"free_text", nlohmann::json::object()}};
  for (std::size_t q = 0; q < study_.questions.size(); ++q) {
    checkScale(answers.likert[q], 1, study_.points, study_.questions[q].id);
    j["likert"][study_.questions[q].id] = answers.likert[q];
  }
  std::size_t k = 0;
  for (const StudyFreeText& f : study_.freeTexts)
    if (f.perCondition) j["free_text"][f.id] = answers.freeText[k++];
  writeFile(questionnaireFile(folder_, next_.position), j.dump(2) + "\n");
  gatherAnswers();
  advance();
}

void ParticipantProgress::answer(const FinalAnswers& answers) {
  if (next_.kind != StudyStepKind::StudyQuestions) throw Error("answer: the next step is not the final questions");
  checkCount(answers.comparisons.size(), study_.comparisons.size(), "comparison");
  checkCount(answers.freeText.size(), countFreeText(study_, false), "free-text");
  nlohmann::json j{{"comparisons", nlohmann::json::object()}, {"free_text", nlohmann::json::object()}};
  for (std::size_t d = 0; d < study_.comparisons.size(); ++d) {
    checkScale(answers.comparisons[d], -study_.comparisonRange, study_.comparisonRange, study_.comparisons[d].id);
    j["comparisons"][study_.comparisons[d].id] = answers.comparisons[d];
  }
  std::size_t k = 0;
  for (const StudyFreeText& f : study_.freeTexts)
    if (!f.perCondition) j["free_text"][f.id] = answers.freeText[k++];
  writeFile(finalFile(folder_), j.dump(2) + "\n");
  gatherAnswers();
  advance();
}

// answers.csv, comparisons.csv and free_text.json (the analysis's input) from the questionnaires
// answered so far, in the participant's order.
void ParticipantProgress::gatherAnswers() const {
  std::vector<std::optional<nlohmann::json>> byPosition(order_.size());
  for (std::size_t pos = 0; pos < order_.size(); ++pos)
    if (fs::exists(questionnaireFile(folder_, pos)))
      byPosition[pos] = readQuestionnaire(questionnaireFile(folder_, pos), study_, true);
  std::optional<nlohmann::json> last;
  if (fs::exists(finalFile(folder_))) last = readQuestionnaire(finalFile(folder_), study_, false);

  std::string answers = "condition,item,answer\n";
  for (std::size_t pos = 0; pos < order_.size(); ++pos)
    if (byPosition[pos])
      for (const StudyQuestion& q : study_.questions)
        answers += fmt::format("{},{},{}\n", study_.conditions[order_[pos]].name, q.id,
                               (*byPosition[pos])["likert"][q.id].get<int>());
  writeFile(folder_ / "answers.csv", answers);
  nlohmann::json freeText = nlohmann::json::array();
  for (const StudyFreeText& f : study_.freeTexts) {
    if (!f.perCondition) {
      if (last) freeText.push_back({{"item", f.id}, {"text", (*last)["free_text"][f.id]}});
      continue;
    }
    for (std::size_t pos = 0; pos < order_.size(); ++pos)
      if (byPosition[pos])
        freeText.push_back({{"item", f.id},
                            {"condition", study_.conditions[order_[pos]].name},
                            {"text", (*byPosition[pos])["free_text"][f.id]}});
  }
  writeFile(folder_ / "free_text.json", freeText.dump(2) + "\n");
  if (!last) return;
  std::string comparisons = "item,rating\n";
  for (const StudyComparison& d : study_.comparisons)
    comparisons += fmt::format("{},{}\n", d.id, (*last)["comparisons"][d.id].get<int>());
  writeFile(folder_ / "comparisons.csv", comparisons);
}

}  // namespace vrd
