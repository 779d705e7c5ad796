// The one-at-a-time and 4-lane sweeps, with the default flags (any x86-64); see lane_sweeps.h.
#include <sleef.h>

#include "lane_sweeps.h"

namespace vrd {
Lane4 atan2(Lane4 y, Lane4 x) { return Sleef_atan2f4_u10sse2(y, x); }
}  // namespace vrd

namespace vrd::sweeps {

const LaneSweeps& scalarSweeps() {
  static const LaneSweeps sweeps = makeLaneSweeps<float>();
  return sweeps;
}

const LaneSweeps& sseSweeps() {
  static const LaneSweeps sweeps = makeLaneSweeps<Lane4>();
  return sweeps;
}

LanePlan lanePlan(SimdLevel level) {
  LanePlan plan;
  const SimdLevel widest = resolveSimd(level);
  if (widest == SimdLevel::Off) {
    plan.widths[plan.count++] = &scalarSweeps();
    return plan;
  }
  if (widest == SimdLevel::Avx512) plan.widths[plan.count++] = &avx512Sweeps();
  if (widest >= SimdLevel::Avx2) plan.widths[plan.count++] = &avx2Sweeps();
  plan.widths[plan.count++] = &sseSweeps();
  return plan;
}

}  // namespace vrd::sweeps
