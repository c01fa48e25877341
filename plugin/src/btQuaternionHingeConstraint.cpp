// btQuaternionHingeConstraint: composes the point part (3 linear rows), the quaternion two-row part
// (QuaternionHingeRows.h, MATH.md Q2–Q10, Q12) and the axis part (AxisRows.h: limit, drive, friction), and tracks the
// multi-turn angle (HingeAngle.h, Q11). getInfo1 decides which rows exist; getInfo2 fills them in that order:
//   [0..2] point-to-point (unless angular-only)   [next 2] quaternion rows   [drive] [friction] [limit]
#include "quathinge/btQuaternionHingeConstraint.h"
#include "quathinge/btQuaternionHingeSerialization.h"

#include "AxisRows.h"
#include "HingeAngle.h"
#include "InputChecks.h"
#include "MatrixLanes.h"
#include "QuaternionHingeRows.h"
#include "SolverRowBasis.h"

#include "BulletDynamics/Dynamics/btRigidBody.h"

#include <cmath>
#include <limits>
#include <sstream>

using namespace quathinge;

namespace
{
// Row kinds for per-row ERP/CFM (setParam's axis).
const int kLinearKind = 0;   // 0..2
const int kAngularKind = 3;  // 3..4
const int kAxialKind = 5;

btMatrix3x3 basisFromColumns(const btVector3& x, const btVector3& y, const btVector3& z)
{
	return btMatrix3x3(x.x(), y.x(), z.x(), x.y(), y.y(), z.y(), x.z(), y.z(), z.z());
}

// Largest body coordinate or speed the joint accepts (m, m/s, rad/s): beyond it differences and products of the rows
// leave float range (the fuzzer found bodies at ±2e38 m whose pivot difference was infinite).
const btScalar kMaxBodyState = btScalar(1e15);

bool finiteBodyState(const btRigidBody& body)
{
	// NaN survives a sum of absolute values, and ±∞ or anything near float's end makes it exceed the bound, so one
	// comparison covers the transform and both velocities (summed three lanes at a time, MatrixLanes.h).
	const btTransform& t = body.getCenterOfMassTransform();
	const Lanes sum = absXyz(t.getOrigin()) + absXyz(t.getBasis()[0]) + absXyz(t.getBasis()[1]) +
					  absXyz(t.getBasis()[2]) + absXyz(body.getLinearVelocity()) + absXyz(body.getAngularVelocity());
	// an inverse mass or inertia that is not finite (a body of 1e-38 kg) makes every row's effective mass 0·∞
	const btScalar inverse = body.getInvMass() + body.getInvInertiaDiagLocal().x() + body.getInvInertiaDiagLocal().y() +
							 body.getInvInertiaDiagLocal().z();
	return sum[0] + sum[1] + sum[2] < kMaxBodyState && inverse < kMaxBodyState;  // false for NaN as well
}

// Frame B's x for the pivot/axis constructors: frame A's x carried along the shortest arc from axisA to axisB (as
// btHingeConstraint does), then made exactly orthogonal to axisB. Near-antiparallel axes make shortestArcQuat lose
// precision (its quaternion is then far from unit and the column neither unit nor orthogonal): the projection repairs
// that, and if nothing is left, any direction across axisB will do.
btVector3 arcTurnedColumn(const btVector3& axisA, const btVector3& axisA1, const btVector3& axisB)
{
	btVector3 column = quatRotate(shortestArcQuat(axisA, axisB).normalized(), axisA1);
	column -= axisB * axisB.dot(column);
	if (column.length2() > SIMD_EPSILON) return column.normalized();
	btVector3 u, v;
	btPlaneSpace1(axisB, u, v);
	return u;
}

bool isStaticLike(const btRigidBody& body)
{
	return body.getInvMass() == 0 && body.getInvInertiaDiagLocal().isZero();
}

bool checkBodies(const char* fn, const btRigidBody& rbA, const btRigidBody& rbB)
{
	return &rbA != &rbB || check::fail(fn, "rbB is the same body as rbA (a joint needs two bodies)");
}

// The user angle α = σθ: σ = +1 with useReferenceFrameA, −1 without (btHingeConstraint::getHingeAngle's sign).
btScalar userSign(bool useReferenceFrameA) { return useReferenceFrameA ? btScalar(1) : btScalar(-1); }

}  // namespace

// ---- Construction ---------------------------------------------------------------------------------------------------

btQuaternionHingeConstraint::btQuaternionHingeConstraint(btRigidBody& rbA, btRigidBody& rbB, const btVector3& pivotInA,
														 const btVector3& pivotInB, const btVector3& axisInA,
														 const btVector3& axisInB, bool useReferenceFrameA)
	: btTypedConstraint(QUATERNION_HINGE_CONSTRAINT_TYPE, rbA, rbB)
{
	const char* fn = "btQuaternionHingeConstraint(rbA, rbB, pivotInA, pivotInB, axisInA, axisInB)";
	btVector3 axisA, axisB;
	if (!checkBodies(fn, rbA, rbB) || !check::pivot(fn, "pivotInA", pivotInA) ||
		!check::pivot(fn, "pivotInB", pivotInB) || !check::direction(fn, "axisInA", axisInA, axisA) ||
		!check::direction(fn, "axisInB", axisInB, axisB))
	{
		refuseConstruction();
		return;
	}

	// Frames chosen exactly as btHingeConstraint chooses them, so that the zero angle is the same.
	btVector3 axisA1 = rbA.getCenterOfMassTransform().getBasis().getColumn(0);
	btVector3 axisA2;
	const btScalar projection = axisA.dot(axisA1);
	if (projection >= 1 - SIMD_EPSILON)
	{
		axisA1 = -rbA.getCenterOfMassTransform().getBasis().getColumn(2);
		axisA2 = rbA.getCenterOfMassTransform().getBasis().getColumn(1);
	}
	else if (projection <= -1 + SIMD_EPSILON)
	{
		axisA1 = rbA.getCenterOfMassTransform().getBasis().getColumn(2);
		axisA2 = rbA.getCenterOfMassTransform().getBasis().getColumn(1);
	}
	else
	{
		axisA2 = axisA.cross(axisA1).normalized();
		axisA1 = axisA2.cross(axisA);
	}
	const btVector3 axisB1 = arcTurnedColumn(axisA, axisA1, axisB);
	const btVector3 axisB2 = axisB.cross(axisB1);

	m_settings.frameInA = btTransform(basisFromColumns(axisA1, axisA2, axisA), pivotInA);
	m_settings.frameInB = btTransform(basisFromColumns(axisB1, axisB2, axisB), pivotInB);
	m_settings.useReferenceFrameA = useReferenceFrameA;
	initFromSettings();
}

