// btQuaternionHingeConstraint's solver interface: getInfo1 decides which rows exist (and checks the bodies' state and
// edited frames first), getInfo2 fills them in this order:
//   [0..2] point-to-point (unless angular-only)   [next 2] quaternion rows   [drive] [friction] [limit]
// The bilateral rows are written by HingeBilateralRows.cpp, the same equations at given transforms for
// post-stabilizers by HingePositionRows.cpp (computePositionRows).
#include "quathinge/btQuaternionHingeConstraint.h"

#include "AxisRows.h"
#include "HingeAngle.h"
#include "InputChecks.h"
#include "MatrixLanes.h"
#include "QuaternionHingeRows.h"
#include "RowKinds.h"
#include "SolverRowBasis.h"
#include "WorldPointRows.h"

#include "BulletDynamics/Dynamics/btRigidBody.h"
#include "LinearMath/btTransformUtil.h"

#include <cmath>
#include <cstring>
#include <type_traits>

using namespace quathinge;

namespace
{
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

// The bits of x without its sign: zero exactly when x == 0 (+0 or −0; never for NaN).
std::make_unsigned<LaneInt>::type magnitudeBits(btScalar x)
{
	std::make_unsigned<LaneInt>::type bits;
	std::memcpy(&bits, &x, sizeof bits);
	return bits << 1;
}

// No inverse mass and no inverse inertia (invMass == 0 && invInertiaDiagLocal.isZero(), one integer test instead of
// four floating-point comparisons, which the compiler evaluates branch-free with their NaN cases).
bool isStaticLike(const btRigidBody& body)
{
	const btVector3& d = body.getInvInertiaDiagLocal();
	return (magnitudeBits(body.getInvMass()) | magnitudeBits(d.x()) | magnitudeBits(d.y()) | magnitudeBits(d.z())) == 0;
}

// A moving kinematic body's pose at the start of a step of h s, where the rows measure the joint's error. Bullet moves
// a kinematic body to its pose at the end of the step before its solver runs (saveKinematicState) and gives it the
// velocity of that move. Measured there, each step would start a step's motion h·v behind the partner, and the error
// correction would turn that lead into speed: stock's btHingeConstraint does, and its bodies then run a step ahead of
// the partner; a post-stabilizer that closes the joint every step takes that speed back every step, a correction of
// order h rather than the drift's h² (docs/ENERGY.md, "Under an app's forces"). Any other body: its pose.
const btTransform& poseAtStepStart(const btRigidBody& body, btScalar h, btTransform& scratch)
{
	if (!body.isKinematicObject() || !(h > 0) ||
		(body.getLinearVelocity().fuzzyZero() && body.getAngularVelocity().fuzzyZero()))
		return body.getCenterOfMassTransform();
	btTransformUtil::integrateTransform(body.getCenterOfMassTransform(), -body.getLinearVelocity(),
										-body.getAngularVelocity(), h, scratch);
	return scratch;
}

// The slowest hit (rad/s) a speculative stop row remembers for the next step's bounce: the 0.2 of Bullet's contact
// solver (btContactSolverInfo::m_restitutionVelocityThreshold, "below this threshold, there is zero restitution").
const btScalar kBounceThreshold = btScalar(0.2);

// A stop row S on a joint to a static body, taken off the tangential point row T, whose lever about the hinge couples
// the two (a door 12.3 m from its pivot pushed into its stop: S halted the turn and left the centre of mass's 24 m/s
// to T through its 12.1 m lever, and 10 Gauss–Seidel sweeps parted the pivots by 1.84 m). The row written is
// S' = S − c T with c = (S M⁻¹ Tᵀ)/(T M⁻¹ Tᵀ), so that S' changes no T·v (the stop turns the body about the pivot, not
// about its centre of mass), and its target e_S − c e_T. An exact row operation for an inequality: T is bilateral, so
// wherever it holds S'·v ≥ e_S − c e_T is S·v ≥ e_S, and the impulse λ' S' = λ' S − λ' c T has its stop part λ' within
// the stop's bounds: the stop still only pushes (the multiple of T is the joint's own, unbounded, pivot force).
// (Not the other way round, T − k S: T then holds the turn about the hinge by itself whenever the stop's impulse is
// at its bound, a pull the stop may not give; a pendulum thrown into an inelastic stop stayed there, held against
// gravity.)
void takeTangentialRowOffStop(btTypedConstraint::btConstraintInfo2* info, int stopAt, int tangentAt,
							  const btRigidBody& a, const btRigidBody& b)
{
	auto read = [](const btScalar* p) { return btVector3(p[0], p[1], p[2]); };
	const btVector3 linearA = read(info->m_J1linearAxis + tangentAt), angularA = read(info->m_J1angularAxis + tangentAt);
	const btVector3 linearB = read(info->m_J2linearAxis + tangentAt), angularB = read(info->m_J2angularAxis + tangentAt);
	// M⁻¹ Tᵀ's angular parts (the solver's: I⁻¹ times the angular factor), and the linear parts' weights
	const btVector3 turnA = a.getInvInertiaTensorWorld() * angularA * a.getAngularFactor();
	const btVector3 turnB = b.getInvInertiaTensorWorld() * angularB * b.getAngularFactor();
	const btScalar tt = linearA.dot(linearA * a.getLinearFactor()) * a.getInvMass() +
						linearB.dot(linearB * b.getLinearFactor()) * b.getInvMass() + angularA.dot(turnA) +
						angularB.dot(turnB);
	if (!(tt > SIMD_EPSILON)) return;
	const btScalar st = read(info->m_J1angularAxis + stopAt).dot(turnA) + read(info->m_J2angularAxis + stopAt).dot(turnB);
	const btScalar c = st / tt;
	for (int k = 0; k < 3; ++k)
	{
		info->m_J1linearAxis[stopAt + k] = -c * linearA[k];
		info->m_J2linearAxis[stopAt + k] = -c * linearB[k];
		info->m_J1angularAxis[stopAt + k] -= c * angularA[k];
		info->m_J2angularAxis[stopAt + k] -= c * angularB[k];
	}
	info->m_constraintError[stopAt] -= c * info->m_constraintError[tangentAt];
}
}  // namespace

