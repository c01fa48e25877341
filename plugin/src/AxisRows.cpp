// Limit, drive and friction rows along the hinge axis. The equations: AxisRows.h.
#include "AxisRows.h"

#include <cmath>

namespace quathinge
{
AxialRow limitRow(const btQuaternionHingeSettings& s, const LimitState& limit, btScalar rate, btScalar fps,
				  btScalar stopErp, btScalar impactSpeed)
{
	AxialRow row;
	if (limit.locked)
	{
		row.error = -s.limitBiasFactor * stopErp * fps * limit.distance;
		row.lower = -SIMD_INFINITY;
		row.upper = SIMD_INFINITY;
		return row;
	}
	const btScalar sign = btScalar(limit.sign);  // +1: α̇ ≥ target, −1: α̇ ≤ target
	if (limit.speculative)
	{
		// reach the stop within this step, not beyond: approach rate at most distance·fps
		row.error = -sign * limit.distance * fps;
		// caught at the stop by the last step's row, and left a rounding's distance short of it (double lands there):
		// the bounce of that hit all the same
		const btScalar bounce = s.limitBiasFactor * sign * s.limitRelaxationFactor * impactSpeed;
		if (impactSpeed > 0 && sign * bounce > sign * row.error) row.error = bounce;
	}
	else
	{
		// at or past the stop: btHingeConstraint's correction and bounce, scaled by the bias factor
		btScalar target = sign * stopErp * fps * (-limit.distance);
		// the speed of the hit: moving into the stop now, or caught at it by the last step's speculative row
		const btScalar incoming = btMax(-sign * rate, impactSpeed);
		if (incoming > 0)
		{
			const btScalar bounce = sign * s.limitRelaxationFactor * incoming;
			if (sign * bounce > sign * target) target = bounce;
		}
		row.error = s.limitBiasFactor * target;
	}
	row.lower = sign > 0 ? btScalar(0) : -SIMD_INFINITY;
	row.upper = sign > 0 ? SIMD_INFINITY : btScalar(0);
	return row;
}

AxialRow driveRow(const btQuaternionHingeSettings& s, btScalar angle, btScalar rate, btScalar fps,
				  btScalar invEffectiveMass)
{
	AxialRow row;
	switch (s.driveMode)
	{
		case BT_QHINGE_DRIVE_VELOCITY:
			row.error = s.motorTargetVelocity;
			row.lower = -s.maxMotorImpulse;
			row.upper = s.maxMotorImpulse;
			break;
		case BT_QHINGE_DRIVE_SERVO:
		{
			const btScalar wanted = (s.servoTargetAngle - angle) * fps;  // reach the target in one step
			row.error = btMax(-s.servoMaxSpeed, btMin(s.servoMaxSpeed, wanted));
			const btScalar maxImpulse = std::isfinite(s.servoMaxTorque) ? s.servoMaxTorque / fps : SIMD_INFINITY;
			row.lower = -maxImpulse;
			row.upper = maxImpulse;
			break;
		}
		case BT_QHINGE_DRIVE_SPRING:
		{
			const btScalar h = btScalar(1) / fps;
			const btScalar omega = SIMD_2_PI * s.springFrequency;
			const btScalar rate1 = (rate - h * omega * omega * (angle - s.springRestAngle)) /
								   (btScalar(1) + btScalar(2) * s.springDampingRatio * omega * h + h * h * omega * omega);
			const btScalar impulse = invEffectiveMass > 0 ? (rate1 - rate) / invEffectiveMass : btScalar(0);
			row.error = rate1;
			row.lower = impulse;
			row.upper = impulse;
			break;
		}
		case BT_QHINGE_DRIVE_OFF:
			break;
	}
	return row;
}

AxialRow frictionRow(const btQuaternionHingeSettings& s, btScalar fps)
{
	AxialRow row;
	row.error = 0;
	row.upper = s.maxFrictionTorque / fps;
	row.lower = -row.upper;
	return row;
}

}  // namespace quathinge