btQuaternionHingeConstraint::btQuaternionHingeConstraint(btRigidBody& rbA, const btVector3& pivotInA,
														 const btVector3& axisInA, bool useReferenceFrameA)
	: btTypedConstraint(QUATERNION_HINGE_CONSTRAINT_TYPE, rbA)
{
	const char* fn = "btQuaternionHingeConstraint(rbA, pivotInA, axisInA)";
	btVector3 axisA;
	if (!check::pivot(fn, "pivotInA", pivotInA) || !check::direction(fn, "axisInA", axisInA, axisA))
	{
		refuseConstruction();
		return;
	}

	// As btHingeConstraint: body B is the world; its frame is A's frame as it is now, in world coordinates.
	btVector3 axisA1, axisA2;
	btPlaneSpace1(axisA, axisA1, axisA2);
	const btVector3 axisB = rbA.getCenterOfMassTransform().getBasis() * axisA;
	const btVector3 axisB1 = arcTurnedColumn(axisA, axisA1, axisB);
	const btVector3 axisB2 = axisB.cross(axisB1);

	const btTransform frameB(basisFromColumns(axisB1, axisB2, axisB), rbA.getCenterOfMassTransform()(pivotInA));
	if (!check::rigidFrame(fn, "world frame derived for B from rbA's pose", frameB))
	{
		refuseConstruction();
		return;
	}
	m_settings.frameInA = btTransform(basisFromColumns(axisA1, axisA2, axisA), pivotInA);
	m_settings.frameInB = frameB;
	m_settings.useReferenceFrameA = useReferenceFrameA;
	initFromSettings();
}

btQuaternionHingeConstraint::btQuaternionHingeConstraint(btRigidBody& rbA, btRigidBody& rbB,
														 const btTransform& rbAFrame, const btTransform& rbBFrame,
														 bool useReferenceFrameA)
	: btTypedConstraint(QUATERNION_HINGE_CONSTRAINT_TYPE, rbA, rbB)
{
	const char* fn = "btQuaternionHingeConstraint(rbA, rbB, rbAFrame, rbBFrame)";
	if (!checkBodies(fn, rbA, rbB) || !check::rigidFrame(fn, "rbAFrame", rbAFrame) ||
		!check::rigidFrame(fn, "rbBFrame", rbBFrame))
	{
		refuseConstruction();
		return;
	}
	m_settings.frameInA = rbAFrame;
	m_settings.frameInB = rbBFrame;
	m_settings.useReferenceFrameA = useReferenceFrameA;
	initFromSettings();
}

btQuaternionHingeConstraint::btQuaternionHingeConstraint(btRigidBody& rbA, const btTransform& rbAFrame,
														 bool useReferenceFrameA)
	: btTypedConstraint(QUATERNION_HINGE_CONSTRAINT_TYPE, rbA)
{
	const char* fn = "btQuaternionHingeConstraint(rbA, rbAFrame)";
	// As btHingeConstraint: B's frame has A's basis and A's pivot in world coordinates.
	const btTransform frameB(rbAFrame.getBasis(), rbA.getCenterOfMassTransform()(rbAFrame.getOrigin()));
	if (!check::rigidFrame(fn, "rbAFrame", rbAFrame) ||
		!check::rigidFrame(fn, "world frame derived for B from rbA's pose", frameB))
	{
		refuseConstruction();
		return;
	}
	m_settings.frameInA = rbAFrame;
	m_settings.frameInB = frameB;
	m_settings.useReferenceFrameA = useReferenceFrameA;
	initFromSettings();
}

