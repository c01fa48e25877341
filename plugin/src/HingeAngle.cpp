// The hinge angle and the multi-turn angle (MATH.md Q11). Derivation: HingeAngle.h.
#include "HingeAngle.h"

#include <cmath>

namespace quathinge
{
btScalar wrapAngle(btScalar angle)
{
	// into (−π, π]; the per-step differences of the multi-turn update are already inside, so test before dividing
	if (angle > -SIMD_PI && angle <= SIMD_PI) return angle;
	angle = btFmod(angle, SIMD_2_PI);
	if (angle <= -SIMD_PI) angle += SIMD_2_PI;
	else if (angle > SIMD_PI) angle -= SIMD_2_PI;
	return angle;
}

btScalar hingeAngle(const btQuaternion& q)
{
	btScalar w = q.w(), z = q.z();
	// Axes flipped (to within float: q0² + q_z² ≤ ε, a swing within about 0.03° of π): the twist is undefined there,
	// and its formula would give whatever the round-off of q0 and q_z says (even −2π from atan2(−0, −0)). Stock's
	// formula is defined there (the angle of frame B's y about A's axis, btHingeConstraint::getHingeAngle):
	// θ = atan2(−m01, m11) of the rotation matrix of q, written homogeneously; taken into (−π, π].
	if (w * w + z * z <= SIMD_EPSILON * q.length2())
	{
		const btScalar x = q.x(), y = q.y();
		const btScalar theta = btAtan2(btScalar(2) * (w * z - x * y), w * w + y * y - x * x - z * z);
		return theta <= -SIMD_PI ? SIMD_PI : theta;
	}
	// (Q3, Q11) the representative with q0 ≥ 0 (and q_z ≥ 0 when q0 = 0) gives θ ∈ (−π, π].
	if (w < 0 || (w == 0 && z < 0))
	{
		w = -w;
		z = -z;
	}
	return btScalar(2) * btAtan2(z, w);
}

btScalar nearestBranch(btScalar raw, btScalar low, btScalar high)
{
	const bool lowFinite = std::isfinite(low), highFinite = std::isfinite(high);
	if (!lowFinite && !highFinite) return raw;
	const btScalar center = !lowFinite ? high - SIMD_PI : !highFinite ? low + SIMD_PI
																	  : btScalar(0.5) * (low + high);
	const btScalar k0 = btScalar(std::floor((center - raw) / SIMD_2_PI + btScalar(0.5)));
	btScalar best = raw + k0 * SIMD_2_PI;
	btScalar bestDistance = SIMD_INFINITY;
	for (int dk = -1; dk <= 1; ++dk)
	{
		const btScalar candidate = raw + (k0 + btScalar(dk)) * SIMD_2_PI;
		const btScalar distance = candidate < low ? low - candidate : candidate > high ? candidate - high
																					   : btScalar(0);
		// inside beats outside; among inside, the one nearest the centre (k0 itself)
		if (distance < bestDistance || (distance == 0 && dk == 0))
		{
			best = candidate;
			bestDistance = distance;
		}
	}
	return best;
}

}  // namespace quathinge
