// Study files (docs/study.md): the schema of a within-subject study, read with the scene files'
// TOML helpers so that every message names the file, the line and the key.
#include "vrdeform/study/study_file.h"

#include <algorithm>

#include "scene/scene_settings_tables.h"
#include "scene/toml_schema.h"
#include "vrdeform/devices/host_port.h"
#include "vrdeform/error.h"
#include "vrdeform/metrics/latin_square.h"
#include "vrdeform/scene/scene_library.h"
#include "vrdeform/study/task_end.h"

namespace vrd {
namespace {

using namespace schema;

// A built-in scene's name as it is; a scene file (a '/' or a .toml ending, as loadSceneByName
// tells them apart) checked to exist and made absolute.
std::string readSceneName(const Field& f) {
  const std::string name = f.name();
  if (name.find('/') != std::string::npos || name.ends_with(".toml")) return f.file();
  std::vector<std::string> known;
  for (const SceneEntry& e : builtinScenes()) known.push_back(e.name);
  if (std::find(known.begin(), known.end(), name) == known.end())
    f.fail(fmt::format("no built-in scene '{}' (built in: {}; a scene file's path has a '/' or ends in .toml)",
                       printable(name), fmt::join(known, ", ")));
  return name;
}

// A name the data files hold as a CSV field.
std::string csvName(const Field& f) {
  std::string name = f.name();
  if (name.find_first_of(",\"\r\n") != std::string::npos)
    f.fail("must not contain a comma, a quote or a line break (the data files hold it as a CSV field)");
  return name;
}

// Names unique within `seen`, which it extends.
void checkUnique(const Field& f, const std::string& name, std::vector<std::string>& seen, std::string_view what) {
  if (std::find(seen.begin(), seen.end(), name) != seen.end())
    f.fail(fmt::format("'{}' is the {} of an earlier entry too", printable(name), what));
  seen.push_back(name);
}

// The CSV name `key` of table `t`, unique within `seen` (which it extends).
std::string uniqueCsvName(const Table& t, std::string_view key, std::vector<std::string>& seen) {
  const Field f = t.require(key);
  std::string name = csvName(f);
  checkUnique(f, name, seen, key);
  return name;
}

// A condition's (or the practice's) [solver] and [haptics] keys, over its scene's own.
void readConditionSettings(const Table& t, SceneSpec& spec) {
  readSolverTable(t.table("solver"), spec.solver);
  readHapticsTable(t.table("haptics"), spec.haptics);
}

constexpr Option<StudyForce> kForces[] = {{"multipliers", StudyForce::Multipliers}, {"baseline", StudyForce::Baseline}};
constexpr Option<StudyDevice> kDevices[] = {
    {"glove", StudyDevice::Glove}, {"none", StudyDevice::None}, {"osc", StudyDevice::Osc}};

// `device` and, for "osc", its `osc` = "HOST:PORT" (required then, refused otherwise).
void readDevice(const Table& t, StudyCondition& c) {
  t.readChoice("device", c.device, kDevices);
  const std::optional<Field> osc = t.get("osc");
  if (c.device != StudyDevice::Osc) {
    if (osc) osc->fail("only for device = \"osc\"");
    return;
  }
  if (!osc) t.fail("osc", "device = \"osc\" needs osc = \"HOST:PORT\"");
  c.osc = osc->name();
  try {
    parseHostPort(c.osc);
  } catch (const Error& e) {
    osc->fail(e.what());
  }
}

StudySpec readStudy(const Table& root) {
  root.allowOnly({"format", "name", "description", "trials", "rest", "points", "comparison_range", "order", "condition",
                  "task", "practice", "question", "comparison", "free_text"});
  if (const std::int64_t format = root.require("format").integer(); format != 1)
    root.fail("format", fmt::format("unknown format {} (this vrdeform reads format 1)", format));
  StudySpec s;
  s.name = root.require("name").name();
  root.readString("description", s.description);
  root.readInt("trials", s.trials, 1, 100);
  root.readNumber("rest", s.restSeconds, kNonNegative);
  root.readInt("points", s.points, 2, 11);
  root.readInt("comparison_range", s.comparisonRange, 1, 5);
  constexpr Option<Counterbalancing> kOrders[] = {{"latin_square", Counterbalancing::LatinSquare},
                                                  {"fixed", Counterbalancing::Fixed}};
  root.readChoice("order", s.order, kOrders);

  std::vector<std::string> names;
  for (const Table& t : root.tables("condition")) {
    t.allowOnly({"name", "scene", "force", "device", "osc", "solver", "haptics"});
    StudyCondition c;
    c.name = uniqueCsvName(t, "name", names);
    c.scene = readSceneName(t.require("scene"));
    t.readChoice("force", c.force, kForces);
    readDevice(t, c);
    c.spec = loadSceneByName(c.scene);
    readConditionSettings(t, c.spec);
    s.conditions.push_back(std::move(c));
  }
  if (s.conditions.size() < 2) root.fail("condition", "a within-subject study needs two or more [[condition]]s");

  names.clear();
  for (const Table& t : root.tables("task")) {
    t.allowOnly({"name", "instructions", "seconds", "end"});
    StudyTask task;
    const Field name = t.require("name");
    task.name = name.name();
    checkUnique(name, task.name, names, "name");
    t.readString("instructions", task.instructions);
    t.readNumber("seconds", task.seconds, kNonNegative);
    constexpr Option<TaskEnd> kEnds[] = {{taskEndName(TaskEnd::Time), TaskEnd::Time},
                                         {taskEndName(TaskEnd::Release), TaskEnd::Release},
                                         {taskEndName(TaskEnd::GraspRelease), TaskEnd::GraspRelease}};
    t.readChoice("end", task.end, kEnds);
    s.tasks.push_back(std::move(task));
  }
  if (s.tasks.empty()) root.fail("task", "needs at least one [[task]]");

  if (root.has("practice")) {
    const Table t = root.table("practice");
    t.allowOnly({"scene", "force", "device", "osc", "seconds", "instructions", "solver", "haptics"});
    StudyPractice p{s.conditions.front(), {}};
    p.condition.name = p.task.name = "practice";
    if (const std::optional<Field> f = t.get("scene")) {
      p.condition.scene = readSceneName(*f);
      p.condition.spec = loadSceneByName(p.condition.scene);
    }
    readConditionSettings(t, p.condition.spec);
    t.readChoice("force", p.condition.force, kForces);
    if (t.has("device") || t.has("osc")) readDevice(t, p.condition);
    t.readNumber("seconds", p.task.seconds, kNonNegative);
    t.readString("instructions", p.task.instructions);
    s.practice = std::move(p);
  }

  std::vector<std::string> ids;
  for (const Table& t : root.tables("question")) {
    t.allowOnly({"id", "dimension", "text", "anchors"});
    StudyQuestion q;
    q.id = uniqueCsvName(t, "id", ids);
    q.dimension = csvName(t.require("dimension"));
    q.text = t.require("text").name();
    if (const std::optional<Field> f = t.get("anchors")) {
      const std::vector<Field> anchors = f->elements("an array of two strings");
      if (anchors.size() != 2)
        f->fail(fmt::format("expected two anchors (of 1 and of {}), got {}", s.points, anchors.size()));
      q.low = anchors[0].name();
      q.high = anchors[1].name();
    }
    s.questions.push_back(std::move(q));
  }
  for (const Table& t : root.tables("comparison")) {
    t.allowOnly({"id", "text", "between"});
    StudyComparison c;
    c.id = uniqueCsvName(t, "id", ids);
    c.text = t.require("text").name();
    if (const std::optional<Field> f = t.get("between")) {
      const std::vector<Field> pair = f->elements("an array of two condition names");
      if (pair.size() != 2) f->fail(fmt::format("expected two condition names, got {}", pair.size()));
      std::size_t index[2];
      for (int k = 0; k < 2; ++k) {
        const std::string name = pair[k].name();
        const auto it = std::find_if(s.conditions.begin(), s.conditions.end(),
                                     [&](const StudyCondition& x) { return x.name == name; });
        if (it == s.conditions.end()) pair[k].fail(fmt::format("no condition '{}'", printable(name)));
        index[k] = std::size_t(it - s.conditions.begin());
      }
      if (index[0] == index[1]) f->fail("names one condition twice");
      c.a = index[0];
      c.b = index[1];
    }
    s.comparisons.push_back(std::move(c));
  }
  for (const Table& t : root.tables("free_text")) {
    t.allowOnly({"id", "text", "after"});
    StudyFreeText f;
    f.id = uniqueCsvName(t, "id", ids);
    f.text = t.require("text").name();
    constexpr Option<bool> kAfter[] = {{"condition", true}, {"study", false}};
    t.readChoice("after", f.perCondition, kAfter);
    s.freeTexts.push_back(std::move(f));
  }
  if (s.questions.empty() && s.comparisons.empty())
    root.fail("question", "needs at least one [[question]] or [[comparison]]");
  return s;
}

}  // namespace

std::vector<std::size_t> StudySpec::orderOf(std::size_t participant) const {
  if (participant == 0) throw Error("participants are numbered from 1");
  if (order == Counterbalancing::LatinSquare) return latinSquareOrder(conditions.size(), participant - 1);
  std::vector<std::size_t> fixed(conditions.size());
  for (std::size_t i = 0; i < fixed.size(); ++i) fixed[i] = i;
  return fixed;
}

std::vector<std::string> StudySpec::dimensions() const {
  std::vector<std::string> out;
  for (const StudyQuestion& q : questions)
    if (std::find(out.begin(), out.end(), q.dimension) == out.end()) out.push_back(q.dimension);
  return out;
}

StudySpec parseStudy(std::string_view text, std::string_view sourceName, const std::filesystem::path& baseDir) {
  const Context ctx{std::string(sourceName), baseDir};
  const toml::table root = parseToml(text, ctx.source);
  StudySpec study = readStudy(Table(ctx, root, "", 1));
  study.source = sourceName;
  return study;
}

StudySpec loadStudy(const std::filesystem::path& path) {
  std::error_code error;
  std::filesystem::path absolute = std::filesystem::absolute(path, error);
  if (error) absolute = path;
  StudySpec study = parseStudy(readText(path), path.string(), absolute.lexically_normal().parent_path());
  return study;
}

}  // namespace vrd
