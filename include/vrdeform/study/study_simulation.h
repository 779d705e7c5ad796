#pragma once
// A simulated participant (docs/study.md): walks through a study headless, so that a whole study
// (its data folder, resuming, the analysis) runs without a person. Each trial runs the condition's
// scene with its scripted hand for the task's length and keeps what the glove would have got
// (condition A: the haptic model's force; B: the baseline); the answers follow from what was felt.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "vrdeform/study/study_spec.h"

namespace vrd {

struct SimulatedParticipant {
  std::uint64_t seed = 1;  ///< the answers' noise; the same seed gives the same answers
  double noise = 0.7;      ///< standard deviation of an answer around its model value (points)
};

struct StudyRunSettings {
  std::filesystem::path dataDir;  ///< the study's data folder; the participant's goes in P<k>
  std::size_t participant = 1;    ///< k, from 1: their order of the conditions is study.orderOf(k)
  SimulatedParticipant simulated;
  std::function<bool()> stop;                   ///< polled between and during trials: true ends the run (vrd::Stopped)
  std::function<void(const std::string&)> log;  ///< a line per trial
};

struct StudyRunResult {
  std::size_t trialsRun = 0;   ///< run now
  std::size_t trialsKept = 0;  ///< finished by an earlier run and kept as they were
};

/// Runs participant k through their steps (study/participant_progress.h: the practice trial, every
/// condition's trials in their order, each followed by its questionnaire, the final questions),
/// answering from what was felt. Each trial's files (the run's per-step forces.csv, summary.json and
/// trial.json with what was felt) go into P<k>/trials/<position>-<task>-<trial>/; a run stopped or
/// killed part-way loses no finished trial or questionnaire, and a second run of the same participant
/// picks up where it ended. Throws vrd::Error for a scene that cannot be built or run, vrd::Stopped
/// when `stop` says so.
StudyRunResult runSimulatedParticipant(const StudySpec& study, const StudyRunSettings& settings);

}  // namespace vrd
