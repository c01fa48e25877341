// btQuaternionHingeConstraint's limit and drive settings (motor, servo, spring, friction) and its angles: the hinge
// angle (Q11) with stock's sign, the multi-turn angle it tracks, and the limit test getInfo1 runs (the rows
// themselves: AxisRows.h; their place among the joint's rows: HingeSolverRows.cpp).
#include "quathinge/btQuaternionHingeConstraint.h"

#include "AxisRows.h"
#include "HingeAngle.h"
#include "InputChecks.h"
#include "MatrixLanes.h"

#include <cmath>
#include <limits>
#include <sstream>

using namespace quathinge;

// ---- Motor, servo, spring, friction ----------------------------------------------------------------------------------

void btQuaternionHingeConstraint::enableAngularMotor(bool enable, btScalar targetVelocity, btScalar maxMotorImpulse)
{
	const char* fn = "btQuaternionHingeConstraint::enableAngularMotor";
	if (!check::finite(fn, "targetVelocity", targetVelocity) ||
		!check::finiteNonNegative(fn, "maxMotorImpulse", maxMotorImpulse))
		return;
	m_settings.motorTargetVelocity = targetVelocity;
	m_settings.maxMotorImpulse = maxMotorImpulse;
	enableMotor(enable);
}

void btQuaternionHingeConstraint::enableMotor(bool enable)
{
	if (enable) m_settings.driveMode = BT_QHINGE_DRIVE_VELOCITY;
	else if (m_settings.driveMode == BT_QHINGE_DRIVE_VELOCITY) m_settings.driveMode = BT_QHINGE_DRIVE_OFF;
}

void btQuaternionHingeConstraint::setMaxMotorImpulse(btScalar maxMotorImpulse)
{
	const char* fn = "btQuaternionHingeConstraint::setMaxMotorImpulse";
	if (!check::finiteNonNegative(fn, "maxMotorImpulse", maxMotorImpulse))
		return;
	m_settings.maxMotorImpulse = maxMotorImpulse;
}

void btQuaternionHingeConstraint::setMotorTargetVelocity(btScalar motorTargetVelocity)
{
	if (!check::finite("btQuaternionHingeConstraint::setMotorTargetVelocity", "motorTargetVelocity", motorTargetVelocity))
		return;
	m_settings.motorTargetVelocity = motorTargetVelocity;
}

void btQuaternionHingeConstraint::setMotorTarget(btScalar targetAngle, btScalar dt)
{
	const char* fn = "btQuaternionHingeConstraint::setMotorTarget";
	if (!check::angle(fn, "targetAngle", targetAngle) || !check::finite(fn, "dt", dt) || !check::positive(fn, "dt", dt))
		return;
	// As stock: clamp the target into a limit with a range (stock's btAngularLimit::fit acts only when high > low),
	// then the velocity that gets there in dt from the angle of the bodies' current pose. Stock compares with the
	// wrapped angle; here with the multi-turn angle when it is tracked (continued to the current pose), so targets
	// beyond ±π work.
	if (hasLimit()) targetAngle = btMax(m_settings.lowerLimit, btMin(m_settings.upperLimit, targetAngle));
	const btScalar raw = getHingeAngle();
	const btScalar current = m_multiTurnValid ? continueAngle(m_multiTurnAngle, raw) : raw;
	const btScalar velocity = (targetAngle - current) / dt;
	// a denormal dt (1e-38 s) turns any angle difference into an infinite velocity: refused, nothing changed
	if (!std::isfinite(velocity))
	{
		check::fail(fn, "dt", "is too small: (targetAngle - angle) / dt is not a finite velocity", dt);
		return;
	}
	m_settings.motorTargetVelocity = velocity;
}

void btQuaternionHingeConstraint::setMotorTarget(const btQuaternion& qAinB, btScalar dt)
{
	const char* fn = "btQuaternionHingeConstraint::setMotorTarget";
	for (int i = 0; i < 4; ++i)
		if (!check::finite(fn, "qAinB", qAinB[i])) return;
	if (qAinB.length2() == 0)
	{
		check::fail(fn, "qAinB must not be the zero quaternion");
		return;
	}
	// As stock: the rotation in constraint space, its hinge (twist) part about ẑ, and that angle as the target. The
	// twist of frameB⁻¹ qAinB frameA is the angle of A relative to B (−θ of the pose it describes), which is
	// getHingeAngle() without useReferenceFrameA; stock passes it on unchanged with useReferenceFrameA too (where
	// getHingeAngle() is θ), and so does this.
	btQuaternion qConstraint =
		m_settings.frameInB.getRotation().inverse() * qAinB.normalized() * m_settings.frameInA.getRotation();
	qConstraint.normalize();
	setMotorTarget(hingeAngle(qConstraint), dt);
}

