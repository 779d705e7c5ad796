#include "viewer.h"

#include "../build_observer.h"
#include "questionnaire.h"

#include <epoxy/gl.h>
// GLFW after epoxy, which must come before any other OpenGL header.
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <fmt/format.h>
#include <imgui.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "vrdeform/devices/glove_link.h"
#include "vrdeform/devices/haptic_output.h"
#include "vrdeform/devices/stop_signals.h"
#include "vrdeform/error.h"
#include "vrdeform/interact/live_hand_input.h"
#include "vrdeform/render/gl_driver.h"
#include "vrdeform/render/image.h"
#include "vrdeform/render/mouse_hand.h"
#include "vrdeform/render/scene_renderer.h"
#include "vrdeform/scene/scene_library.h"
#include "vrdeform/scene/simulation_loop.h"
#include "vrdeform/study/participant_progress.h"
#include "vrdeform/study/task_end.h"
#include "vrdeform/study/trial_outputs.h"

namespace vrd {
namespace {

using Clock = std::chrono::steady_clock;

// A built scene running: its loop, the hand that drives it and what the window draws of it.
// Members in dependency order: destroyed from the bottom up, the loop stops before its inputs go.
struct Running {
  BuiltScene scene;
  LiveHandInput mouseInput;
  std::optional<GloveLink> glove;
  std::optional<TrialOutputs> trial;  // a study's trial: its device, its signal and task events recorded
  std::unique_ptr<SimulationLoop> loop;
  std::shared_ptr<SnapshotChannel> channel;
  Snapshot settled;  // the world before the first step: drawn until the first snapshot arrives
  PosedScene posed;
  SceneRenderer renderer;
  MouseHand mouse;

  Running(const SceneSpec& spec, const SceneBuildObserver& observer)
      : scene(buildScene(spec, observer)),
        posed(scene),
        renderer(posed),
        mouse(spec.hand.rig.geometry.fingertipRadius, parkAbove(scene)) {}

  // The fingertips wait well above everything until the mouse uses them.
  static Vec3 parkAbove(const BuiltScene& scene) {
    Eigen::AlignedBox3f box;
    for (const SceneBody& b : scene.bodies) box.extend(bodyBounds(*scene.world, b.id));
    return Vec3(box.center().x(), box.max().y() + box.sizes().maxCoeff() + 1.0f, box.center().z());
  }
};

// How a built scene's loop runs: the viewer's defaults, or a study's trial.
struct LoopOptions {
  std::string weart;                          // HOST[:PORT] of the WEART middleware; empty: the mouse is the hand
  bool paused = false;                        // the loop starts paused
  bool scripted = false;                      // the scene's scripted hand drives it (a study's dry run)
  const StudyCondition* condition = nullptr;  // a study's trial in this condition, its signal recorded:
  std::filesystem::path forces;               // here (CSV), the task events beside it
  std::uint64_t maxSteps = 0;                 // 0: until stopped
};

std::unique_ptr<Running> start(const SceneSpec& spec, const SceneBuildObserver& observer, const LoopOptions& o) {
  auto r = std::make_unique<Running>(spec, observer);
  r->mouseInput.set(r->mouse.update({}, r->posed, OrbitCamera{}, 0.0f));  // parked
  SimulationLoopSettings settings;
  settings.maxSteps = o.maxSteps;
  settings.input = &r->mouseInput;
  if (!o.weart.empty() && spec.hand.enabled) {
    const Vec3 point = r->scene.actions.empty() ? r->scene.bodies.front().top : r->scene.actions.front().target;
    r->glove.emplace(o.weart, r->scene.session.hand, point);
    settings.input = &r->glove->input();
  }
  HapticOutput* glove = r->glove ? &r->glove->output() : nullptr;
  if (o.condition)
    r->trial.emplace(settings, r->scene, *o.condition, glove, o.forces);
  else if (glove)
    settings.outputs.push_back(glove);
  if (o.scripted) settings.input = nullptr;
  captureSnapshot(r->settled, *r->scene.world, nullptr, 0, 0.0);
  captureConstraintForces(r->settled, *r->scene.world);
  r->posed.pose(r->settled, ColorMap::None);
  r->loop = std::make_unique<SimulationLoop>(r->scene, settings);
  r->channel = r->loop->subscribe();
  r->loop->setPaused(o.paused);
  r->loop->start();
  return r;
}

// Recent values for a plot, oldest first once full.
class History {
 public:
  explicit History(std::size_t n = 300) : values_(n, 0.0f) {}
  void add(float v) {
    values_[next_] = v;
    next_ = (next_ + 1) % values_.size();
  }
  const float* data() const { return values_.data(); }
  int size() const { return int(values_.size()); }
  int offset() const { return int(next_); }

