// The 16-lane sweeps, compiled with -mavx512f (CMakeLists.txt); see lane_sweeps.h.
#include "lane_sweeps.h"

namespace vrd::sweeps {

const LaneSweeps& avx512Sweeps() {
  static const LaneSweeps sweeps = makeLaneSweeps<Lane16>();
  return sweeps;
}

}  // namespace vrd::sweeps
