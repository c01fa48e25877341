// The hinge angle and the multi-turn angle (MATH.md Q11).
//
//   (Q11) θ = 2·atan2(q_v·ẑ, q0) with q0 ≥ 0, θ ∈ (−π, π];   θ_k = θ_{k−1} + wrap(θ_raw − θ_{k−1}), wrap into (−π, π].
//
// θ is the twist of q about the hinge axis ẑ (the swing–twist decomposition q = swing ⊗ twist), so it is defined
// whenever the axes are not exactly flipped, and equals the rotation about the hinge on the hinge.
// Its exact derivative (from q̇ = ½ Ω ⊗ q, Q5):
//   θ̇ = Ω·t,  t = ẑ + ((q0 q_y + q_z q_x), (q_z q_y − q0 q_x), 0) / (q0² + q_z²)    (in joint frame A)
// which is ẑ on the hinge; the axial (limit and drive) rows use t, so they are exact too.
// Stock convention: btHingeConstraint::getHingeAngle() returns −θ unless useReferenceFrameA, where it returns θ.
// The multi-turn update relies on the relative rotation per step staying below π; Bullet's integrator clamps each
// body's rotation to π/4 per step (ANGULAR_MOTION_THRESHOLD), so relative rotation stays below π/2.
#ifndef QUATHINGE_HINGE_ANGLE_H
#define QUATHINGE_HINGE_ANGLE_H

#include "LinearMath/btQuaternion.h"
#include "LinearMath/btScalar.h"
#include "LinearMath/btVector3.h"
#include "QuaternionHingeRows.h"  // beyondQuarterTurn (Q12)

namespace quathinge
{
/// The user angle α = σθ: σ = +1 with useReferenceFrameA, −1 without (btHingeConstraint::getHingeAngle's sign).
inline btScalar userSign(bool useReferenceFrameA) { return useReferenceFrameA ? btScalar(1) : btScalar(-1); }

/// Wraps an angle into (−π, π].
btScalar wrapAngle(btScalar angle);

/// (Q11) θ ∈ (−π, π] from the relative quaternion q (either sign of q).
btScalar hingeAngle(const btQuaternion& q);

/// ∂θ/∂Ω in joint frame A (see above); ẑ when the axes are exactly flipped (θ undefined there). Inline, as the next:
/// asked at every step with a limit.
inline btVector3 hingeAngleGradient(const btQuaternion& q)
{
	const btScalar w = q.w(), x = q.x(), y = q.y(), z = q.z();
	const btScalar c2 = w * w + z * z;
	if (c2 <= SIMD_EPSILON * SIMD_EPSILON) return btVector3(0, 0, 1);  // exactly flipped: θ undefined
	const btScalar inv = btScalar(1) / c2;
	return btVector3((w * y + z * x) * inv, (z * y - w * x) * inv, btScalar(1));
}

/// The direction of the axial (limit, drive, friction) rows in joint frame A: the exact gradient t while the axes are
/// within 90° (q0² + q_z² ≥ ½, where |t| ≤ √2), the hinge axis ẑ beyond. Past 90° the angle is ill-conditioned
/// (|t| grows as 1/cos(φ/2)); the fuzzer found a spring row there whose huge Jacobian threw a body to 1e27 rad/s.
/// The joint is then far from assembled and its quaternion rows (the log form, Q12) are what matters.
inline btVector3 axialRowDirection(const btQuaternion& q)
{
	return beyondQuarterTurn(q) ? btVector3(0, 0, 1) : hingeAngleGradient(q);
}

/// (Q11) the continuous update θ_k = θ_{k−1} + wrap(θ_raw − θ_{k−1}).
inline btScalar continueAngle(btScalar previous, btScalar raw) { return previous + wrapAngle(raw - previous); }

/// The angle θ_raw + 2πk closest to the interval [low, high] (inside it when some branch is).
btScalar nearestBranch(btScalar raw, btScalar low, btScalar high);

}  // namespace quathinge

#endif