 private:
  std::vector<float> values_;
  std::size_t next_ = 0;
};

class Viewer {
 public:
  // Ctrl-C (`signals`) stops a build in any phase (vrd::Stopped) and ends the window's loop.
  Viewer(GLFWwindow* window, const ViewerOptions& options, const StopSignals& signals)
      : window_(window), options_(options), signals_(signals), observer_(commandObserver(signals)) {
    render_.colorMap = options.colorMap;
    loop_.weart = options.weart;
    if (options.study) {
      prepareStudyStep(true);
    } else {
      spec_ = loadSceneByName(options.scene);
      sceneName_ = spec_.name;
      rebuild();
    }
    render_.colorRange = defaultColorRange(options.colorMap, running_->settled);
  }

  int run();

 private:
  void rebuild();
  void takeSnapshot();
  void handleInput(float dt);
  void panels();
  void scenePanel();
  void colorLegend() const;
  void solverPanel();
  void materialPanel();
  void hapticsPanel();
  void forcePanel();
  void timingPanel();
  void convergencePanel();
  void screenshot(int width, int height) const;
  // A study's participant (options_.study): one panel for the step at hand.
  void prepareStudyStep(bool first);
  void studyPanel();
  void trialPanel(const StudyStep& step);
  void startTrial();
  void finishTrial();
  void restPanel();
  void questionsPanel(const StudyStep& step);
  bool studyDone() const { return options_.study && options_.study->next().kind == StudyStepKind::Done; }

