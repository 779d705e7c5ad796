#pragma once
// A study task's end condition (StudyTask::end), followed step by step on what the hand does, the
// same for a simulated participant (every step) and a live one (every snapshot the viewer draws).

#include "vrdeform/study/study_spec.h"

namespace vrd {

class TaskEndWatch {
 public:
  /// A poke ends after the hand has left the body this long: a finger lifting for a moment between
  /// two presses does not end it.
  static constexpr double kReleaseSeconds = 0.5;

  explicit TaskEndWatch(TaskEnd end) : end_(end) {}

  /// One step of the trial at `time` (s): whether a finger touches a body or a grasp holds one
  /// (`contact`), and whether a grasp holds. True from the step the task has ended on.
  bool update(bool contact, bool grasping, double time) {
    if (contact) {
      touched_ = true;
      lastContact_ = time;
    }
    grasped_ = grasped_ || grasping;
    switch (end_) {
      case TaskEnd::Time:
        return false;
      case TaskEnd::Release:
        return touched_ && !contact && time - lastContact_ >= kReleaseSeconds;
      case TaskEnd::GraspRelease:
        return grasped_ && !grasping;
    }
    return false;
  }

 private:
  TaskEnd end_;
  bool touched_ = false, grasped_ = false;
  double lastContact_ = 0.0;
};

/// The name a study file and trial.json give an end condition.
constexpr const char* taskEndName(TaskEnd end) {
  return end == TaskEnd::Release ? "release" : end == TaskEnd::GraspRelease ? "grasp_release" : "time";
}

}  // namespace vrd
