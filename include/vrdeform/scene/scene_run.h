#pragma once
// Runs a built scene headless: the hand (scripted, or any HandInput such as a glove) on the world
// through a HapticSession, step by step, collecting what `vrdeform run` reports and writes
// (docs/scenes.md#outputs): summary.json, the per-finger force trace, per-stage latencies, the
// deformed meshes for ParaView and plots of force against time and against indentation.

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "vrdeform/devices/haptic_output.h"
#include "vrdeform/interact/session_recording.h"
#include "vrdeform/metrics/latency_stats.h"
#include "vrdeform/metrics/signal_quality.h"
#include "vrdeform/scene/scene_builder.h"

namespace vrd {

/// One finished step, for progress reports and real-time pacing.
struct RunStep {
  std::uint64_t step = 0;                  ///< 0-based, counted from the end of settling
  double time = 0.0;                       ///< s since the end of settling, at the end of this step
  const HapticSession* session = nullptr;  ///< null in a scene without a hand
  const StageTimes* times = nullptr;       ///< this step's, per stage
  double volumeLoss = 0.0;                 ///< largest over the soft bodies, this step
  std::uint64_t nanEvents = 0;             ///< so far (RunSummary::nanEvents)
};

struct RunSettings {
  std::uint64_t steps = 0;             ///< steps to run (the hand input may not end them earlier)
  std::filesystem::path outDir;        ///< where the files go; empty: none
  HandInput* input = nullptr;          ///< replaces the scene's scripted hand (e.g. a glove); may be null
  std::vector<HapticOutput*> outputs;  ///< also receive every step's signal (OSC, a CSV log, ...)
  /// Called after every step; returning false ends the run there (Ctrl-C, a real-time pace).
  std::function<bool(const RunStep&)> afterStep;
  /// In a scene with a hand, called after every step with the hand the step consumed and its
  /// recordedOutputs, before afterStep: a SessionRecordingWriter's add for `vrdeform run --record`.
  std::function<void(const RecordedStep&)> record;
};

/// The signal of one of the scene's scripted pokes, from its start to 0.3 s after its release.
struct PokeSignal {
  Finger finger = Finger::Index;
  double start = 0.0;     ///< s after settling
  SignalQuality newtons;  ///< of the poking finger's force in newtons
  SignalQuality force;    ///< of its normalised force (what the glove gets)
};

/// One of the scene's scripted grasps whose time ran out during the run: how long it held the body.
struct GraspOutcome {
  Finger finger = Finger::Index;  ///< the finger that pinches with the thumb
  double start = 0.0;             ///< s after settling
  double seconds = 0.0;           ///< the action's length
  double heldSeconds = 0.0;       ///< 0: it never took hold
};

struct RunSummary {
  std::string scene;
  std::uint64_t steps = 0;
  double dt = 0.0;
  std::size_t tets = 0, particles = 0;
  std::map<std::string, std::size_t> constraints;  ///< count per type ("volume", "strain", ...)
  /// |v0 - v| / v0 (a gain counts as much as a loss), largest over the soft bodies
  double volumeLossMax = 0.0, volumeLossFinal = 0.0;
  /// Contact between bodies and within them: the most contacts that pushed at a step's end, and the
  /// deepest a vertex went past a surface it touches (m, StepReport::deepestPenetration).
  std::size_t bodyContactsMax = 0;
  float penetrationMax = 0.0f;
  std::array<bool, kFingerCount> fingers{};  ///< the hand's fingers
  std::array<float, kFingerCount> forceMax{}, newtonsMax{};
  float paperMax = 0.0f;
  std::vector<PokeSignal> pokes;     ///< the scripted pokes that ran to their end
  std::vector<GraspOutcome> grasps;  ///< the scripted grasps that ran to their end
  /// How converged the steps were, per constraint stage (StepReport::residuals): the mean of the
  /// steps' RMS and the largest max; NaN for stages not measured.
  std::array<Residual, kStageCount> residuals;
  double iterationsMean = 0.0;  ///< Gauss-Seidel iterations per step
  /// With a warm start, the share of substeps that started cold because it would have moved a
  /// particle too far (World::warmPushesFit): more than a few percent asks for more substeps.
  double coldSubstepShare = 0.0;
  /// Of those, the ones in steps where a fingertip touched a body: each can be a dip in what the
  /// finger feels (the substep rebuilds its contacts' multipliers from zero; docs/haptics.md).
  std::uint64_t coldSubstepsTouching = 0;
  std::uint64_t nanEvents = 0;      ///< bodies frozen or particles reset after a NaN
  std::vector<std::string> events;  ///< what the first 100 of them were
  LatencyRecorder latency;          ///< per step: idle (no finger touching, no grasp) or contact
  double wallSeconds = 0.0;
  bool ok = false;
  std::string error;
  std::vector<std::filesystem::path> files;  ///< written into outDir, relative to it
};

/// Runs the scene. With an outDir, writes every output there (creating the folder) and
/// summary.json last, also when the run fails (then with ok = false and the error), and rethrows.
RunSummary runScene(BuiltScene& scene, const RunSettings& settings);

/// summary.json's text (docs/scenes.md lists the keys).
std::string summaryJson(const RunSummary& summary);

}  // namespace vrd