  GLFWwindow* window_;
  ViewerOptions options_;
  const StopSignals& signals_;
  SceneBuildObserver observer_;     // prints the build's progress on the terminal; Ctrl-C stops it
  SceneSpec spec_;                  // what the next rebuild builds (the sliders edit it)
  LoopOptions loop_;                // how its loop runs
  std::optional<SceneSpec> built_;  // what the running scene was built from
  std::string sceneName_;
  std::unique_ptr<Running> running_;
  std::string error_;  // shown in the panel: why the loop stopped or a rebuild was refused
  OrbitCamera camera_;
  RenderSettings render_;
  bool paused_ = false, grabbing_ = false, colorMapChanged_ = false;
  bool stopped_ = false, failed_ = false;  // the running loop ended; it ended with an error
  double lastX_ = 0, lastY_ = 0;
  std::array<History, kFingerCount> force_, newtons_;
  StageTimes stageMs_{};                         // smoothed
  std::array<Residual, kStageCount> residuals_;  // of the newest snapshot
  int snapshotIterations_ = 0;
  double stepWallMs_ = 0.0, frameMs_ = 0.0;
  std::uint64_t lastStep_ = 0;
  bool trialStarted_ = false;
  std::optional<TaskEndWatch> taskEnd_;  // the trial's end condition
  bool endConditionMet_ = false;
  Clock::time_point trialBegan_, restBegan_;
  std::optional<Questionnaire> questionnaire_;
};

void Viewer::rebuild() {
  running_.reset();  // stops the old loop first
  error_.clear();
  stopped_ = false;
  glfwSetWindowTitle(window_, fmt::format("vrdeform view: {} (building...)", spec_.name).c_str());
  try {
    running_ = start(spec_, observer_, loop_);
    built_ = spec_;
  } catch (const Error& e) {  // e.g. a material the builder refuses: back to the last scene that built
    fmt::print(stderr, "vrdeform: cannot rebuild {}: {}\n", spec_.name, e.what());
    if (!built_) throw;
    spec_ = *built_;
    running_ = start(spec_, observer_, loop_);
    error_ = fmt::format("rebuild refused: {}", e.what());
  }
  glfwSetWindowTitle(window_, fmt::format("vrdeform view: {}", spec_.name).c_str());
  camera_.frame(running_->posed.bounds());
  running_->loop->setPaused(paused_);
  running_->loop->setConstraintForces(render_.colorMap == ColorMap::ConstraintForce);
  for (History& h : force_) h = History();
  for (History& h : newtons_) h = History();
  lastStep_ = 0;
}

void Viewer::takeSnapshot() {
  Running& r = *running_;
  const bool fresh = r.channel->update();
  const Snapshot& s = r.channel->front();
  if (s.step == 0) {
    if (colorMapChanged_) r.posed.pose(r.settled, render_.colorMap);
    colorMapChanged_ = false;
    return;
  }
  if (fresh || colorMapChanged_) r.posed.pose(s, render_.colorMap);
  colorMapChanged_ = false;
  if (!fresh || s.step == lastStep_) return;
  lastStep_ = s.step;
  for (int f = 0; f < kFingerCount; ++f) {
    force_[f].add(s.haptics.fingers[f].force);
    newtons_[f].add(s.haptics.fingers[f].newtons);
  }
  const double a = 0.05;  // smoothing of the displayed times (about 20 snapshots)
  for (std::size_t i = 0; i < kStageCount; ++i) stageMs_.ms[i] += a * (s.times.ms[i] - stageMs_.ms[i]);
  residuals_ = s.residuals;
  snapshotIterations_ = s.iterations;
  stepWallMs_ += a * (s.stepWallMs - stepWallMs_);
}

void Viewer::handleInput(float dt) {
  const ImGuiIO& io = ImGui::GetIO();
  double x = 0, y = 0;
  glfwGetCursorPos(window_, &x, &y);
  int w = 1, h = 1;
  glfwGetWindowSize(window_, &w, &h);
  const float dx = float(x - lastX_), dy = float(y - lastY_);
  lastX_ = x;
  lastY_ = y;
  const bool uiMouse = io.WantCaptureMouse, uiKeys = io.WantCaptureKeyboard;
  if (!uiMouse) {
    if (glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS) {
      if (glfwGetKey(window_, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS)
        camera_.pan(dx / float(h), dy / float(h));
      else
        camera_.orbit(-0.008f * dx, 0.008f * dy);
    }
    if (glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS) camera_.pan(dx / float(h), dy / float(h));
    if (io.MouseWheel != 0.0f) camera_.zoom(std::pow(0.9f, io.MouseWheel));
  }
  if (!uiKeys && options_.study) {
    if (ImGui::IsKeyPressed(GLFW_KEY_SPACE) && !trialStarted_) {
      const StudyStepKind k = options_.study->next().kind;
      if (k == StudyStepKind::Practice || k == StudyStepKind::Trial) startTrial();
    }
    if (ImGui::IsKeyPressed(GLFW_KEY_R)) camera_.frame(running_->posed.bounds());
    if (ImGui::IsKeyPressed(GLFW_KEY_ESCAPE)) glfwSetWindowShouldClose(window_, GLFW_TRUE);
  } else if (!uiKeys) {
    if (ImGui::IsKeyPressed(GLFW_KEY_SPACE)) {
      paused_ = !paused_;
      running_->loop->setPaused(paused_);
    }
    if (ImGui::IsKeyPressed(GLFW_KEY_N) && paused_) running_->loop->requestSteps(1);
    if (ImGui::IsKeyPressed(GLFW_KEY_R)) camera_.frame(running_->posed.bounds());
    if (ImGui::IsKeyPressed(GLFW_KEY_ESCAPE)) glfwSetWindowShouldClose(window_, GLFW_TRUE);
  }
  if (running_->glove) return;  // the glove is the hand
  // Cursor coordinates to the framebuffer's pixels (they differ on high-density screens).
  int fw = 1, fh = 1;
  glfwGetFramebufferSize(window_, &fw, &fh);
  MouseState m;
  m.x = float(x) * float(fw) / float(std::max(w, 1));
  m.y = float(y) * float(fh) / float(std::max(h, 1));
  m.width = fw;
  m.height = fh;
  // A press that starts on a panel stays the panel's; one that started on the scene keeps poking.
  const bool left = glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
  if (!left) grabbing_ = false;
  if (left && !uiMouse && !running_->mouse.busy()) grabbing_ = true;
  m.poke = left && grabbing_;
  m.pinch = !uiKeys && glfwGetKey(window_, GLFW_KEY_G) == GLFW_PRESS;
  running_->mouseInput.set(running_->mouse.update(m, running_->posed, camera_, dt));
}

void Viewer::scenePanel() {
  if (ImGui::BeginCombo("scene", sceneName_.c_str())) {
    for (const SceneEntry& e : builtinScenes())
      if (ImGui::Selectable(e.name.c_str(), e.name == sceneName_)) {
        sceneName_ = e.name;
        spec_ = loadSceneByName(e.name);
        rebuild();
      }
    ImGui::EndCombo();
  }
  if (ImGui::Button(paused_ ? "Play" : "Pause")) {
    paused_ = !paused_;
    running_->loop->setPaused(paused_);
  }
  ImGui::SameLine();
  ImGui::BeginDisabled(!paused_);
  if (ImGui::Button("Step")) running_->loop->requestSteps(1);
  ImGui::EndDisabled();
  ImGui::SameLine();
  if (ImGui::Button("Restart")) rebuild();
  const Snapshot& s = running_->channel->front();
  ImGui::Text("t = %.2f s, step %llu, %s", s.time, static_cast<unsigned long long>(s.step),
              running_->glove ? "hand: glove" : "hand: mouse");
  if (!error_.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.3f, 1), "%s", error_.c_str());
  ImGui::TextDisabled(
      "left drag: poke  G: pinch  right drag: orbit\nwheel: zoom  shift/middle drag: pan\nspace: pause  N: step  R: "
      "reframe");

  int map = int(render_.colorMap);
  if (ImGui::Combo("colour", &map, "none\0strain\0volume change\0constraint force\0")) {
    render_.colorMap = ColorMap(map);
    render_.colorRange = defaultColorRange(render_.colorMap, running_->settled);
    running_->loop->setConstraintForces(render_.colorMap == ColorMap::ConstraintForce);
    colorMapChanged_ = true;
  }
  if (render_.colorMap == ColorMap::ConstraintForce)
    ImGui::SliderFloat("range (N)", &render_.colorRange, 0.001f, 100.0f, "%.3f", ImGuiSliderFlags_Logarithmic);
  else if (render_.colorMap != ColorMap::None)
    ImGui::SliderFloat("range", &render_.colorRange, 0.001f, 0.5f, "%.3f", ImGuiSliderFlags_Logarithmic);
  if (render_.colorMap != ColorMap::None) colorLegend();
  ImGui::Checkbox("fingertips", &render_.fingertips);
  ImGui::SameLine();
  ImGui::Checkbox("colliders", &render_.colliders);
}

// The colour map's key: the bar the shader draws (blue at -range, white at 0, red at +range) with
// its ends and middle labelled in the map's units.
void Viewer::colorLegend() const {
  const float r = render_.colorRange;
  const bool force = render_.colorMap == ColorMap::ConstraintForce;
  const std::string unit = force ? " N" : render_.colorMap == ColorMap::Strain ? " strain" : " of volume";
  const ImVec2 at = ImGui::GetCursorScreenPos();
  const float width = std::max(ImGui::GetContentRegionAvail().x, 60.0f), height = 12.0f;
  const ImU32 blue = IM_COL32(38, 89, 242, 255), white = IM_COL32(235, 235, 235, 255), red = IM_COL32(230, 38, 26, 255);
  ImDrawList* draw = ImGui::GetWindowDrawList();
  const ImVec2 mid(at.x + 0.5f * width, at.y + height), end(at.x + width, at.y + height);
  draw->AddRectFilledMultiColor(at, mid, blue, white, white, blue);
  draw->AddRectFilledMultiColor(ImVec2(mid.x, at.y), end, white, red, red, white);
  ImGui::Dummy(ImVec2(width, height));
  // A force map shows magnitudes (0 to range, white to red); strain and volume change are signed.
  const std::string low = force ? "" : fmt::format("{:.3g}{}", -r, unit), high = fmt::format("{:.3g}{}", r, unit);
  ImGui::TextUnformatted(low.c_str());
  ImGui::SameLine(0.5f * width - 0.5f * ImGui::CalcTextSize("0").x);
  ImGui::TextUnformatted("0");
  ImGui::SameLine(width - ImGui::CalcTextSize(high.c_str()).x);
  ImGui::TextUnformatted(high.c_str());
}

void Viewer::solverPanel() {
  SolverSettings& s = spec_.solver;
  bool changed = ImGui::SliderInt("iterations", &s.iterations, 1, 50);
  changed |= ImGui::SliderInt("substeps", &s.substeps, 1, 32);
  changed |= ImGui::SliderFloat("damping (1/s)", &s.linearDamping, 0.0f, 20.0f);
  if (changed) running_->loop->setSolverSettings(s);  // live, applied between two steps
  ImGui::Text("rate %.0f Hz (the scene's; its calibration belongs to it)", 1.0 / s.timeStep);
}

void Viewer::materialPanel() {
  bool edited = false;
  for (BodySpec& b : spec_.bodies) {
    ImGui::PushID(b.name.c_str());
    ImGui::TextUnformatted(b.name.c_str());
    Material& m = b.material;
    if (m.elastic) {
      edited |=
          ImGui::SliderFloat("E (Pa)", &m.elastic->youngsModulus, 1e2f, 1e7f, "%.3g", ImGuiSliderFlags_Logarithmic);
      edited |= ImGui::SliderFloat("Poisson", &m.elastic->poissonRatio, 0.0f, 0.49f, "%.3f");
      edited |= ImGui::SliderFloat("Rayleigh tau (s)", &m.elastic->rayleighDamping, 0.0f, 0.05f, "%.4f");
    } else {
      const auto pair = [&](const char* name, ConstraintMaterial& c) {
        ImGui::PushID(name);
        edited |= ImGui::SliderFloat(fmt::format("{} compliance", name).c_str(), &c.compliance, 1e-7f, 1.0f, "%.2e",
                                     ImGuiSliderFlags_Logarithmic);
        edited |= ImGui::SliderFloat(fmt::format("{} damping", name).c_str(), &c.damping, 0.0f, 0.2f, "%.3f");
        ImGui::PopID();
      };
      if (b.kind == BodyKind::Cloth) {
        pair("stretch", m.distance);
        pair("bending", m.bending);
      } else {
        pair("volume", m.volume);
        pair("strain stretch", m.strainStretch);
        pair("strain shear", m.strainShear);
        pair("shape matching", m.shapeMatching);
      }
    }
    ImGui::PopID();
  }
  (void)edited;
  if (ImGui::Button("Apply materials (rebuilds the scene)")) rebuild();
}

void Viewer::hapticsPanel() {
  HapticSettings& h = spec_.haptics.settings;
  ImGui::Checkbox("calibrate tau on rebuild", &spec_.haptics.calibrate);
  ImGui::SliderFloat("alpha_t (eq. 44)", &h.signal.alphaT, 0.01f, 1.0f);
  ImGui::SliderFloat("beta_c (eq. 43)", &h.signal.betaContact, 0.0f, 1.0f);
  ImGui::SliderFloat("max change / ms", &h.maxChangePerMs, 0.001f, 1.0f, "%.3f", ImGuiSliderFlags_Logarithmic);
  if (!spec_.haptics.calibrate) {
    ImGui::SliderFloat("tau_C", &h.signal.tauContact, 1e-4f, 1e2f, "%.3g", ImGuiSliderFlags_Logarithmic);
    ImGui::SliderFloat("tau_finger", &h.signal.tauFingerContact, 1e-4f, 1e2f, "%.3g", ImGuiSliderFlags_Logarithmic);
  }
  ImGui::SliderFloat("poke depth (radii)", &running_->mouse.settings.pokeDepth, 0.1f, 3.0f);
  if (ImGui::Button("Apply haptics (rebuilds the scene)")) rebuild();
}

void Viewer::forcePanel() {
  const Snapshot& s = running_->channel->front();
  ImGui::Text("contact %s, grasp %s, hand (Algorithm 2) %.3f", s.contact ? "yes" : "no", s.grasping ? "on" : "off",
              s.haptics.paper);
  for (int f = 0; f < kFingerCount; ++f) {
    if (!s.fingerPresent[f]) continue;
    // The label above its plot, which takes the panel's width: beside it, it was cut off.
    ImGui::Text("%s %.2f (%.3f N)", std::string(fingerName(Finger(f))).c_str(), s.haptics.fingers[f].force,
                s.haptics.fingers[f].newtons);
    ImGui::PlotLines(fmt::format("##force{}", f).c_str(), force_[f].data(), force_[f].size(), force_[f].offset(),
                     nullptr, 0.0f, 1.0f, ImVec2(-1.0f, 40.0f));
  }
  for (const SceneBody& b : running_->scene.bodies)
    if (b.kind == BodyKind::Soft)
      ImGui::Text("volume loss %s: %.3f%%", b.name.c_str(), 100.0 * running_->posed.volumeLoss(b.id));
}

void Viewer::timingPanel() {
  ImGui::Text("step %.3f ms of %.3f ms; frame %.2f ms (%.0f fps)", stepWallMs_, 1e3 * spec_.solver.timeStep, frameMs_,
              frameMs_ > 0 ? 1e3 / frameMs_ : 0.0);
  if (ImGui::BeginTable("stages", 2)) {
    for (std::size_t i = 0; i < kStageCount; ++i) {
      if (stageMs_.ms[i] < 5e-5) continue;
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(std::string(stageName(Stage(i))).c_str());
      ImGui::TableNextColumn();
      ImGui::Text("%.4f ms", stageMs_.ms[i]);
    }
    ImGui::EndTable();
  }
}

void Viewer::convergencePanel() {
  ImGui::Text("%d iterations this step; corrections of the last / mean rest edge:", snapshotIterations_);
  if (ImGui::BeginTable("residuals", 3)) {
    for (std::size_t i = 0; i < kStageCount; ++i) {
      const Residual& r = residuals_[i];
      if (!std::isfinite(r.max)) continue;
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(std::string(stageName(Stage(i))).c_str());
      ImGui::TableNextColumn();
      ImGui::Text("RMS %.1e", r.rms);
      ImGui::TableNextColumn();
      ImGui::Text("max %.1e", r.max);
    }
    ImGui::EndTable();
  }
}

void Viewer::panels() {
  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(430, 0), ImGuiCond_FirstUseEver);
  ImGui::Begin("vrdeform");
  scenePanel();
  if (ImGui::CollapsingHeader("Solver (live)", ImGuiTreeNodeFlags_DefaultOpen)) solverPanel();
  if (ImGui::CollapsingHeader("Materials")) materialPanel();
  if (ImGui::CollapsingHeader("Haptics")) hapticsPanel();
  if (ImGui::CollapsingHeader("Forces", ImGuiTreeNodeFlags_DefaultOpen)) forcePanel();
  if (ImGui::CollapsingHeader("Stage times")) timingPanel();
  if (ImGui::CollapsingHeader("Convergence")) convergencePanel();
  ImGui::End();
}

// The scene the participant's next step shows. A trial's is built afresh and paused, its signal
// recorded into the trial's scratch folder, until the participant starts it; after the last trial
// of a condition its scene stays in view through the questions and the rest.
void Viewer::prepareStudyStep(bool first) {
  ParticipantProgress& p = *options_.study;
  const StudyStep s = p.next();
  questionnaire_.reset();
  trialStarted_ = false;
  restBegan_ = Clock::now();
  const bool trial = s.kind == StudyStepKind::Practice || s.kind == StudyStepKind::Trial;
  if (!trial && !first) return;
  loop_ = LoopOptions();
  loop_.weart = options_.weart;
  loop_.paused = true;
  if (trial) {
    const StudyCondition& c = p.condition(s);
    spec_ = c.spec;
    loop_.maxSteps = p.trialSteps(s);
    loop_.forces = p.beginTrial() / "forces.csv";
    loop_.condition = &c;
    taskEnd_.emplace(p.task(s).end);
    endConditionMet_ = false;
    loop_.scripted = options_.autopilot;
  } else {
    spec_ = p.study().conditions[s.kind == StudyStepKind::ConditionQuestions ? s.condition : p.order().front()].spec;
  }
  paused_ = true;
  rebuild();
  glfwSetWindowTitle(window_, fmt::format("vrdeform study: {}, P{}", p.study().name, p.participant()).c_str());
}

void Viewer::studyPanel() {
  const ParticipantProgress& p = *options_.study;
  const StudyStep s = p.next();
  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(560, 0), ImGuiCond_FirstUseEver);
  ImGui::Begin("Study");
  ImGui::TextDisabled("%s, P%zu", p.study().name.c_str(), p.participant());
  switch (s.kind) {
    case StudyStepKind::Practice:
    case StudyStepKind::Trial:
      trialPanel(s);
      break;
    case StudyStepKind::ConditionQuestions:
    case StudyStepKind::StudyQuestions:
      questionsPanel(s);
      break;
    case StudyStepKind::Rest:
      restPanel();
      break;
    case StudyStepKind::Done:
      ImGui::TextWrapped("All done: thank you! (Esc closes the window.)");
      break;
  }
  if (!error_.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.3f, 1), "%s", error_.c_str());
  ImGui::End();
}

