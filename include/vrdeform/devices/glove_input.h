#pragma once
// A hand driven by a WEART glove: the finger closures it tracks, on a wrist held where the user
// placed it (the TouchDIVER tracks fingers, not the hand's position).

#include "vrdeform/devices/weart_client.h"
#include "vrdeform/interact/hand_input.h"

namespace vrd::weart {

class GloveInput final : public HandInput {
 public:
  GloveInput(const Client& client, const Eigen::Isometry3f& wrist) : client_(client) { pose_.wrist = wrist; }
  /// The wrist pose with the glove's latest closures (open until the first tracking arrives).
  HandFrame frame(std::uint64_t step, double time) override;
  bool finished(std::uint64_t, double) const override { return false; }  ///< until the user stops

 private:
  const Client& client_;
  HandPose pose_;
};

}  // namespace vrd::weart
