#include "study_vr.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>
#include <vector>

#include "build_observer.h"
#include "vrdeform/devices/glove_link.h"
#include "vrdeform/devices/stop_signals.h"
#include "vrdeform/error.h"
#include "vrdeform/study/questionnaire_items.h"
#include "vrdeform/study/task_end.h"
#include "vrdeform/study/trial_outputs.h"
#include "vrdeform/web/static_files.h"

namespace vrd {
namespace {

using Clock = std::chrono::steady_clock;
using json = nlohmann::json;

// A rest's Continue is taken this much before the page's countdown ends (the clocks differ by the
// message's way).
constexpr double kRestSlackSeconds = 0.5;

// A scene on the page: the hand the viewers drive, a trial's outputs and its loop, paused until the
// participant starts the trial. Members in dependency order: the loop stops before its inputs go.
struct Shown {
  BuiltScene scene;
  Vec3 park;
  LiveHandInput hand;
  std::optional<TrialOutputs> trial;
  std::unique_ptr<SimulationLoop> loop;
  std::shared_ptr<SnapshotChannel> channel;

  Shown(const SceneSpec& spec, const SceneBuildObserver& observer, XrHandSettings xr)
      : scene(buildScene(spec, observer)), park(scene.bodies.front().top + Vec3(0.0f, 0.15f, 0.0f)) {
    xr.park = park;
    hand.set(xrParkedFrame(xr, scene.session.hand.geometry.fingertipRadius));
  }
};

class StudyInVr {
 public:
  StudyInVr(ParticipantProgress& progress, const StudyVrOptions& options)
      : p_(progress), o_(options), settings_(vrServerSettings(options.serve)) {
    settings_.onStudy = [this](const vr::StudyReply& r) {
      std::lock_guard lock(repliesMutex_);
      if (replies_.size() < 64) replies_.push_back(r);
    };
  }