void Viewer::trialPanel(const StudyStep& s) {
  const ParticipantProgress& p = *options_.study;
  const StudyTask& task = p.task(s);
  const std::string title = s.kind == StudyStepKind::Practice
                                ? std::string("Practice")
                                : fmt::format("Part {} of {}: {}, trial {} of {}", s.position + 1, p.order().size(),
                                              task.name, s.trial, p.study().trials);
  ImGui::TextUnformatted(title.c_str());
  if (!task.instructions.empty()) ImGui::TextWrapped("%s", task.instructions.c_str());
  if (failed_) {  // the simulation failed: this trial is not kept
    if (ImGui::Button("Run the trial again")) {
      failed_ = false;
      prepareStudyStep(false);
    }
    return;
  }
  if (!trialStarted_) {
    if (ImGui::Button("Start (space)") || options_.autopilot) startTrial();
    return;
  }
  ImGui::ProgressBar(float(double(running_->loop->steps()) / double(loop_.maxSteps)));
  const Snapshot& now = running_->channel->front();
  if (!stopped_ && now.step > 0 && taskEnd_->update(now.contact, now.grasping, now.time)) {
    running_->loop->stop();  // the task is done before its length
    stopped_ = endConditionMet_ = true;
  }
  if (stopped_) finishTrial();
}