btQuaternionHingeConstraint::btQuaternionHingeConstraint(btRigidBody& rbA, btRigidBody& rbB,
														 const btQuaternionHingeSettings& settings)
	: btTypedConstraint(QUATERNION_HINGE_CONSTRAINT_TYPE, rbA, rbB)
{
	const char* fn = "btQuaternionHingeConstraint(rbA, rbB, settings)";
	if (!checkBodies(fn, rbA, rbB) || !check::rigidFrame(fn, "settings.frameInA", settings.frameInA) ||
		!check::rigidFrame(fn, "settings.frameInB", settings.frameInB))
	{
		refuseConstruction();
		return;
	}
	m_settings.frameInA = settings.frameInA;
	m_settings.frameInB = settings.frameInB;
	m_settings.useReferenceFrameA = settings.useReferenceFrameA;
	m_settings.angularOnly = settings.angularOnly;
	m_settings.useFrameOffset = settings.useFrameOffset;
	initFromSettings();
	// Everything else through the checked setters, so a corrupt settings struct is refused like any other input
	// (without exceptions: any refusal among them refuses the whole construction).
	const unsigned refusalsBefore = check::refusals();
	for (int kind = 0; kind < 6; ++kind)
	{
		if (settings.flags & (BT_QHINGE_FLAGS_ERP_ROW0 << kind)) setParam(BT_CONSTRAINT_ERP, settings.rowErp[kind], kind);
		if (settings.flags & (BT_QHINGE_FLAGS_CFM_ROW0 << kind)) setParam(BT_CONSTRAINT_CFM, settings.rowCfm[kind], kind);
	}
	if (settings.flags & BT_QHINGE_FLAGS_ERP_STOP) setParam(BT_CONSTRAINT_STOP_ERP, settings.stopErp);
	if (settings.flags & BT_QHINGE_FLAGS_CFM_STOP) setParam(BT_CONSTRAINT_STOP_CFM, settings.stopCfm);
	// A limit that does not act (settings.hasLimit false) keeps its values, as stock keeps a freed limit's.
	setLimit(settings.lowerLimit, settings.upperLimit, settings.limitSoftness, settings.limitBiasFactor,
			 settings.limitRelaxationFactor);
	if (!settings.hasLimit) removeLimit();
	switch (settings.driveMode)
	{
		case BT_QHINGE_DRIVE_VELOCITY:
			enableAngularMotor(true, settings.motorTargetVelocity, settings.maxMotorImpulse);
			break;
		case BT_QHINGE_DRIVE_SERVO:
			setServoTarget(settings.servoTargetAngle, settings.servoMaxSpeed, settings.servoMaxTorque);
			break;
		case BT_QHINGE_DRIVE_SPRING:
			setSpring(settings.springRestAngle, settings.springFrequency, settings.springDampingRatio);
			break;
		case BT_QHINGE_DRIVE_OFF:
			// keep the motor's values (stock keeps them while the motor is off)
			setMotorTargetVelocity(settings.motorTargetVelocity);
			setMaxMotorImpulse(settings.maxMotorImpulse);
			break;
		default:
			check::fail(fn, "settings.driveMode", "is not a btQuaternionHingeDriveMode", btScalar(settings.driveMode));
	}
	setMaxFrictionTorque(settings.maxFrictionTorque);
	if (check::refusals() != refusalsBefore) refuseConstruction();
}

// Serialization lives in HingeSerialization.cpp, which uses only the public API; these overrides forward to it.
int btQuaternionHingeConstraint::calculateSerializeBufferSize() const { return btQuaternionHingeSerializeBufferSize(); }

const char* btQuaternionHingeConstraint::serialize(void* dataBuffer, btSerializer* serializer) const
{
	return btQuaternionHingeSerialize(*this, dataBuffer, serializer);
}

btQuaternionHingeConstraint* btQuaternionHingeConstraint::upcast(btTypedConstraint* constraint)
{
	// The number rules out every Bullet constraint at the cost of a load; dynamic_cast settles a number shared with
	// another plugin by the object's own type (which no other class can claim).
	if (!constraint || constraint->getConstraintType() != QUATERNION_HINGE_CONSTRAINT_TYPE) return nullptr;
	return dynamic_cast<btQuaternionHingeConstraint*>(constraint);
}

const btQuaternionHingeConstraint* btQuaternionHingeConstraint::upcast(const btTypedConstraint* constraint)
{
	if (!constraint || constraint->getConstraintType() != QUATERNION_HINGE_CONSTRAINT_TYPE) return nullptr;
	return dynamic_cast<const btQuaternionHingeConstraint*>(constraint);
}

void btQuaternionHingeConstraint::refuseConstruction()
{
	// Only reached without exceptions (with them the check threw): a safe joint that never gives the solver a row.
	m_settings = btQuaternionHingeSettings();
	initFromSettings();
	m_fault = BT_QHINGE_FAULT_INVALID_ARGUMENT;
	setEnabled(false);
}

namespace
{
// q from the rotation matrix m = R_Aᵀ R_B (Q2), as btMatrix3x3::getRotation computes it (the same operations in the same
// order, so the same bits), with the two branches a hinge takes written out: q0 from the trace while it is positive
// (|θ| < 120°), else q_z from the z diagonal, which is the largest one near the hinge (the axes within 90°) for any
// angle. getRotation picks its branch from indices it computes and addresses a temporary through them, which costs
// several times the arithmetic; anything else (axes far apart) still goes through it.
inline void rotationToQuaternion(const btMatrix3x3& m, btQuaternion& q)
{
	const btScalar m00 = m[0].x(), m11 = m[1].y(), m22 = m[2].z();
	const btScalar trace = m00 + m11 + m22;
	if (trace > btScalar(0))
	{
		btScalar s = btSqrt(trace + btScalar(1));
		const btScalar w = s * btScalar(0.5);
		s = btScalar(0.5) / s;
		q.setValue((m[2].y() - m[1].z()) * s, (m[0].z() - m[2].x()) * s, (m[1].x() - m[0].y()) * s, w);
	}
	else if (m00 < m11 ? m11 < m22 : m00 < m22)  // getRotation's i = 2 (then j = 0, k = 1)
	{
		btScalar s = btSqrt(m22 - m00 - m11 + btScalar(1));
		const btScalar z = s * btScalar(0.5);
		s = btScalar(0.5) / s;
		q.setValue((m[0].z() + m[2].x()) * s, (m[1].z() + m[2].y()) * s, z, (m[1].x() - m[0].y()) * s);
	}
	else
		m.getRotation(q);
}
}  // namespace

void btQuaternionHingeConstraint::poseAt(const btTransform& transA, const btTransform& transB, Pose& pose) const
{
	// One matrix-to-quaternion conversion: q from R_Aᵀ R_B of the joint frames (the products with btTransform's bits,
	// MatrixLanes.h). Body A's basis by columns serves both R_Aᵀ and the pivot, body B's the pivot.
	const Lanes a0 = columnLanes(transA.getBasis(), 0), a1 = columnLanes(transA.getBasis(), 1),
				a2 = columnLanes(transA.getBasis(), 2);
	productTransposedRows(a0, a1, a2, m_settings.frameInA.getBasis(), pose.axesA);
	storeLanes(pose.pivotA, transformedLanes(a0, a1, a2, transA.getOrigin(), m_settings.frameInA.getOrigin()));
	storeLanes(pose.pivotB, transformedLanes(columnLanes(transB.getBasis(), 0), columnLanes(transB.getBasis(), 1),
											 columnLanes(transB.getBasis(), 2), transB.getOrigin(),
											 m_settings.frameInB.getOrigin()));
	btMatrix3x3 basisB, relative;
	multiplyRows(transB.getBasis(), m_settings.frameInB.getBasis(), basisB);
	multiplyRows(pose.axesA, basisB, relative);  // R_Aᵀ R_B
	rotationToQuaternion(relative, pose.q);
	pose.axialKnown = false;
}

