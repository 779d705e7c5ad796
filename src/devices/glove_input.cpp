#include "vrdeform/devices/glove_input.h"

namespace vrd::weart {

HandFrame GloveInput::frame(std::uint64_t, double) {
  if (const auto closures = client_.closures()) pose_.closure = *closures;
  HandFrame f;
  f.pose = pose_;
  return f;
}

}  // namespace vrd::weart
