// The 8-lane sweeps, compiled with -mavx2 -mfma (CMakeLists.txt); see lane_sweeps.h.
#include <sleef.h>

#include "sim/lane_sweeps.h"

namespace vrd {
Lane8 atan2(Lane8 y, Lane8 x) { return Sleef_atan2f8_u10avx2(y, x); }
}  // namespace vrd

namespace vrd::sweeps {

const LaneSweeps& avx2Sweeps() {
  static const LaneSweeps sweeps = makeLaneSweeps<Lane8>();
  return sweeps;
}

}  // namespace vrd::sweeps
