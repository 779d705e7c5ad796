#include "study_command.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <memory>
#include <string>
#include <vector>

#include "study_vr.h"
#include "viewer/viewer.h"
#include "vrdeform/devices/glove_link.h"
#include "vrdeform/devices/stop_signals.h"
#include "vrdeform/error.h"
#include "vrdeform/study/participant_progress.h"
#include "vrdeform/study/study_analysis.h"
#include "vrdeform/study/study_file.h"
#include "vrdeform/study/study_simulation.h"
#include "vrdeform/study/task_end.h"

namespace vrd {
namespace {

struct StudyArgs {
  std::string study, data, out, weart;
  std::size_t participants = 0, participant = 0;
  std::uint64_t seed = 1;
  bool autopilot = false, vr = false;
  ServeOptions serve;  // --vr
};

int check(const StudyArgs& a) {
  const StudySpec s = loadStudy(a.study);
  fmt::print(
      "study {}: {} conditions, {} tasks x {} trials, {} questions in {} dimensions, {} comparisons, {} free-text "
      "items\n",
      s.name, s.conditions.size(), s.tasks.size(), s.trials, s.questions.size(), s.dimensions().size(),
      s.comparisons.size(), s.freeTexts.size());
  const auto describe = [](const StudyCondition& c) {
    const SolverSettings& solver = c.spec.solver;
    const std::string device = c.device == StudyDevice::Glove  ? "the glove"
                               : c.device == StudyDevice::None ? "no device (visual only)"
                                                               : "OSC to " + c.osc;
    return fmt::format("scene {} ({} substeps x {} iterations at {:g} Hz), force {} to {}", c.scene, solver.substeps,
                       solver.iterations, 1.0 / solver.timeStep,
                       c.force == StudyForce::Multipliers ? "multipliers (A)" : "baseline (B)", device);
  };
  if (s.practice) fmt::print("  practice first: {}\n", describe(s.practice->condition));
  for (const StudyCondition& c : s.conditions) fmt::print("  condition {}: {}\n", c.name, describe(c));
  for (const StudyTask& t : s.tasks) {
    const std::string length = t.seconds > 0.0 ? fmt::format("{:g} s", t.seconds) : "the scene's length";
    fmt::print("  task {}: {}\n", t.name,
               t.end == TaskEnd::Time ? length : fmt::format("until {}, at most {}", taskEndName(t.end), length));
  }
  const std::size_t n = a.participants > 0 ? a.participants : 2 * s.conditions.size();
  for (std::size_t k = 1; k <= n; ++k) {
    std::vector<std::string_view> order;
    for (std::size_t c : s.orderOf(k)) order.push_back(s.conditions[c].name);
    fmt::print("  P{}: {}\n", k, fmt::join(order, ", "));
  }
  return 0;
}

int analyse(const StudyArgs& a) {
  const StudySpec s = loadStudy(a.study);
  const std::vector<ParticipantAnswers> participants = readStudyAnswers(s, a.data);
  const StudyAnalysis analysis = analyseStudy(s, participants);
  const std::string out = a.out.empty() ? (std::filesystem::path(a.data) / "analysis").string() : a.out;
  writeStudyAnalysis(s, participants, analysis, out);
  for (const PairedTest& t : analysis.tests)
    if (t.dimension)
      fmt::print("{:<12} {} vs {}: {} pairs, W+ {}, p {:.4f}{}, r {:.2f}\n", t.measure, s.conditions[t.a].name,
                 s.conditions[t.b].name, t.pairs, t.result.wPlus, t.result.p, t.result.exact ? " (exact)" : "",
                 t.result.effectSize);
  fmt::print(
      "wrote {}/: report.md tidy.csv descriptive.csv tests.csv order.csv comparisons.csv free_text.csv, figures as "
      ".svg and .png\n",
      out);
  return 0;
}

// Simulated participants 1..N (or participant K alone), each resumed where an earlier run ended.
int simulate(const StudyArgs& a) {
  const StudySpec s = loadStudy(a.study);
  const StopSignals signals;
  std::size_t first = 1, last = a.participants > 0 ? a.participants : 2 * s.conditions.size();
  if (a.participant > 0) first = last = a.participant;
  for (std::size_t k = first; k <= last; ++k) {
    StudyRunSettings settings;
    settings.dataDir = a.data;
    settings.participant = k;
    settings.simulated.seed = a.seed;
    settings.stop = [&signals] { return signals.requested(); };
    settings.log = [](const std::string& line) { fmt::print("{}\n", line); };
    try {
      const StudyRunResult r = runSimulatedParticipant(s, settings);
      fmt::print("P{}: done ({} trials run, {} kept from an earlier run)\n", k, r.trialsRun, r.trialsKept);
    } catch (const Stopped& e) {
      fmt::print(stderr, "\nvrdeform: {}: P{}'s finished trials are kept; run the same command again to go on\n",
                 e.what(), k);
      return 130;
    }
  }
  fmt::print("wrote {}/P{}..P{}; next: vrdeform study analyse {} {}\n", a.data, first, last, a.study, a.data);
  return 0;
}

// A live participant in the desktop viewer or on the VR page, resumed where an earlier run ended.
int runLive(const StudyArgs& a) {
  const StudySpec s = loadStudy(a.study);
  ParticipantProgress progress(s, a.data, a.participant, false);
  std::vector<std::string_view> order;
  for (std::size_t c : progress.order()) order.push_back(s.conditions[c].name);
  fmt::print("P{}: {} ({} trials kept from an earlier run)\n", a.participant, fmt::join(order, ", "),
             progress.trialsKept());
  if (progress.next().kind != StudyStepKind::Done) {
    ViewerOptions o;
    o.study = &progress;
    o.autopilot = a.autopilot;
    o.weart = a.weart;
    try {
      const int status = a.vr ? runStudyInVr(progress, {a.serve, a.weart, a.autopilot}) : runViewer(o);
      if (status != 0) return status;
    } catch (const Stopped& e) {  // Ctrl-C while a scene was built
      fmt::print(stderr, "vrdeform: {}\n", e.what());
    }
  }
  if (progress.next().kind != StudyStepKind::Done) {
    fmt::print(stderr,
               "vrdeform: P{} stopped before the end; their finished trials and answers are kept: run the same "
               "command again to go on\n",
               a.participant);
    return 130;
  }
  fmt::print("P{}: done, in {}; next: vrdeform study analyse {} {}\n", a.participant, progress.folder().string(),
             a.study, a.data);
  return 0;
}

}  // namespace

std::function<int()> addStudyCommand(CLI::App& app) {
  auto a = std::make_shared<StudyArgs>();
  CLI::App* cmd = app.add_subcommand("study", "A within-subject haptics study from a study file (docs/study.md)");
  cmd->require_subcommand(1);
  CLI::App* checkCmd = cmd->add_subcommand("check", "Read a study file; print its plan and the participants' orders");
  checkCmd->add_option("study", a->study, "The study file (.toml)")->required();
  checkCmd->add_option("--participants", a->participants, "Orders to print (default: two of each)")
      ->check(CLI::Range(1, 10000));
  CLI::App* analyseCmd =
      cmd->add_subcommand("analyse", "Statistics and a report from the participants' answers (DATA/P1, DATA/P2, ...)");
  analyseCmd->add_option("study", a->study, "The study file (.toml)")->required();
  analyseCmd->add_option("data", a->data, "The study's data folder")->required();
  analyseCmd->add_option("--out", a->out, "Where the report goes (default: DATA/analysis)");
  CLI::App* simulateCmd = cmd->add_subcommand(
      "simulate", "Run simulated participants through the study headless, into DATA/P1, DATA/P2, ... (resumable)");
  simulateCmd->add_option("study", a->study, "The study file (.toml)")->required();
  simulateCmd->add_option("data", a->data, "The study's data folder")->required();
  simulateCmd->add_option("--participants", a->participants, "Participants 1..N (default: two of each condition)")
      ->check(CLI::Range(1, 10000));
  simulateCmd->add_option("--participant", a->participant, "Participant K alone")->check(CLI::Range(1, 10000));
  simulateCmd->add_option("--seed", a->seed, "Seed of the simulated answers' noise")->capture_default_str();
  CLI::App* runCmd = cmd->add_subcommand(
      "run",
      "Walk a participant through the study in the desktop viewer or on the VR page, into DATA/P<K> (resumable)");
  runCmd->add_option("study", a->study, "The study file (.toml)")->required();
  runCmd->add_option("data", a->data, "The study's data folder")->required();
  runCmd->add_option("--participant", a->participant, "Participant K: their order of the conditions follows from K")
      ->check(CLI::Range(1, 10000))
      ->required();
  runCmd
      ->add_option("--weart", a->weart,
                   "The participant's WEART glove: HOST[:PORT] of the middleware (default port 13031); without "
                   "it the mouse is the hand")
      ->check(CLI::Validator(weartEndpointError, "HOST[:PORT]"));
  runCmd->add_flag("--autopilot", a->autopilot,
                   "A dry run of the set-up: every step starts by itself, the scenes' scripted hands poke, the "
                   "questions get the scales' middles and rests are skipped");
  CLI::Option* vr = runCmd->add_flag(
      "--vr", a->vr,
      "On the VR page instead of the desktop viewer: the headset (or a browser) opens the address printed, "
      "and the instructions and questions are on a panel there; --port, --bind, --tls and --fps as serve's");
  addServeOptions(*runCmd, a->serve);
  for (const char* name : {"--port", "--bind", "--tls", "--tls-dir", "--fps"}) runCmd->get_option(name)->needs(vr);
  return [a, checkCmd, analyseCmd, simulateCmd, runCmd]() -> int {
    if (*runCmd) return runLive(*a);
    if (*checkCmd) return check(*a);
    if (*simulateCmd) return simulate(*a);
    if (*analyseCmd) return analyse(*a);
    return 0;
  };
}

}  // namespace vrd
