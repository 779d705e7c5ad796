#pragma once
// A particle held at a point, fixed or moving, with compliance: C = A (p - t), where the diagonal
// mask A selects the world axes held. All three axes pin the particle; a single axis makes a
// roller that slides freely in the other two. The multiplier is a vector; lambda/h^2 is the
// force the attachment applies (N).

#include "vrdeform/sim/xpbd.h"

namespace vrd {

struct Attachment {
  Index particle;     ///< world particle index
  Vec3 target;        ///< t: the point the particle is held at in the current substep
  Vec3 goal;          ///< where t arrives at the end of the step; substeps move t there linearly
  Vec3 axes;          ///< 1 for each held world axis, 0 for free ones
  float compliance;   ///< alpha (m/N)
  float dampingTime;  ///< tau = alpha * beta (s), see xpbd.h
};

/// Eqs. 1 and 3 for the vector constraint: returns dLambda; the particle moves by w dLambda.
inline Vec3 solveAttachment(const Point& p, const Vec3& target, const Vec3& axes, const Vec3& lambda,
                            const XpbdCoefficients& k, const Vec3& disp = Vec3::Zero()) {
  const float denominator = (1.0f + k.gamma) * p.w + k.alphaTilde;
  if (!(denominator > 1e-20f)) return Vec3::Zero();
  const Vec3 C = axes.cwiseProduct(p.pos - target);
  return (-C - k.alphaTilde * lambda - k.gamma * axes.cwiseProduct(disp)) / denominator;
}

}  // namespace vrd
