// The one-at-a-time and 4-lane sweeps, with the default flags (any CPU of the architecture: SSE
// on x86-64, NEON on aarch64); see lane_sweeps.h.
#include "lane_sweeps.h"

#ifdef VRDEFORM_X86_LANES
#include <sleef.h>
#endif

namespace vrd {
#ifdef VRDEFORM_X86_LANES
Lane4 atan2(Lane4 y, Lane4 x) { return Sleef_atan2f4_u10sse2(y, x); }
#else
Lane4 atan2(Lane4 y, Lane4 x) {
  Lane4 r;
  for (std::size_t k = 0; k < 4; ++k) r[k] = std::atan2(y[k], x[k]);
  return r;
}
#endif
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
#ifdef VRDEFORM_X86_LANES
  if (widest == SimdLevel::Avx512) plan.widths[plan.count++] = &avx512Sweeps();
  if (widest >= SimdLevel::Avx2) plan.widths[plan.count++] = &avx2Sweeps();
#endif
  plan.widths[plan.count++] = &sseSweeps();
  return plan;
}

}  // namespace vrd::sweeps