  int run() {
    prepare(true);
    while (!signals_.requested()) {
      std::vector<vr::StudyReply> replies;
      {
        std::lock_guard lock(repliesMutex_);
        replies.swap(replies_);
      }
      for (const vr::StudyReply& r : replies)
        if (r.panel == panelId_) act(r.action, r.ratings, r.texts);
      if (o_.autopilot) {
        if (failed_) break;
        autopilot();
      }
      if (started_ && !stopped_) watchTrial();
      if (glove_) glove_->reportEvents();
      if (p_.next().kind == StudyStepKind::Done) {
        std::this_thread::sleep_for(std::chrono::seconds(1));  // the pages get the last panel
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    server_->stop();
    shown_.reset();
    if (glove_) glove_->shutdown();
    return failed_ ? 1 : 0;
  }

 private:
  // The scene of the participant's next step, as the desktop viewer's: a trial's built afresh,
  // recorded into its scratch folder; after a condition's last trial its scene stays in view
  // through the questions and the rest. Then the step's panel.
  void prepare(bool first) {
    const StudyStep s = p_.next();
    started_ = stopped_ = failed_ = endMet_ = false;
    error_.clear();
    restBegan_ = Clock::now();
    const bool trial = s.kind == StudyStepKind::Practice || s.kind == StudyStepKind::Trial;
    const bool final = s.kind == StudyStepKind::StudyQuestions;
    items_ = final || s.kind == StudyStepKind::ConditionQuestions ? questionnaireItems(p_.study(), p_.order(), final)
                                                                  : std::vector<QuestionnaireItem>{};
    if (trial || first) {
      const StudySpec& study = p_.study();
      const StudyCondition& c =
          trial ? p_.condition(s)
                : study.conditions[s.kind == StudyStepKind::ConditionQuestions ? s.condition : p_.order().front()];
      auto next = std::make_unique<Shown>(c.spec, commandObserver(signals_, false), settings_.hand);
      if (!glove_ && !o_.weart.empty()) {
        glove_.emplace(o_.weart, next->scene.session.hand, next->scene.bodies.front().top);
        settings_.gloveClosure = [this] { return glove_->closure(Finger::Index); };
        settings_.gloveConnected = [this] { return glove_->connected(); };
      }
      SimulationLoopSettings ls;
      ls.input = o_.autopilot ? nullptr : &next->hand;
      if (trial) {
        ls.maxSteps = p_.trialSteps(s);
        trialSeconds_ = double(ls.maxSteps) * c.spec.solver.timeStep;
        next->trial.emplace(ls, next->scene, c, glove_ ? &glove_->output() : nullptr, p_.beginTrial() / "forces.csv");
        taskEnd_.emplace(p_.task(s).end);
      }
      next->loop = std::make_unique<SimulationLoop>(next->scene, ls);
      next->channel = next->loop->subscribe();
      show(*next);
      next->loop->setPaused(true);
      next->loop->start();
      shown_ = std::move(next);  // the previous scene's loop stops and goes
    }
    publishPanel();
  }

  void show(Shown& next) {
    LiveHandInput* hand = next.scene.spec.hand.enabled ? &next.hand : nullptr;
    if (server_) return server_->show(*next.loop, next.scene, hand, next.park);
    settings_.hand.park = next.park;
    server_.emplace(*next.loop, next.scene, webFolder(), settings_, hand);
    server_->start();
    fmt::print("P{}: the study on the VR page\n", p_.participant());
    printAddresses(o_.serve, server_->port());
  }

  // The panel of the step at hand (docs/vr.md#study), under a new id: replies to older panels are
  // stale (a double press, a page that had not caught up) and ignored.
  void publishPanel() {
    const StudyStep s = p_.next();
    const StudySpec& study = p_.study();
    json m = {{"type", "study"}, {"id", ++panelId_}, {"study", study.name}, {"participant", p_.participant()}};
    switch (s.kind) {
      case StudyStepKind::Practice:
      case StudyStepKind::Trial: {
        const StudyTask& task = p_.task(s);
        m["step"] = failed_ ? "failed" : "trial";
        m["title"] = s.kind == StudyStepKind::Practice
                         ? std::string("Practice")
                         : fmt::format("Part {} of {}: {}, trial {} of {}", s.position + 1, p_.order().size(),
                                       task.name, s.trial, study.trials);
        m["text"] = task.instructions;
        m["started"] = started_;
        m["seconds"] = trialSeconds_;
        break;
      }
      case StudyStepKind::ConditionQuestions:
      case StudyStepKind::StudyQuestions: {
        m["step"] = "questions";
        m["title"] = s.kind == StudyStepKind::StudyQuestions
                         ? std::string("Every part done: a few last questions.")
                         : fmt::format("Part {} of {} done: how was it?", s.position + 1, p_.order().size());
        json items = json::array();
        for (const QuestionnaireItem& i : items_)
          items.push_back(i.rated ? json{{"text", i.text},
                                         {"rated", true},
                                         {"low", i.low},
                                         {"high", i.high},
                                         {"lowAnchor", i.lowAnchor},
                                         {"highAnchor", i.highAnchor}}
                                  : json{{"text", i.text}, {"rated", false}});
        m["items"] = items;
        break;
      }
      case StudyStepKind::Rest:
        m["step"] = "rest";
        m["title"] = "Time for a rest: take the headset and the glove off if you like.";
        m["seconds"] = std::max(0.0, restLeft());
        break;
      case StudyStepKind::Done:
        m["step"] = "done";
        m["title"] = "All done: thank you!";
        break;
    }
    if (!error_.empty()) m["error"] = error_;
    server_->setPanel(m.dump());
    // The experimenter, at the desktop, follows the steps here, with the conditions' names.
    const bool named = s.kind == StudyStepKind::Trial || s.kind == StudyStepKind::ConditionQuestions;
    std::string line =
        fmt::format("P{}: {}{}{}", p_.participant(), m["title"].get<std::string>(),
                    named ? fmt::format(" [condition {}]", p_.condition(s).name) : "", started_ ? " (running)" : "");
    if (!error_.empty()) line += fmt::format(" ({})", error_);
    if (line != lastLine_) {
      fmt::print("{}\n", line);
      std::fflush(stdout);
      lastLine_ = std::move(line);
    }
  }

  double restLeft() const {
    return p_.study().restSeconds - std::chrono::duration<double>(Clock::now() - restBegan_).count();
  }

  // What the participant did on the panel (or the autopilot for them).
  void act(vr::StudyReply::Action action, const std::vector<int>& ratings, const std::vector<std::string>& texts) {
    const StudyStepKind k = p_.next().kind;
    const bool trial = k == StudyStepKind::Practice || k == StudyStepKind::Trial;
    switch (action) {
      case vr::StudyReply::Action::Start:
        if (trial && !started_ && !failed_) startTrial();
        break;
      case vr::StudyReply::Action::Retry:
        if (trial && failed_) prepare(false);
        break;
      case vr::StudyReply::Action::Continue:
        if (k == StudyStepKind::Rest && restLeft() <= kRestSlackSeconds) {
          p_.finishRest();
          prepare(false);
        }
        break;
      case vr::StudyReply::Action::Submit:
        if (k == StudyStepKind::ConditionQuestions || k == StudyStepKind::StudyQuestions) submit(ratings, texts);
        break;
    }
  }

  void autopilot() {
    const StudyStepKind k = p_.next().kind;
    if (k == StudyStepKind::ConditionQuestions || k == StudyStepKind::StudyQuestions) {
      std::vector<int> ratings;
      std::vector<std::string> texts;
      dryRunAnswers(items_, ratings, texts);
      act(vr::StudyReply::Action::Submit, ratings, texts);
    } else if (k == StudyStepKind::Rest) {
      p_.finishRest();
      prepare(false);
    } else if (k != StudyStepKind::Done) {
      act(vr::StudyReply::Action::Start, {}, {});
    }
  }

  void submit(const std::vector<int>& ratings, const std::vector<std::string>& texts) {
    const auto rated = std::size_t(std::count_if(items_.begin(), items_.end(), [](const auto& i) { return i.rated; }));
    try {
      if (ratings.size() != rated || texts.size() != items_.size() - rated)
        throw Error(fmt::format("{} ratings and {} texts for {} rated and {} free-text items", ratings.size(),
                                texts.size(), rated, items_.size() - rated));
      if (p_.next().kind == StudyStepKind::StudyQuestions)
        p_.answer(FinalAnswers{ratings, texts});
      else
        p_.answer(ConditionAnswers{ratings, texts});
    } catch (const Error& e) {  // answers the page should not have sent: said on the panel
      error_ = e.what();
      fmt::print(stderr, "vrdeform: P{}: answers refused: {}\n", p_.participant(), error_);
      publishPanel();
      return;
    }
    prepare(false);
  }

  void startTrial() {
    started_ = true;
    trialBegan_ = Clock::now();
    shown_->loop->setPaused(false);
    publishPanel();
  }

  // A trial running: it ends with its length or its task's end condition; then its record and the
  // next step. A failed simulation is not kept: the panel offers to run it again.
  void watchTrial() {
    Shown& r = *shown_;
    bool ended = !r.loop->running();
    if (!ended && r.channel->update()) {
      const Snapshot& now = r.channel->front();
      ended = endMet_ = now.step > 0 && taskEnd_->update(now.contact, now.grasping, now.time);
    }
    if (!ended) return;
    stopped_ = true;
    try {
      r.loop->stop();
    } catch (const std::exception& e) {
      failed_ = true;
      error_ = fmt::format("the simulation stopped: {}", e.what());
      fmt::print(stderr, "vrdeform: {}\n", error_);
      publishPanel();
      return;
    }
    r.trial->finish(*r.loop);
    const double wall = std::chrono::duration<double>(Clock::now() - trialBegan_).count();
    p_.finishTrial({r.loop->stats().steps, wall, std::nullopt, endMet_});
    prepare(false);
  }

  ParticipantProgress& p_;
  StudyVrOptions o_;
  StopSignals signals_;
  VrServerSettings settings_;
  std::optional<GloveLink> glove_;  // one for the whole study, its closure read by the server
  std::unique_ptr<Shown> shown_;
  std::mutex repliesMutex_;
  std::vector<vr::StudyReply> replies_;  // from the server's thread
  std::uint64_t panelId_ = 0;
  std::vector<QuestionnaireItem> items_;
  std::optional<TaskEndWatch> taskEnd_;
  double trialSeconds_ = 0.0;
  bool started_ = false, stopped_ = false, failed_ = false, endMet_ = false;
  std::string error_, lastLine_;
  Clock::time_point trialBegan_, restBegan_;
  std::optional<VrServer> server_;  // declared last: stopped before anything it calls or shows goes
};

}  // namespace

int runStudyInVr(ParticipantProgress& progress, const StudyVrOptions& options) {
  return StudyInVr(progress, options).run();
}

}  // namespace vrd
