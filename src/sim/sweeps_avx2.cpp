// The 8-lane sweeps, compiled with -mavx2 -mfma (CMakeLists.txt); see lane_sweeps.h.
#include "lane_sweeps.h"

namespace vrd::sweeps {

const LaneSweeps& avx2Sweeps() {
  static const LaneSweeps sweeps = makeLaneSweeps<Lane8>();
  return sweeps;
}

}  // namespace vrd::sweeps