void Viewer::startTrial() {
  trialStarted_ = true;
  paused_ = false;
  trialBegan_ = Clock::now();
  running_->loop->setPaused(false);
}

// The trial's loop ran its steps (run() stopped it): its record, and the next step.
void Viewer::finishTrial() {
  Running& r = *running_;
  r.trial->finish(*r.loop);
  const double wall = std::chrono::duration<double>(Clock::now() - trialBegan_).count();
  options_.study->finishTrial({r.loop->stats().steps, wall, std::nullopt, endConditionMet_});
  prepareStudyStep(false);
}

void Viewer::restPanel() {
  const double left =
      options_.study->study().restSeconds - std::chrono::duration<double>(Clock::now() - restBegan_).count();
  if (left > 0.0 && !options_.autopilot) {
    ImGui::TextWrapped("Time for a rest: take the glove off if you like.");
    ImGui::ProgressBar(float(1.0 - left / options_.study->study().restSeconds), ImVec2(-1.0f, 0.0f),
                       fmt::format("{:.0f} s", left).c_str());
    return;
  }
  ImGui::TextWrapped("The rest is over.");
  if (ImGui::Button("Continue") || options_.autopilot) {
    options_.study->finishRest();
    prepareStudyStep(false);
  }
}

void Viewer::questionsPanel(const StudyStep& s) {
  ParticipantProgress& p = *options_.study;
  const bool last = s.kind == StudyStepKind::StudyQuestions;
  if (!questionnaire_) questionnaire_.emplace(p.study(), p.order(), last);
  const std::string title = last ? std::string("Every part done: a few last questions.")
                                 : fmt::format("Part {} of {} done: how was it?", s.position + 1, p.order().size());
  ImGui::TextUnformatted(title.c_str());
  ImGui::Separator();
  if (options_.autopilot) questionnaire_->answerForDryRun();
  if (questionnaire_->draw() || options_.autopilot) {
    if (last)
      p.answer(questionnaire_->finalAnswers());
    else
      p.answer(questionnaire_->conditionAnswers());
    prepareStudyStep(false);
  }
}

