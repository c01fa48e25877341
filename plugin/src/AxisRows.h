// The axis part: limit, drive (velocity motor, servo, spring) and friction rows along the hinge axis.
//
// Each is one row J_α = σ t along the exact gradient of the angle (HingeAngle.h: θ̇ = Ω·t, α = σθ in the
// getHingeAngle convention, σ = +1 with useReferenceFrameA, else −1), so the solver drives α̇ = J_α·v:
//   limit (lower stop, impulse ≥ 0):   α̇ ≥ b·max(erp_stop·fps·(low − α), −r·α̇₀)   at or past the stop
//                                      α̇ ≥ −(α − low)·fps                          speculative, before the stop
//   (the speculative row is on once the stop is within (1 − softness)·half-range + |α̇|·h)
//   (upper stop mirrored, impulse ≤ 0; low == high: bilateral lock). b = biasFactor, r = relaxationFactor (bounce),
//   as btHingeConstraint's row; the speculative form lets the joint reach the stop within the step but not pass it.
//   α̇₀ is the speed the joint met the stop with: the larger of the current approach and the speed the last step's
//   speculative row caught it at (which leaves only the rest of the speed for this step; a catch slower than
//   0.2 rad/s, Bullet's contact restitution threshold, is not remembered), so the bounce is stock's r·b·α̇₀ wherever
//   within the step the stop was met. A stop row only pushes: impulse bounds [0, ∞) (lower) or
//   (−∞, 0] (upper) along J_α, targets that never ask the joint into the stop; on a joint to a static body the row is
//   taken off the tangential point row by an exact row operation that keeps those bounds (HingeSolverRows.cpp).
//   velocity motor:  α̇ = v_target, |impulse| ≤ maxMotorImpulse                   (btHingeConstraint's motor)
//   servo:           α̇ = clamp((α_target − α)·fps, ±maxSpeed), |impulse| ≤ maxTorque/fps   (reaches in one step)
//   spring:          implicit Euler of α̈ = −ω²(α − rest) − 2ζω α̇, ω = 2πf, for the pair's effective inertia:
//                    α̇₁ = (α̇₀ − hω²(α − rest)) / (1 + 2ζωh + h²ω²), applied as the fixed impulse m_eff (α̇₁ − α̇₀)
//                    (row bounds lower = upper = that impulse; Bullet's CFM cannot express a soft row: its PGS update
//                    diverges for CFM ≥ 1, which soft springs need).
//   friction:        α̇ = 0, |impulse| ≤ maxFrictionTorque/fps.
#ifndef QUATHINGE_AXIS_ROWS_H
#define QUATHINGE_AXIS_ROWS_H

#include "quathinge/btQuaternionHingeConstraint.h"

#include <cmath>

namespace quathinge
{
/// Which stop (if any) needs a row at angle α.
struct LimitState
{
	int sign = 0;              ///< +1 lower stop, −1 upper stop, 0 no row (btHingeConstraint::getLimitSign's values)
	bool locked = false;       ///< low == high: one bilateral row
	bool speculative = false;  ///< the stop is not reached yet (distance > 0)
	btScalar distance = 0;     ///< α − low (lower) or high − α (upper); negative when past the stop
};
/// reach: how far the angle can move toward a stop within this step (|α̇|·h); the speculative row switches on once a
/// stop is within the softness margin plus the reach, so a fast joint meets its stop instead of passing it. Inline:
/// asked at every step with a limit.
inline LimitState evaluateLimit(const btQuaternionHingeSettings& s, btScalar angle, btScalar reach)
{
	LimitState state;
	if (!s.hasLimit) return state;
	if (s.lowerLimit == s.upperLimit)
	{
		state.sign = 1;
		state.locked = true;
		state.distance = angle - s.lowerLimit;
		return state;
	}
	const btScalar halfRange = btScalar(0.5) * (s.upperLimit - s.lowerLimit);
	// speculative margin: the outer (1 − softness) of the half range; none for an unbounded side
	// (softness taken into [0, 1]: stock accepts any value and never uses it)
	const btScalar softness = btMax(btScalar(0), btMin(btScalar(1), s.limitSoftness));
	const btScalar margin = (std::isfinite(halfRange) ? (btScalar(1) - softness) * halfRange : btScalar(0)) + reach;
	const btScalar toLower = angle - s.lowerLimit;
	const btScalar toUpper = s.upperLimit - angle;
	if (toLower <= margin && toLower <= toUpper)
	{
		state.sign = 1;
		state.distance = toLower;
	}
	else if (toUpper <= margin)
	{
		state.sign = -1;
		state.distance = toUpper;
	}
	state.speculative = state.sign != 0 && state.distance > 0;
	return state;
}


/// One axial row's right-hand side and impulse bounds.
struct AxialRow
{
	btScalar error = 0;  ///< target α̇ (m_constraintError)
	btScalar lower = 0;  ///< impulse bounds
	btScalar upper = 0;
};

/// impactSpeed: the speed the joint met the stop with in the last step, when a speculative row stopped it there (that
/// row leaves it only the rest of its speed, which the bounce must not take for the speed of the hit); 0 otherwise.
AxialRow limitRow(const btQuaternionHingeSettings& s, const LimitState& limit, btScalar rate, btScalar fps,
				  btScalar stopErp, btScalar impactSpeed = 0);
/// Whether the drive currently needs a row (a drive with a zero impulse bound does nothing and gets no row). Inline:
/// asked twice per joint and step.
inline bool driveActive(const btQuaternionHingeSettings& s)
{
	switch (s.driveMode)
	{
		case BT_QHINGE_DRIVE_VELOCITY:
			return s.maxMotorImpulse > 0;
		case BT_QHINGE_DRIVE_SERVO:
			return s.servoMaxTorque > 0;
		case BT_QHINGE_DRIVE_SPRING:
			return true;
		case BT_QHINGE_DRIVE_OFF:
			break;
	}
	return false;
}
/// invEffectiveMass: J_α M⁻¹ J_αᵀ of the pair (for the spring).
AxialRow driveRow(const btQuaternionHingeSettings& s, btScalar angle, btScalar rate, btScalar fps,
				  btScalar invEffectiveMass);
AxialRow frictionRow(const btQuaternionHingeSettings& s, btScalar fps);

}  // namespace quathinge

#endif
