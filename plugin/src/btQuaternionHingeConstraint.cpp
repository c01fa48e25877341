// btQuaternionHingeConstraint: composes the point part (3 linear rows), the quaternion two-row part
// (QuaternionHingeRows.h, MATH.md Q2–Q10, Q12) and the axis part (AxisRows.h: limit, drive, friction), and tracks the
// multi-turn angle (HingeAngle.h, Q11). The class lives in six files, one concept each:
//   btQuaternionHingeConstraint.cpp  construction, the joint frames and the pose they give (this file)
//   HingeLimitsAndDrives.cpp         limit, motor, servo, spring and friction settings; the angle and multi-turn angle
//   HingeErpCfm.cpp                  setParam/getParam: ERP and CFM per row kind
//   HingeSolverRows.cpp              the solver interface: which rows exist (getInfo1) and their values (getInfo2)
//   HingeBilateralRows.cpp           the five bilateral rows in the solver's row basis
//   HingePositionRows.cpp            computePositionRows: the same equations at given transforms
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
btMatrix3x3 basisFromColumns(const btVector3& x, const btVector3& y, const btVector3& z)
{
	return btMatrix3x3(x.x(), y.x(), z.x(), x.y(), y.y(), z.y(), x.z(), y.z(), z.z());
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

bool checkBodies(const char* fn, const btRigidBody& rbA, const btRigidBody& rbB)
{
	return &rbA != &rbB || check::fail(fn, "rbB is the same body as rbA (a joint needs two bodies)");
}
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

	initFrames(btTransform(basisFromColumns(axisA1, axisA2, axisA), pivotInA), btTransform(basisFromColumns(axisB1, axisB2, axisB), pivotInB), useReferenceFrameA);
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
	initFrames(btTransform(basisFromColumns(axisA1, axisA2, axisA), pivotInA), frameB, useReferenceFrameA);
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
	initFrames(rbAFrame, rbBFrame, useReferenceFrameA);
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
	initFrames(rbAFrame, frameB, useReferenceFrameA);
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

// q of the joint frames (framePoseAt's): frame A's axes (rows of R_Aᵀ, from body A's basis by columns) into axesA,
// then R_Aᵀ R_B.
inline void frameRotation(const Lanes& a0, const Lanes& a1, const Lanes& a2, const btTransform& frameInA,
						  const btTransform& transB, const btTransform& frameInB, btMatrix3x3& axesA, btQuaternion& q)
{
	productTransposedRows(a0, a1, a2, frameInA.getBasis(), axesA);
	btMatrix3x3 basisB, relative;
	multiplyRows(transB.getBasis(), frameInB.getBasis(), basisB);
	multiplyRows(axesA, basisB, relative);  // R_Aᵀ R_B
	rotationToQuaternion(relative, q);
}
}  // namespace

void btQuaternionHingeConstraint::poseAt(const btTransform& transA, const btTransform& transB, Pose& pose) const
{
	framePoseAt(m_settings.frameInA, m_settings.frameInB, transA, transB, pose);
}

void btQuaternionHingeConstraint::framePoseAt(const btTransform& frameInA, const btTransform& frameInB,
											  const btTransform& transA, const btTransform& transB, Pose& pose)
{
	// One matrix-to-quaternion conversion: q from R_Aᵀ R_B of the joint frames (the products with btTransform's bits,
	// MatrixLanes.h). Body A's basis by columns serves both R_Aᵀ and the pivot, body B's the pivot.
	const Lanes a0 = columnLanes(transA.getBasis(), 0), a1 = columnLanes(transA.getBasis(), 1),
				a2 = columnLanes(transA.getBasis(), 2);
	frameRotation(a0, a1, a2, frameInA, transB, frameInB, pose.axesA, pose.q);
	storeLanes(pose.pivotA, transformedLanes(a0, a1, a2, transA.getOrigin(), frameInA.getOrigin()));
	storeLanes(pose.pivotB, transformedLanes(columnLanes(transB.getBasis(), 0), columnLanes(transB.getBasis(), 1),
											 columnLanes(transB.getBasis(), 2), transB.getOrigin(),
											 frameInB.getOrigin()));
	pose.axialKnown = false;
}

btScalar btQuaternionHingeConstraint::computeFrameAngle(const btTransform& frameInA, const btTransform& frameInB,
														const btTransform& transA, const btTransform& transB)
{
	// framePoseAt's q without the pivots; frameAngleRowAt's angle with σ = 1 from 0 is continueAngle(0, θ) = θ, as
	// hingeAngle's θ is in (−π, π] already
	btMatrix3x3 axesA;
	btQuaternion q;
	frameRotation(columnLanes(transA.getBasis(), 0), columnLanes(transA.getBasis(), 1),
				  columnLanes(transA.getBasis(), 2), frameInA, transB, frameInB, axesA, q);
	return hingeAngle(q);
}

void btQuaternionHingeConstraint::initFrames(const btTransform& frameA, const btTransform& frameB,
											 bool useReferenceFrameA)
{
	m_settings.frameInA = frameA;
	m_settings.frameInB = frameB;
	m_settings.useReferenceFrameA = useReferenceFrameA;
	initFromSettings();
}

void btQuaternionHingeConstraint::initFromSettings()
{
	m_poseCached = false;
	m_limitIsOneTurn = false;
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
	m_limitImpactSpeed = 0;
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
