#pragma once
// `vrdeform study run --vr`: a participant walked through their study on the VR page (docs/study.md):
// each trial's scene served to the headset, which drives the hand; the instructions, the
// questionnaires and the rests on a panel in the page, answered with the controller's or the
// hand's ray (or the mouse on a desktop browser).

#include <string>

#include "serve_command.h"
#include "vrdeform/study/participant_progress.h"

namespace vrd {

struct StudyVrOptions {
  ServeOptions serve;
  std::string weart;       ///< HOST[:PORT] of the participant's glove; empty: none
  bool autopilot = false;  ///< a dry run: steps start by themselves, scripted hands, middle answers
};

/// Walks `progress` on to its end, or until Ctrl-C (then returns with its finished steps kept).
/// Returns 0, or 1 when a dry run's simulation failed. Throws vrd::Error when the page cannot be
/// served (a port in use) and vrd::Stopped on Ctrl-C while a scene is built.
int runStudyInVr(ParticipantProgress& progress, const StudyVrOptions& options);

}  // namespace vrd
