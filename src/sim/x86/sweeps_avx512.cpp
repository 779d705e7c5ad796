// The 16-lane sweeps, compiled with -mavx512f (CMakeLists.txt); see lane_sweeps.h.
#include <sleef.h>

#include "sim/lane_sweeps.h"

namespace vrd {
Lane16 atan2(Lane16 y, Lane16 x) { return Sleef_atan2f16_u10avx512f(y, x); }
}  // namespace vrd

namespace vrd::sweeps {

const LaneSweeps& avx512Sweeps() {
  static const LaneSweeps sweeps = makeLaneSweeps<Lane16>();
  return sweeps;
}

}  // namespace vrd::sweeps