void Viewer::screenshot(int width, int height) const {
  vrd::Image bottomUp(width, height), image(width, height);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, bottomUp.rgba.data());
  const std::size_t row = std::size_t(width) * 4;
  for (int y = 0; y < height; ++y)
    std::copy_n(&bottomUp.rgba[std::size_t(height - 1 - y) * row], row, &image.rgba[std::size_t(y) * row]);
  writePng(options_.screenshot, image);
  fmt::print("screenshot: {} ({}x{})\n", options_.screenshot, width, height);
}

int Viewer::run() {
  int frames = 0;
  const Clock::time_point opened = Clock::now();
  Clock::time_point last = opened;
  while (!glfwWindowShouldClose(window_) && !signals_.requested()) {
    glfwPollEvents();
    const Clock::time_point now = Clock::now();
    const float dt = std::min(std::chrono::duration<float>(now - last).count(), 0.1f);
    frameMs_ += 0.05 * (1e3 * double(dt) - frameMs_);
    last = now;
    if (!running_->loop->running() && !stopped_) {
      stopped_ = true;
      try {
        running_->loop->stop();
        if (!options_.study) error_ = "stopped: the loop ended";  // a study's trial ends so
      } catch (const std::exception& e) {
        error_ = fmt::format("stopped: {}", e.what());
        failed_ = true;
        fmt::print(stderr, "vrdeform: the simulation stopped: {}\n", e.what());
      }
    }
    if (running_->glove) running_->glove->reportEvents();
    takeSnapshot();

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    handleInput(dt);
    if (options_.study)
      studyPanel();
    else
      panels();
    ImGui::Render();

    int width = 1, height = 1;
    glfwGetFramebufferSize(window_, &width, &height);
    const Snapshot& s = running_->channel->front().step > 0 ? running_->channel->front() : running_->settled;
    RenderSettings settings = render_;
    if (!running_->glove)  // the mouse hand shows the fingers it uses; a glove shows them all
      for (int f = 0; f < kFingerCount; ++f) settings.showFinger[f] = running_->mouse.active()[f];
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    running_->renderer.draw(running_->posed, s, camera_, width, height, settings);
    ++frames;
    const bool done =
        (options_.frames > 0 && frames >= options_.frames) || (options_.autopilot && (studyDone() || failed_)) ||
        (options_.seconds > 0.0 && std::chrono::duration<double>(now - opened).count() >= options_.seconds);
    if (done && !options_.screenshot.empty()) screenshot(width, height);  // the 3D view, before the panels
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    glfwSwapBuffers(window_);
    if (done) break;
  }
  running_.reset();
  return failed_ ? 1 : 0;
}

}  // namespace

int runViewer(const ViewerOptions& options) {
  // First of all: a Ctrl-C while the window opens stops too (a script's background job ignores
  // SIGINT until a handler is installed).
  const StopSignals signals;
  glfwSetErrorCallback([](int code, const char* text) { fmt::print(stderr, "glfw: {} (0x{:x})\n", text, code); });
  if (!glfwInit()) {
    fmt::print(stderr, "vrdeform: cannot open a window (no display?); `vrdeform render` draws headless\n");
    return 1;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SAMPLES, 4);
  GLFWwindow* window = glfwCreateWindow(options.width, options.height, "vrdeform view", nullptr, nullptr);
  if (!window) {
    glfwTerminate();
    fmt::print(stderr, "vrdeform: cannot open an OpenGL 3.3 window\n");
    return 1;
  }
  glfwMakeContextCurrent(window);
  keepGlDriverLoaded();
  glfwSwapInterval(1);  // the display's rate
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini left in the working folder
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330");
  int status = 1;
  try {
    Viewer viewer(window, options, signals);
    status = viewer.run();
  } catch (...) {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    glfwDestroyWindow(window);
    glfwTerminate();
    throw;
  }
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
  glfwTerminate();
  return status;
}

}  // namespace vrd