void btQuaternionHingeConstraint::initFromSettings()
{
	m_poseCached = false;
	m_checkedFrameA = m_settings.frameInA;
	m_checkedFrameB = m_settings.frameInB;
	m_multiTurnAngle = 0;
	m_multiTurnValid = false;
	m_trackAlways = false;
	m_framesMayHaveChanged = false;
	m_limitSign = 0;
	m_limitLocked = false;
	m_limitSpeculative = false;
	m_limitDistance = 0;
	m_lastTimeStep = 0;
	m_numRows = 0;
	m_fault = BT_QHINGE_FAULT_NONE;
}

// ---- Frames -----------------------------------------------------------------------------------------------------------

btTransform& btQuaternionHingeConstraint::getFrameOffsetA()
{
	m_framesMayHaveChanged = true;
	return m_settings.frameInA;
}

btTransform& btQuaternionHingeConstraint::getFrameOffsetB()
{
	m_framesMayHaveChanged = true;
	return m_settings.frameInB;
}

void btQuaternionHingeConstraint::validateFramesIfEdited()
{
	if (!m_framesMayHaveChanged) return;
	// A non-const reference was handed out; most callers only read through it (e.g. a non-const joint pointer).
	if (m_settings.frameInA == m_checkedFrameA && m_settings.frameInB == m_checkedFrameB)
	{
		m_framesMayHaveChanged = false;
		return;
	}
	if (!check::isRigidFrame(m_settings.frameInA) || !check::isRigidFrame(m_settings.frameInB))
	{
		// refused: checked again at every getInfo1 (and by clearFault) until the frames are repaired
		m_fault = BT_QHINGE_FAULT_FRAME_EDITED_INVALID;
		setEnabled(false);
		return;
	}
	m_framesMayHaveChanged = false;
	m_checkedFrameA = m_settings.frameInA;
	m_checkedFrameB = m_settings.frameInB;
	m_multiTurnValid = false;  // the zero angle may have moved
}

void btQuaternionHingeConstraint::setFrames(const btTransform& frameA, const btTransform& frameB)
{
	const char* fn = "btQuaternionHingeConstraint::setFrames";
	if (!check::rigidFrame(fn, "frameA", frameA) || !check::rigidFrame(fn, "frameB", frameB)) return;
	m_settings.frameInA = frameA;
	m_settings.frameInB = frameB;
	m_checkedFrameA = frameA;
	m_checkedFrameB = frameB;
	m_multiTurnValid = false;
}

void btQuaternionHingeConstraint::setAxis(btVector3& axisInA)
{
	btVector3 axisA;
	if (!check::direction("btQuaternionHingeConstraint::setAxis", "axisInA", axisInA, axisA)) return;
	// As btHingeConstraint::setAxis: A's frame gets the new axis; B's frame is derived from the current pose.
	btVector3 axisA1, axisA2;
	btPlaneSpace1(axisA, axisA1, axisA2);
	const btVector3 pivotInA = m_settings.frameInA.getOrigin();
	const btTransform& transA = m_rbA.getCenterOfMassTransform();
	const btTransform& transB = m_rbB.getCenterOfMassTransform();
	const btMatrix3x3 basisA = basisFromColumns(axisA1, axisA2, axisA);
	// B's frame: A's joint frame as it is now in world coordinates, expressed in B — checked like a given frame (two
	// bodies 1e9 m apart would put B's pivot 1e9 m from it), before anything changes.
	const btTransform frameB(transB.getBasis().transposeTimes(transA.getBasis() * basisA), transB.inverse()(transA(pivotInA)));
	if (!check::rigidFrame("btQuaternionHingeConstraint::setAxis", "frame derived for B from the bodies' poses", frameB))
		return;
	m_settings.frameInA.setBasis(basisA);
	m_settings.frameInB = frameB;
	m_checkedFrameA = m_settings.frameInA;
	m_checkedFrameB = m_settings.frameInB;
	m_multiTurnValid = false;
}

void btQuaternionHingeConstraint::setUseReferenceFrameA(bool useReferenceFrameA)
{
	if (useReferenceFrameA != m_settings.useReferenceFrameA) m_multiTurnAngle = -m_multiTurnAngle;
	m_settings.useReferenceFrameA = useReferenceFrameA;
}

// ---- Motor, servo, spring, friction ----------------------------------------------------------------------------------