void btQuaternionHingeConstraint::clearFault()
{
	// A refused frame edit is not cleared until the frames are rigid again (else the refused frame would be used); a
	// refused construction never is (the joint has no configuration to return to).
	if (m_fault == BT_QHINGE_FAULT_INVALID_ARGUMENT) return;
	m_fault = BT_QHINGE_FAULT_NONE;
	validateFramesIfEdited();
	setEnabled(m_fault == BT_QHINGE_FAULT_NONE);
}

// Defined here, beside its only callers (getInfo1 and getInfo2), so that it is inlined into them.
bool btQuaternionHingeConstraint::needsAngle() const
{
	return m_settings.hasLimit || m_trackAlways || m_settings.driveMode == BT_QHINGE_DRIVE_SERVO ||
		   m_settings.driveMode == BT_QHINGE_DRIVE_SPRING;
}

void btQuaternionHingeConstraint::getInfo1(btConstraintInfo1* info)
{
	// (the step's h is not in btConstraintInfo1: the last getInfo2's; getInfo2 computes the pose again if it differs)
	btTransform startA, startB;
	computeRowCount(info, poseAtStepStart(m_rbA, m_lastTimeStep, startA), poseAtStepStart(m_rbB, m_lastTimeStep, startB));
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
	const btScalar h = btScalar(1) / info->fps;
	// getInfo1 moved a kinematic partner back by m_lastTimeStep, which fillRows sets to h only below
	if (m_rbA.isKinematicObject() || m_rbB.isKinematicObject()) m_poseCached = m_poseCached && m_lastTimeStep == h;
	btTransform startA, startB;
	fillRows(info, poseAtStepStart(m_rbA, h, startA), poseAtStepStart(m_rbB, h, startB), m_rbA.getAngularVelocity(),
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
	// Never more rows than the last getInfo1 reserved (m_numRows), whatever changed since: a setter called between
	// the two, or getInfo2NonVirtual's own limit test. Dropped first: the limit row, then friction (the order below
	// writes the drive first). Decided before the bilateral rows, which need to know whether a stop row follows.
	const int budget = m_numRows;
	int row = m_settings.angularOnly ? 2 : 5;
	const bool drive = driveActive(m_settings) && row < budget;
	const bool friction = m_settings.maxFrictionTorque > 0 && row + (drive ? 1 : 0) < budget;
	const bool limitRowFits = row + (drive ? 1 : 0) + (friction ? 1 : 0) < budget;
	const bool axisRows = (m_limitSign != 0 && limitRowFits) || drive || friction;
	// The angle's direction of change R_A t (HingeAngle.h: the exact gradient of the angle within 90° of assembly),
	// once, for the axis rows below and a binding stop; not computed for a joint with neither.
	const Lanes alpha = axisRows
							? (pose.axialKnown ? lanesOf(pose.axial) : timesTransposed(pose.axesA, axialRowDirection(pose.q)))
							: Lanes{};
	row = fillBilateralRows(info, transA, transB, pose);
	const int skip = info->rowskip;
	if (!(m_limitSign != 0 && limitRowFits)) m_limitImpactSpeed = 0;  // no stop row this step: no hit to remember
	if (!axisRows) return;

	// Axis part: rows along J_α = σ R_A t. (In SIMD lanes, MatrixLanes.h: btVector3's products, the same bits.)
	const btScalar sigma = userSign(m_settings.useReferenceFrameA);
	const Lanes axis = alpha * sigma;
	const btScalar rate = dotXyz(axis, lanesOf(angVelB) - lanesOf(angVelA));
	const btScalar normalErp = rowErp(kAxialKind, info->erp);
	auto emit = [&](const AxialRow& axial, bool setCfm, btScalar cfm) {
		const int at = row * skip;
		storeXyzNegatedAndAsIs(info->m_J1angularAxis + at, info->m_J2angularAxis + at, axis);
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
		const int stopAt = row * skip;
		emit(limitRow(m_settings, limit, rate, info->fps, stopErp, m_limitImpactSpeed),
			 (m_settings.flags & BT_QHINGE_FLAGS_CFM_STOP) != 0, m_settings.stopCfm);
		// a speculative row that meets its stop within this step stops the joint there with the rest of its speed:
		// the next step's bounce takes the speed it came with (AxisRows.h). Not below kBounceThreshold: a joint resting
		// on its stop meets it every step with the speed one step of gravity gives, and bouncing that kept it from rest
		// (chains against their stops never slept on aarch64, where they land a rounding short of the stop).
		const btScalar approach = -btScalar(m_limitSign) * rate;
		m_limitImpactSpeed = limit.speculative && approach > limit.distance * info->fps && approach > kBounceThreshold
								 ? approach
								 : btScalar(0);
		// on a joint to a static body, the stop row off the tangential point row (the point rows' second, after the
		// quaternion rows when the study hook puts those first)
		if (!m_settings.angularOnly && (m_rbA.getInvMass() < SIMD_EPSILON) != (m_rbB.getInvMass() < SIMD_EPSILON))
			takeTangentialRowOffStop(info, stopAt, ((m_angularRowsFirst ? 2 : 0) + 1) * skip, m_rbA, m_rbB);
	}
}