void btQuaternionHingeConstraint::setServoTarget(btScalar targetAngle, btScalar maxSpeed, btScalar maxTorque)
{
	const char* fn = "btQuaternionHingeConstraint::setServoTarget";
	if (!check::angle(fn, "targetAngle", targetAngle) || !check::positive(fn, "maxSpeed", maxSpeed) ||
		!check::nonNegative(fn, "maxTorque", maxTorque))
		return;
	m_settings.servoTargetAngle = targetAngle;
	m_settings.servoMaxSpeed = maxSpeed;
	m_settings.servoMaxTorque = maxTorque;
	m_settings.driveMode = BT_QHINGE_DRIVE_SERVO;
}

void btQuaternionHingeConstraint::setSpring(btScalar restAngle, btScalar frequencyHz, btScalar dampingRatio)
{
	const char* fn = "btQuaternionHingeConstraint::setSpring";
	if (!check::angle(fn, "restAngle", restAngle) ||
		!check::inRange(fn, "frequencyHz", frequencyHz, 0, false, check::kMaxSpringFrequency, true) ||
		!check::finite(fn, "dampingRatio", dampingRatio) || !check::nonNegative(fn, "dampingRatio", dampingRatio))
		return;
	m_settings.springRestAngle = restAngle;
	m_settings.springFrequency = frequencyHz;
	m_settings.springDampingRatio = dampingRatio;
	m_settings.driveMode = BT_QHINGE_DRIVE_SPRING;
}

void btQuaternionHingeConstraint::disableDrive() { m_settings.driveMode = BT_QHINGE_DRIVE_OFF; }

void btQuaternionHingeConstraint::setMaxFrictionTorque(btScalar maxTorque)
{
	const char* fn = "btQuaternionHingeConstraint::setMaxFrictionTorque";
	if (!check::finite(fn, "maxTorque", maxTorque) || !check::nonNegative(fn, "maxTorque", maxTorque)) return;
	m_settings.maxFrictionTorque = maxTorque;
}

// ---- Limits and angles -------------------------------------------------------------------------------------------------

void btQuaternionHingeConstraint::setLimit(btScalar low, btScalar high, btScalar softness, btScalar biasFactor,
										   btScalar relaxationFactor)
{
	// Stock's meaning for everything stock accepts (btAngularLimit::set): low > high is a limit that never acts (a
	// free joint; stock's URDF importer and Godot pass such pairs for "no limit"), low == high locks the hinge, and
	// softness is any finite number, bias and relaxation any number of magnitude up to 1e3 (check::kMaxLimitFactor:
	// stock documents both as fractions). Refused: NaN or infinite softness, a factor beyond that, a NaN end, and the ends
	// that have no angle (low at +∞, high at −∞) or no float precision left (a finite low above 1e6 rad, or high below
	// −1e6 rad, with low ≤ high).
	const char* fn = "btQuaternionHingeConstraint::setLimit";
	if (std::isnan(low) && !check::fail(fn, "low", "must not be NaN", low)) return;
	if (std::isnan(high) && !check::fail(fn, "high", "must not be NaN", high)) return;
	if (!check::finite(fn, "softness", softness) || !check::limitFactor(fn, "biasFactor", biasFactor) ||
		!check::limitFactor(fn, "relaxationFactor", relaxationFactor))
		return;
	bool acts = low <= high;
	if (acts)
	{
		// A side at or beyond ±BT_LARGE_FLOAT (±SIMD_INFINITY, ±inf) or beyond ±1e6 rad (SDF's ±1e16: 160 000 turns,
		// which no stop can mean) has no stop: stored as ±inf.
		if (low >= BT_LARGE_FLOAT && !check::fail(fn, "low", "must be below +infinity", low)) return;
		if (high <= -BT_LARGE_FLOAT && !check::fail(fn, "high", "must be above -infinity", high)) return;
		if (low < -check::kMaxAngle) low = -std::numeric_limits<btScalar>::infinity();
		else if (!check::angle(fn, "low", low)) return;
		if (high > check::kMaxAngle) high = std::numeric_limits<btScalar>::infinity();
		else if (!check::angle(fn, "high", high)) return;
	}
	// A range of exactly one turn (high − low = 2π within kOneTurnTolerance: setLimit(−π, π), Godot's HingeJoint with
	// its limit off) never acts, as stock's never does (it wraps the angle into a turn): the common way to say "no
	// limit". Wider ranges act on the multi-turn angle (docs/MIGRATING.md, the difference table).
	const bool oneTurn = acts && std::isfinite(low) && std::isfinite(high) &&
						 btFabs((high - low) - SIMD_2_PI) <= check::kOneTurnTolerance;
	m_limitIsOneTurn = oneTurn;
	acts = acts && !oneTurn;
	m_settings.hasLimit = acts;
	m_settings.lowerLimit = low;
	m_settings.upperLimit = high;
	m_settings.limitSoftness = softness;
	m_settings.limitBiasFactor = biasFactor;
	m_settings.limitRelaxationFactor = relaxationFactor;
	if (acts) rebranchForLimit();
	else m_limitSign = 0;
}