void btQuaternionHingeConstraint::enableAngularMotor(bool enable, btScalar targetVelocity, btScalar maxMotorImpulse)
{
	const char* fn = "btQuaternionHingeConstraint::enableAngularMotor";
	if (!check::finite(fn, "targetVelocity", targetVelocity) || !check::finite(fn, "maxMotorImpulse", maxMotorImpulse) ||
		!check::nonNegative(fn, "maxMotorImpulse", maxMotorImpulse))
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
	if (!check::finite(fn, "maxMotorImpulse", maxMotorImpulse) || !check::nonNegative(fn, "maxMotorImpulse", maxMotorImpulse))
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
	const bool acts = low <= high;
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

bool btQuaternionHingeConstraint::needsAngle() const
{
	return m_settings.hasLimit || m_trackAlways || m_settings.driveMode == BT_QHINGE_DRIVE_SERVO ||
		   m_settings.driveMode == BT_QHINGE_DRIVE_SPRING;
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

// ---- ERP / CFM ----------------------------------------------------------------------------------------------------------

void btQuaternionHingeConstraint::setParam(int num, btScalar value, int axis)
{
	// Stock's meaning for axis −1 and 5 (btHingeConstraint::setParam treats both as "the joint"): its normal ERP acts
	// on every row, its normal CFM on the motor row only, STOP_* on the limit row. Axes 0..4 (which stock ignores)
	// reach the linear and quaternion rows one kind at a time.
	const char* fn = "btQuaternionHingeConstraint::setParam";
	if (axis < -1 || axis > 5)
	{
		check::fail(fn, "axis", "must be -1 (the joint) or 0..5", btScalar(axis));
		return;
	}
	const char* name = num == BT_CONSTRAINT_ERP		 ? "value (ERP)"
					   : num == BT_CONSTRAINT_CFM	 ? "value (CFM)"
					   : num == BT_CONSTRAINT_STOP_ERP ? "value (STOP_ERP)"
												   : "value (STOP_CFM)";
	if (num != BT_CONSTRAINT_ERP && num != BT_CONSTRAINT_CFM && num != BT_CONSTRAINT_STOP_ERP &&
		num != BT_CONSTRAINT_STOP_CFM)
	{
		check::fail(fn, "num", "must be BT_CONSTRAINT_ERP, _STOP_ERP, _CFM or _STOP_CFM", btScalar(num));
		return;
	}
	// Finite, ERP in [0, 2) and CFM in [0, 1): stock takes any value, but a negative one asks for error growth or a
	// negative compliance, an ERP of 2 or more overshoots by more than it corrects, and a CFM of 1 or more makes
	// Bullet's Gauss–Seidel update diverge on an unbounded row (stock's CFM reaches only its bounded motor row; here
	// a servo row may be unbounded): no value there has a meaning a solve can reach.
	const bool erpLike = num == BT_CONSTRAINT_ERP || num == BT_CONSTRAINT_STOP_ERP;
	if (!check::inRange(fn, name, value, 0, true, erpLike ? btScalar(2) : btScalar(1), false)) return;
	const bool joint = axis == -1 || axis == kAxialKind;
	switch (num)
	{
		case BT_CONSTRAINT_ERP:
		{
			const int first = joint ? 0 : axis, last = joint ? 5 : axis;
			for (int kind = first; kind <= last; ++kind)
			{
				m_settings.rowErp[kind] = value;
				m_settings.flags |= BT_QHINGE_FLAGS_ERP_ROW0 << kind;
			}
			m_settings.flags |= BT_QHINGE_FLAGS_ERP_NORM;
			break;
		}
		case BT_CONSTRAINT_CFM:
		{
			const int kind = joint ? kAxialKind : axis;
			m_settings.rowCfm[kind] = value;
			m_settings.flags |= (BT_QHINGE_FLAGS_CFM_ROW0 << kind) | BT_QHINGE_FLAGS_CFM_NORM;
			break;
		}
		case BT_CONSTRAINT_STOP_ERP:
		case BT_CONSTRAINT_STOP_CFM:
			if (!joint)
			{
				check::fail(fn, "axis", "must be -1 or 5 for STOP_ERP/STOP_CFM (the limit row)", btScalar(axis));
				return;
			}
			if (num == BT_CONSTRAINT_STOP_ERP)
			{
				m_settings.stopErp = value;
				m_settings.flags |= BT_QHINGE_FLAGS_ERP_STOP;
			}
			else
			{
				m_settings.stopCfm = value;
				m_settings.flags |= BT_QHINGE_FLAGS_CFM_STOP;
			}
			break;
		default:
			break;  // refused above
	}
}

btScalar btQuaternionHingeConstraint::getParam(int num, int axis) const
{
	// As stock: the value set, else 0 (stock's members start at 0); an unknown num or axis gives 0 (stock asserts in
	// a debug build and returns 0). Never throws: a const getter.
	if (axis < -1 || axis > 5) return 0;
	const int kind = axis < 0 ? kAxialKind : axis;
	switch (num)
	{
		case BT_CONSTRAINT_ERP:
			return (m_settings.flags & (BT_QHINGE_FLAGS_ERP_ROW0 << kind)) ? m_settings.rowErp[kind] : btScalar(0);
		case BT_CONSTRAINT_CFM:
			return (m_settings.flags & (BT_QHINGE_FLAGS_CFM_ROW0 << kind)) ? m_settings.rowCfm[kind] : btScalar(0);
		case BT_CONSTRAINT_STOP_ERP:
			if (kind != kAxialKind) return 0;
			return (m_settings.flags & BT_QHINGE_FLAGS_ERP_STOP) ? m_settings.stopErp : btScalar(0);
		case BT_CONSTRAINT_STOP_CFM:
			if (kind != kAxialKind) return 0;
			return (m_settings.flags & BT_QHINGE_FLAGS_CFM_STOP) ? m_settings.stopCfm : btScalar(0);
		default:
			return 0;
	}
}

btScalar btQuaternionHingeConstraint::rowErp(int kind, btScalar globalErp) const
{
	return (m_settings.flags & (BT_QHINGE_FLAGS_ERP_ROW0 << kind)) ? m_settings.rowErp[kind] : globalErp;
}

btScalar btQuaternionHingeConstraint::rowCfm(int kind, btScalar globalCfm) const
{
	return (m_settings.flags & (BT_QHINGE_FLAGS_CFM_ROW0 << kind)) ? m_settings.rowCfm[kind] : globalCfm;
}

// ---- Solver interface ------------------------------------------------------------------------------------------------

void btQuaternionHingeConstraint::clearFault()
{
	// A refused frame edit is not cleared until the frames are rigid again (else the refused frame would be used); a
	// refused construction never is (the joint has no configuration to return to).
	if (m_fault == BT_QHINGE_FAULT_INVALID_ARGUMENT) return;
	m_fault = BT_QHINGE_FAULT_NONE;
	validateFramesIfEdited();
	setEnabled(m_fault == BT_QHINGE_FAULT_NONE);
}

void btQuaternionHingeConstraint::getInfo1(btConstraintInfo1* info)
{
	computeRowCount(info, m_rbA.getCenterOfMassTransform(), m_rbB.getCenterOfMassTransform());
}

void btQuaternionHingeConstraint::getInfo1NonVirtual(btConstraintInfo1* info)
{
	// Bullet's non-virtual path: getInfo2NonVirtual tests the limit again at transforms this call never sees, so the
	// reservation must hold every row it may write (stock reserves its 6 here for the same reason): the bilateral
	// rows, the drive and friction rows when on, and a limit row whenever a limit acts, needed or not. A reserved row
	// left unwritten stays the solver's zero row (no effect). getInfo1's checks (faults, body state) still decide
	// whether there are any rows at all.
	computeRowCount(info, m_rbA.getCenterOfMassTransform(), m_rbB.getCenterOfMassTransform());
	if (info->m_numConstraintRows == 0) return;
	int rows = m_settings.angularOnly ? 2 : 5;
	if (m_settings.hasLimit) ++rows;
	if (driveActive(m_settings)) ++rows;
	if (m_settings.maxFrictionTorque > 0) ++rows;
	info->m_numConstraintRows = rows;
	m_numRows = rows;
}

void btQuaternionHingeConstraint::computeRowCount(btConstraintInfo1* info, const btTransform& transA,
												  const btTransform& transB)
{
	info->m_numConstraintRows = 0;
	info->nub = 0;
	m_numRows = 0;
	if (m_framesMayHaveChanged) validateFramesIfEdited();
	// A fault stands until clearFault(), even for a joint re-enabled by hand with setEnabled(true): no rows, disabled
	// again (the stabilizer skips a faulted joint as well; the two must agree).
	if (m_fault == BT_QHINGE_FAULT_FRAME_EDITED_INVALID || m_fault == BT_QHINGE_FAULT_NONFINITE_BODY_STATE ||
		m_fault == BT_QHINGE_FAULT_INVALID_ARGUMENT)
	{
		setEnabled(false);
		return;
	}
	// State from outside must not turn the rows into NaN: refuse, disable, say why.
	if (!finiteBodyState(m_rbA) || !finiteBodyState(m_rbB))
	{
		m_fault = BT_QHINGE_FAULT_NONFINITE_BODY_STATE;
		setEnabled(false);
		return;
	}
	if (isStaticLike(m_rbA) && isStaticLike(m_rbB))
	{
		m_fault = BT_QHINGE_FAULT_NO_DYNAMIC_BODY;  // transient: no row could act; rows return with a dynamic body
		return;
	}
	if (m_fault == BT_QHINGE_FAULT_NO_DYNAMIC_BODY) m_fault = BT_QHINGE_FAULT_NONE;

	int rows = m_settings.angularOnly ? 2 : 5;
	if (needsAngle())
	{
		if (m_settings.hasLimit) testLimit(transA, transB);  // caches the pose, advances the multi-turn angle
		else
		{
			poseAt(transA, transB, m_pose);
			m_poseCached = true;
			updateMultiTurnAngle(userSign(m_settings.useReferenceFrameA) * hingeAngle(m_pose.q));
		}
	}
	else
	{
		m_multiTurnValid = false;  // not tracked this step: whole turns may be missed from here on
		m_limitSign = 0;
	}
	if (m_limitSign != 0) ++rows;
	if (driveActive(m_settings)) ++rows;
	if (m_settings.maxFrictionTorque > 0) ++rows;
	info->m_numConstraintRows = rows;
	info->nub = m_settings.angularOnly ? 2 : 5;  // the bilateral, unbounded rows
	m_numRows = rows;
}

void btQuaternionHingeConstraint::getInfo2(btConstraintInfo2* info)
{
	fillRows(info, m_rbA.getCenterOfMassTransform(), m_rbB.getCenterOfMassTransform(), m_rbA.getAngularVelocity(),
			 m_rbB.getAngularVelocity());
}

void btQuaternionHingeConstraint::getInfo2NonVirtual(btConstraintInfo2* info, const btTransform& transA,
													 const btTransform& transB, const btVector3& angVelA,
													 const btVector3& angVelB)
{
	m_poseCached = false;       // a cached pose belongs to the body transforms, not to these
	testLimit(transA, transB);  // as stock: getInfo1 did not run for these transforms
	fillRows(info, transA, transB, angVelA, angVelB);
}

int btQuaternionHingeConstraint::fillBilateralRows(btConstraintInfo2* info, const btTransform& transA,
												  const btTransform& transB, const Pose& pose) const
{
	// pose: joint frame A's basis and both pivots in world; q = a* ⊗ b (Q2).
	const int skip = info->rowskip;
	const bool angularOnly = m_settings.angularOnly;
	const btScalar erpFps = info->erp * info->fps;
	// Per-row ERP/CFM only when some override is set (the common case writes one ERP and leaves CFM alone).
	const bool overrides = m_settings.flags != 0;
	auto errorScale = [&](int kind) { return overrides ? rowErp(kind, info->erp) * info->fps : erpFps; };
	auto rowCfmOverride = [&](int kind, int at) {
		if (overrides && (m_settings.flags & (BT_QHINGE_FLAGS_CFM_ROW0 << kind))) info->cfm[at] = m_settings.rowCfm[kind];
	};

	// Point part: C = p_B − p_A (MATH.md, "Bullet's conventions"). Along a direction e held for the step,
	// e·Ċ = e·(v_B + ω_B × r_B − v_A − ω_A × r_A), so the row is J1 = (−e, e × r_A), J2 = (e, r_B × e); error −erp·fps·e·C
	// (Q10), with e ∈ {p, t, a} (SolverRowBasis.h: a rotation of the row space that Gauss–Seidel converges on as fast
	// as on stock's rows; computePositionRows keeps world x, y, z). The solver hands rows in zeroed; every entry of a
	// row is written all the same (straight-line stores are cheaper than skipping zeros).
	// (Vectors in SIMD lanes, MatrixLanes.h: btVector3's operations lane by lane, the same bits.)
	const Lanes pivotA = lanesOf(pose.pivotA), pivotB = lanesOf(pose.pivotB);
	const Lanes rA = pivotA - lanesOf(transA.getOrigin());
	const Lanes rB = pivotB - lanesOf(transB.getOrigin());
	const PointRowBasis basis = pointRowBasis(pose.axesA, rA, rB, m_rbA.getInvMass(), m_rbB.getInvMass());

	// Quaternion part (Q7, Q9, Q10; the log form beyond 90°, Q12): body A −g, body B +g, error −erp·fps·C; for the
	// solver turned within the part's plane so the first row lies along p (SolverRowBasis.h). Written after the point
	// rows; computed first, as the point rows take a multiple of them (below).
	AngularRows angular;
	computeAngularRowsFromAxes(pose.axesA, pose.q, angular);
	const Lanes rowU = lanesOf(angular.rowU), rowV = lanesOf(angular.rowV);
	btScalar cosPsi, sinPsi;
	quaternionRowTurn(rowU, rowV, basis.p, cosPsi, sinPsi);
	const Lanes turnedU = rowU * cosPsi + rowV * sinPsi, turnedV = rowV * cosPsi - rowU * sinPsi;
	const btScalar errorU = -errorScale(kAngularKind) * (cosPsi * angular.errorU + sinPsi * angular.errorV);
	const btScalar errorV = -errorScale(kAngularKind + 1) * (cosPsi * angular.errorV - sinPsi * angular.errorU);

	int row = 0;
	if (!angularOnly)
	{
		// The axial parts of the lever arms (along the hinge axis a) couple a point row to the swing through the
		// bodies' inertia across the axis: a pivot 1 m along the axis from a body's centre held 0.04 m apart after 10
		// Gauss–Seidel sweeps where stock, which drops those parts, holds 2e-10 m. Shifting both arms by the same
		// δ a changes a point row by −δ (a × e)·(ω_B − ω_A), which vanishes wherever the quaternion rows hold; written
		// here as an exact row operation with them (the point row minus δ (c_u u' + c_v v') on both the Jacobian and
		// the error, c the combination of the quaternion rows nearest a × e), so the rows keep their solution set and
		// their exactness (SolverRowBasis.h: a change of row basis held for the step). δ as stock's: the arms' axial
		// offsets blended by inverse mass (a static side keeps its own; the dynamic side's axial arm becomes 0).
		const Lanes c = pivotB - pivotA;
		const btScalar invMassSum = m_rbA.getInvMass() + m_rbB.getInvMass();
		const btScalar weightA = invMassSum > btScalar(0) ? m_rbB.getInvMass() / invMassSum : btScalar(0.5);
		const btScalar axialA = dotXyz(basis.a, rA), axialB = dotXyz(basis.a, rB);
		const btScalar delta = axialA - (axialA - axialB) * weightA;
		const btScalar uu = dotXyz(turnedU, turnedU), uv = dotXyz(turnedU, turnedV), vv = dotXyz(turnedV, turnedV);
		const btScalar det = uu * vv - uv * uv;
		// (not for an offset at round-off level, 8 ε of the arms: a chain whose pivots lie across its axes keeps its bits)
		const btScalar roundOff = btScalar(8) * SIMD_EPSILON * (btSqrt(dotXyz(rA, rA)) + btSqrt(dotXyz(rB, rB)));
		const bool shift = btFabs(delta) > roundOff && det > SIMD_EPSILON * uu * vv;
		const Lanes directions[3] = {basis.p, basis.t, basis.a};
		for (int i = 0; i < 3; ++i, ++row)
		{
			const Lanes& e = directions[i];
			const int at = row * skip;
			Lanes angularA = crossLanes(e, rA), angularB = crossLanes(rB, e);
			btScalar error = -errorScale(kLinearKind + i) * dotXyz(e, c);
			if (shift && i < 2)  // a × a = 0: the axial row needs none
			{
				const Lanes w = crossLanes(basis.a, e);
				const btScalar wu = dotXyz(turnedU, w), wv = dotXyz(turnedV, w);
				const btScalar cu = delta * (vv * wu - uv * wv) / det, cv = delta * (uu * wv - uv * wu) / det;
				const Lanes g = turnedU * cu + turnedV * cv;
				angularA += g;  // minus (c_u, c_v)·δ times the quaternion rows, whose A side is −g
				angularB -= g;
				error -= cu * errorU + cv * errorV;
			}
			storeXyz(info->m_J1linearAxis + at, -e);
			storeXyz(info->m_J2linearAxis + at, e);
			storeXyz(info->m_J1angularAxis + at, angularA);
			storeXyz(info->m_J2angularAxis + at, angularB);
			info->m_constraintError[at] = error;
			rowCfmOverride(kLinearKind + i, at);
		}
	}

	const int atU = row * skip, atV = atU + skip;
	storeXyz(info->m_J1angularAxis + atU, -turnedU);
	storeXyz(info->m_J2angularAxis + atU, turnedU);
	storeXyz(info->m_J1angularAxis + atV, -turnedV);
	storeXyz(info->m_J2angularAxis + atV, turnedV);
	info->m_constraintError[atU] = errorU;
	info->m_constraintError[atV] = errorV;
	rowCfmOverride(kAngularKind, atU);
	rowCfmOverride(kAngularKind + 1, atV);
	return row + 2;
}

int btQuaternionHingeConstraint::computePositionRows(const btTransform& transA, const btTransform& transB, btScalar* C,
													 btScalar* jacobian) const
{
	// The same equations as the solver's rows, unrotated: point rows along world x, y, z (row i: J1 = (−e_i, e_i × r_A),
	// J2 = (e_i, r_B × e_i)), then the two quaternion rows (Q7, Q9; Q12 past 90°): J1 = (0, −g), J2 = (0, g).
	Pose pose;
	poseAt(transA, transB, pose);
	int rows = 0;
	if (!m_settings.angularOnly)
	{
		const btVector3 rA = pose.pivotA - transA.getOrigin();
		const btVector3 rB = pose.pivotB - transB.getOrigin();
		const btVector3 c = pose.pivotB - pose.pivotA;
		for (; rows < 3; ++rows)
		{
			btVector3 e(0, 0, 0);
			e[rows] = 1;
			const btVector3 angularA = e.cross(rA), angularB = rB.cross(e);
			btScalar* j = jacobian + 12 * rows;
			for (int k = 0; k < 3; ++k)
			{
				j[k] = -e[k];
				j[3 + k] = angularA[k];
				j[6 + k] = e[k];
				j[9 + k] = angularB[k];
			}
			C[rows] = c[rows];
		}
	}
	AngularRows angular;
	computeAngularRowsFromAxes(pose.axesA, pose.q, angular);
	const btVector3* g[2] = {&angular.rowU, &angular.rowV};
	const btScalar value[2] = {angular.errorU, angular.errorV};
	for (int r = 0; r < 2; ++r, ++rows)
	{
		btScalar* j = jacobian + 12 * rows;
		for (int k = 0; k < 3; ++k)
		{
			j[k] = 0;
			j[3 + k] = -(*g[r])[k];
			j[6 + k] = 0;
			j[9 + k] = (*g[r])[k];
		}
		C[rows] = value[r];
	}
	return rows;
}

void btQuaternionHingeConstraint::fillRows(btConstraintInfo2* info, const btTransform& transA,
										   const btTransform& transB, const btVector3& angVelA,
										   const btVector3& angVelB)
{
	// none when getInfo1 reserved none, or fewer than the bilateral rows (angular-only turned off in between)
	if (m_numRows < (m_settings.angularOnly ? 2 : 5)) return;
	m_lastTimeStep = btScalar(1) / info->fps;
	// the pose getInfo1 cached, used in place; else computed here (no copy either way)
	Pose computed;
	if (!m_poseCached) poseAt(transA, transB, computed);
	const Pose& pose = m_poseCached ? m_pose : computed;
	m_poseCached = false;  // the cache belongs to this getInfo1/getInfo2 pair
	int row = fillBilateralRows(info, transA, transB, pose);
	const int skip = info->rowskip;

	// Never more rows than the last getInfo1 reserved (m_numRows), whatever changed since: a setter called between
	// the two, or getInfo2NonVirtual's own limit test. Dropped first: the limit row, then friction (the order below
	// writes the drive first).
	const int budget = m_numRows;
	const bool drive = driveActive(m_settings) && row < budget;
	const bool friction = m_settings.maxFrictionTorque > 0 && row + (drive ? 1 : 0) < budget;
	const bool limitRowFits = row + (drive ? 1 : 0) + (friction ? 1 : 0) < budget;
	if ((m_limitSign == 0 || !limitRowFits) && !drive && !friction) return;

	// Axis part: rows along J_α = σ R_A t (HingeAngle.h: the exact gradient of the angle within 90° of assembly).
	// (In SIMD lanes, MatrixLanes.h: btVector3's products, the same bits.)
	const btScalar sigma = userSign(m_settings.useReferenceFrameA);
	const Lanes axis =
		(pose.axialKnown ? lanesOf(pose.axial) : timesTransposed(pose.axesA, axialRowDirection(pose.q))) * sigma;
	const btScalar rate = dotXyz(axis, lanesOf(angVelB) - lanesOf(angVelA));
	const btScalar normalErp = rowErp(kAxialKind, info->erp);
	auto emit = [&](const AxialRow& axial, bool setCfm, btScalar cfm) {
		const int at = row * skip;
		storeXyz(info->m_J1angularAxis + at, -axis);
		storeXyz(info->m_J2angularAxis + at, axis);
		info->m_constraintError[at] = axial.error;
		info->m_lowerLimit[at] = axial.lower;
		info->m_upperLimit[at] = axial.upper;
		if (setCfm) info->cfm[at] = cfm;
		++row;
	};
	const bool axialCfm = (m_settings.flags & (BT_QHINGE_FLAGS_CFM_ROW0 << kAxialKind)) != 0;
	if (drive)
	{
		btScalar invEffectiveMass = 0;
		if (m_settings.driveMode == BT_QHINGE_DRIVE_SPRING)
		{
			btVector3 a;
			storeLanes(a, axis);
			invEffectiveMass = a.dot(m_rbA.getInvInertiaTensorWorld() * a * m_rbA.getAngularFactor()) +
							   a.dot(m_rbB.getInvInertiaTensorWorld() * a * m_rbB.getAngularFactor());
		}
		const btScalar angle = needsAngle() ? m_multiTurnAngle : btScalar(0);
		emit(driveRow(m_settings, angle, rate, info->fps, invEffectiveMass), axialCfm && m_settings.driveMode != BT_QHINGE_DRIVE_SPRING,
			 m_settings.rowCfm[kAxialKind]);
	}
	if (friction) emit(frictionRow(m_settings, info->fps), axialCfm, m_settings.rowCfm[kAxialKind]);
	// The limit row comes last: Gauss–Seidel leaves each sweep with the last row satisfied, so a stop is never crossed
	// because a drive row was solved after it (a motor driven into a stop is held by the stop).
	if (m_limitSign != 0 && limitRowFits)
	{
		LimitState limit;  // as testLimit found it in getInfo1 (or getInfo2NonVirtual)
		limit.sign = m_limitSign;
		limit.locked = m_limitLocked;
		limit.speculative = m_limitSpeculative;
		limit.distance = m_limitDistance;
		const btScalar stopErp = (m_settings.flags & BT_QHINGE_FLAGS_ERP_STOP) ? m_settings.stopErp : normalErp;
		emit(limitRow(m_settings, limit, rate, info->fps, stopErp), (m_settings.flags & BT_QHINGE_FLAGS_CFM_STOP) != 0,
			 m_settings.stopCfm);
	}
}