void btQuaternionHingeConstraint::removeLimit()
{
	m_settings.hasLimit = false;
	m_limitIsOneTurn = false;
	m_limitSign = 0;
}

void btQuaternionHingeConstraint::rebranchForLimit()
{
	const btScalar raw = getHingeAngle();
	const btScalar current = m_multiTurnValid ? continueAngle(m_multiTurnAngle, raw) : raw;
	if (!m_multiTurnValid || current < m_settings.lowerLimit || current > m_settings.upperLimit)
		m_multiTurnAngle = nearestBranch(current, m_settings.lowerLimit, m_settings.upperLimit);
	else
		m_multiTurnAngle = current;
	m_multiTurnValid = true;
}

btScalar btQuaternionHingeConstraint::getHingeAngle() const
{
	return getHingeAngle(m_rbA.getCenterOfMassTransform(), m_rbB.getCenterOfMassTransform());
}

btScalar btQuaternionHingeConstraint::getHingeAngle(const btTransform& transA, const btTransform& transB) const
{
	// (Q11) with stock's sign
	Pose pose;
	poseAt(transA, transB, pose);
	return userSign(m_settings.useReferenceFrameA) * hingeAngle(pose.q);
}

btScalar btQuaternionHingeConstraint::computeAngleRow(const btTransform& transA, const btTransform& transB,
													  btScalar previousAngle, btVector3& gradient) const
{
	Pose pose;
	poseAt(transA, transB, pose);
	return angleRowAt(pose, previousAngle, gradient);
}

btScalar btQuaternionHingeConstraint::angleRowAt(const Pose& pose, btScalar previousAngle, btVector3& gradient) const
{
	return frameAngleRowAt(pose, userSign(m_settings.useReferenceFrameA), previousAngle, gradient);
}

btScalar btQuaternionHingeConstraint::frameAngleRowAt(const Pose& pose, btScalar sigma, btScalar previousAngle,
													  btVector3& gradient)
{
	// (Q11) α = σθ continued from the previous angle; α̇ = σ Ω·t with Ω = R_Aᵀ(ω_B − ω_A), so the world axis is σ R_A t
	storeLanes(gradient, timesTransposed(pose.axesA, hingeAngleGradient(pose.q)));
	gradient *= sigma;
	return continueAngle(previousAngle, sigma * hingeAngle(pose.q));
}

void btQuaternionHingeConstraint::updateMultiTurnAngle(btScalar rawUserAngle)
{
	if (m_multiTurnValid)
		m_multiTurnAngle = continueAngle(m_multiTurnAngle, rawUserAngle);  // (Q11)
	else if (m_settings.hasLimit)
		m_multiTurnAngle = nearestBranch(rawUserAngle, m_settings.lowerLimit, m_settings.upperLimit);
	else
		m_multiTurnAngle = rawUserAngle;
	m_multiTurnValid = true;
}

btScalar btQuaternionHingeConstraint::getMultiTurnAngle()
{
	m_trackAlways = true;
	updateMultiTurnAngle(getHingeAngle());
	return m_multiTurnAngle;
}

void btQuaternionHingeConstraint::setMultiTurnAngle(btScalar angle)
{
	const char* fn = "btQuaternionHingeConstraint::setMultiTurnAngle";
	if (!check::angle(fn, "angle", angle)) return;
	const btScalar raw = getHingeAngle();
	// 1e-3 rad: generous against float round-off of the pose, far below any distinct angle a user means
	if (btFabs(wrapAngle(angle - raw)) > btScalar(1e-3))
	{
		std::ostringstream message;
		message << "angle (" << angle << ") is not the current hinge angle (" << raw << ") plus whole turns";
		check::fail(fn, message.str().c_str());
		return;
	}
	m_multiTurnAngle = raw + (angle - raw - wrapAngle(angle - raw));
	m_multiTurnValid = true;
	m_trackAlways = true;
}

void btQuaternionHingeConstraint::testLimit(const btTransform& transA, const btTransform& transB)
{
	m_limitSign = 0;
	if (!m_settings.hasLimit) return;
	poseAt(transA, transB, m_pose);
	m_poseCached = true;
	const btScalar sigma = userSign(m_settings.useReferenceFrameA);
	updateMultiTurnAngle(sigma * hingeAngle(m_pose.q));
	// reach this step: the current relative speed about the axis times the last step (unknown before the first)
	storeLanes(m_pose.axial, timesTransposed(m_pose.axesA, axialRowDirection(m_pose.q)));
	m_pose.axialKnown = true;  // the limit row's getInfo2 takes it from here
	const btScalar reach =
		btFabs(m_pose.axial.dot(m_rbB.getAngularVelocity() - m_rbA.getAngularVelocity())) * m_lastTimeStep;
	const LimitState limit = evaluateLimit(m_settings, m_multiTurnAngle, reach);
	m_limitSign = limit.sign;  // kept whole for the limit row (evaluated once per step)
	m_limitLocked = limit.locked;
	m_limitSpeculative = limit.speculative;
	m_limitDistance = limit.distance;
}
