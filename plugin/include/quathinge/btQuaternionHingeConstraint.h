/** \file
The quaternion hinge: btQuaternionHingeConstraint, its turn-counting subclass, and the calls that upgrade a world's
stock hinges (btReplaceHingeConstraints, btSwapConstraintInWorld).

Errors: what has no meaning (NaN/Inf, a zero axis, the same body twice, a negative impulse) is refused, naming the
function and parameter: std::invalid_argument, or the error callback without exceptions (btQuaternionHingeErrors.h).
Nothing invalid is stored; no const method throws; a body's non-finite state found in getInfo1 disables the joint
with a reason (getFault()).
*/
#ifndef BT_QUATERNION_HINGE_CONSTRAINT_H
#define BT_QUATERNION_HINGE_CONSTRAINT_H

#include "LinearMath/btQuaternion.h"
#include "LinearMath/btTransform.h"
#include "LinearMath/btVector3.h"
#include "BulletDynamics/ConstraintSolver/btTypedConstraint.h"
#include "quathinge/quathinge_export.h"
#include "btQuaternionHingeErrors.h"
#include "btQuaternionHingeSettings.h"

class btHingeConstraint;
class btDynamicsWorld;
namespace quathinge
{
struct SolverRowBasisAccess;  // plugin/src/SolverRowBasis.h: the in-tree hook that picks the rows' basis (studies)
}
class btIDebugDraw;

/// Constraint type reported by getConstraintType(). It is none of the types that
/// btDiscreteDynamicsWorld::debugDrawConstraint downcasts (MATH.md, "Bullet's conventions"); the joint draws itself
/// with btQuaternionHingeConstraint::debugDraw. The value is 15: btTypedConstraintType has no fixed underlying type,
/// so only values inside its enumerators' bit range (0–15) are valid values of the enum (UBSan checks this); 14 and
/// 15 are the unused ones above MAX_CONSTRAINT_TYPE (13).
const btTypedConstraintType QUATERNION_HINGE_CONSTRAINT_TYPE = btTypedConstraintType(MAX_CONSTRAINT_TYPE + 2);

/// A drop-in replacement for btHingeConstraint (stock's constructors, methods and sign conventions) whose two angular
/// rows are the exact derivative of the relative quaternion of the joint frames (MATH.md Q2–Q12), at full strength at
/// every angle; limits on a multi-turn angle, a servo, a spring in hertz, joint friction and per-row ERP/CFM. It
/// reports only the rows it needs (5 bare, 2 angular-only, a limit or drive row only while active). It is not a
/// btHingeConstraint: identify one with upcast().
/// \code
/// btQuaternionHingeConstraint* hinge = new btQuaternionHingeConstraint(*a, *b, btVector3(0, -1, 0), btVector3(0, 1, 0),
///                                                                      btVector3(0, 0, 1), btVector3(0, 0, 1));
/// hinge->setLimit(-SIMD_HALF_PI, SIMD_HALF_PI);  // radians; a multi-turn range may be wider than 2π
/// world->addConstraint(hinge, true);             // the app owns it: remove and delete it before its bodies
/// \endcode
/// More: docs/MIGRATING.md (from stock, the differences), docs/MATH.md (the rows), README.md (a complete program).
ATTRIBUTE_ALIGNED16(class)
QUATHINGE_API btQuaternionHingeConstraint : public btTypedConstraint
{
public:
	BT_DECLARE_ALIGNED_ALLOCATOR();

	// ---- Constructors: the four of btHingeConstraint, same arguments, same meaning ----------------------------------

	/// Pivots and axes in A's and B's local frames. The frames' x axes are chosen as btHingeConstraint chooses them, so
	/// the zero angle is the same as stock's.
	btQuaternionHingeConstraint(btRigidBody & rbA, btRigidBody & rbB, const btVector3& pivotInA, const btVector3& pivotInB,
								const btVector3& axisInA, const btVector3& axisInB, bool useReferenceFrameA = false);
	/// Body A hinged to the world (Bullet's fixed body) at pivotInA about axisInA. As with every one-body constraint of
	/// Bullet's, the fixed body, btTypedConstraint::getFixedBody(), is one static object shared by all worlds, and
	/// adding such a joint to a world appends the joint to that body's list of constraints: an app that builds worlds
	/// in several threads at once hangs its joints from a static btRigidBody of each world instead (the two-body
	/// constructors).
	btQuaternionHingeConstraint(btRigidBody & rbA, const btVector3& pivotInA, const btVector3& axisInA,
								bool useReferenceFrameA = false);
	/// Joint frames in A's and B's local frames (origin: the pivot; z column: the hinge axis), as stock's.
	btQuaternionHingeConstraint(btRigidBody & rbA, btRigidBody & rbB, const btTransform& rbAFrame,
								const btTransform& rbBFrame, bool useReferenceFrameA = false);
	/// Body A hinged to the world with its joint frame rbAFrame, as stock's (the shared fixed body: see above).
	btQuaternionHingeConstraint(btRigidBody & rbA, const btTransform& rbAFrame, bool useReferenceFrameA = false);

	/// The equivalent of an existing stock hinge: same bodies, frames, limits, motor, ERP/CFM parameters, breaking
	/// threshold, enabled state, user ids, solver-iteration override and joint feedback pointer.
	explicit btQuaternionHingeConstraint(const btHingeConstraint& stock);

	/// From a complete configuration (what getSettings() returns). rbB may be btTypedConstraint::getFixedBody().
	btQuaternionHingeConstraint(btRigidBody & rbA, btRigidBody & rbB, const btQuaternionHingeSettings& settings);

	/// The quaternion hinge behind a constraint pointer, or null (as btRigidBody::upcast): the type number first
	/// (QUATERNION_HINGE_CONSTRAINT_TYPE, cheap; every Bullet constraint is ruled out there), then dynamic_cast, so a
	/// constraint of another plugin that uses the same number is never taken for one. Needs RTTI for the classes
	/// that carry this type number (Bullet and QuatHinge are built with it). Use it instead of a static_cast on
	/// getConstraintType().
	static btQuaternionHingeConstraint* upcast(btTypedConstraint * constraint);
	/// The const form of upcast().
	static const btQuaternionHingeConstraint* upcast(const btTypedConstraint* constraint);

	// ---- btTypedConstraint --------------------------------------------------------------------------------------------
	/// Bullet's solver interface: how many rows the joint has this step (0 when disabled or faulted).
	virtual void getInfo1(btConstraintInfo1 * info);
	/// Bullet's solver interface: the rows' Jacobians, errors, CFM and bounds, in getInfo1's count. A moving
	/// kinematic body enters at its pose at the step's start (its pose less its velocity over the step): Bullet has
	/// moved it to the step's end already, and stock's rows, measured there, make its partner run a step ahead of it
	/// (docs/MIGRATING.md, "Every difference").
	virtual void getInfo2(btConstraintInfo2 * info);
	/// For Bullet's non-virtual path: as stock's (which reserves a fixed 6), every row getInfo2NonVirtual may write —
	/// the bilateral rows, the drive and friction rows when on, and a limit row whenever a limit acts (it is tested
	/// again there, at the transforms given). Neither getInfo2 form ever writes more rows than the last getInfo1 or
	/// getInfo1NonVirtual reserved.
	void getInfo1NonVirtual(btConstraintInfo1 * info);
	/// As getInfo2, for given transforms and angular velocities (used by btHingeConstraint-style callers).
	void getInfo2NonVirtual(btConstraintInfo2 * info, const btTransform& transA, const btTransform& transB,
							const btVector3& angVelA, const btVector3& angVelB);
	/// Stock's two row formulations, between which its getInfo2NonVirtual chooses by useFrameOffset. The exact rows have
	/// one form, so both are getInfo2NonVirtual (source compatibility). One difference: stock's take the limit state of
	/// its last testLimit; these test the limit at the transforms given, as getInfo2NonVirtual does, so their rows
	/// stay within what getInfo1NonVirtual reserved whatever transforms a caller passes.
	void getInfo2Internal(btConstraintInfo2 * info, const btTransform& transA, const btTransform& transB,
						  const btVector3& angVelA, const btVector3& angVelB)
	{
		getInfo2NonVirtual(info, transA, transB, angVelA, angVelB);
	}
	/// Stock's frame-offset row formulation: the same rows as getInfo2Internal (above).
	void getInfo2InternalUsingFrameOffset(btConstraintInfo2 * info, const btTransform& transA, const btTransform& transB,
										  const btVector3& angVelA, const btVector3& angVelB)
	{
		getInfo2NonVirtual(info, transA, transB, angVelA, angVelB);
	}
	/// As stock's: nothing to update (the rows are written whole by getInfo2).
	void updateRHS(btScalar /*timeStep*/) {}

	/// ERP / STOP_ERP / CFM / STOP_CFM. axis −1 or 5 means what it means for stock: ERP for every row, CFM for the
	/// axial drive (motor) and friction rows, STOP_* for the limit row. Beyond stock, axis 0..2 sets the linear rows,
	/// 3..4 the angular rows (stock ignores these axes); STOP_* accept only −1 and 5. ERP in [0, 2), CFM in [0, 1)
	/// (outside them the solve diverges or asks for error growth); anything else is refused.
	virtual void setParam(int num, btScalar value, int axis = -1);
	/// The value set for (num, axis), or 0 when none was set (as stock, whose unset values are 0; the solver's global
	/// value is then in effect). Never fails: an unknown num or axis returns 0.
	virtual btScalar getParam(int num, int axis = -1) const;
	/// The BT_QHINGE_FLAGS_* bits of the ERP/CFM overrides that are set.
	virtual int getFlags() const { return m_settings.flags; }

	/// Writes a btHingeConstraintData that any Bullet reader loads as a stock hinge, and through the serializer a second
	/// chunk with everything a QuatHinge reader needs to restore the joint (btQuaternionHingeSerialization.h; these
	/// forward to btQuaternionHingeSerializeBufferSize and btQuaternionHingeSerialize).
	virtual int calculateSerializeBufferSize() const;
	/// Writes the joint (see calculateSerializeBufferSize); returns the chunk's struct name.
	virtual const char* serialize(void* dataBuffer, btSerializer* serializer) const;

	// ---- btHingeConstraint's public methods ----------------------------------------------------------------------------
	const btRigidBody& getRigidBodyA() const { return m_rbA; }  ///< Body A (const).
	const btRigidBody& getRigidBodyB() const { return m_rbB; }  ///< Body B (const).
	btRigidBody& getRigidBodyA() { return m_rbA; }              ///< Body A.
	btRigidBody& getRigidBodyB() { return m_rbB; }              ///< Body B.

	/// Frames (non-const access as in btHingeConstraint: an edit is re-validated before the next solve).
	btTransform& getFrameOffsetA();
	btTransform& getFrameOffsetB();                                       ///< Joint frame in body B (an edit is re-validated before the next solve).
	btTransform& getAFrame() { return getFrameOffsetA(); }                ///< Joint frame in body A, as getFrameOffsetA().
	btTransform& getBFrame() { return getFrameOffsetB(); }                ///< Joint frame in body B, as getFrameOffsetB().
	const btTransform& getAFrame() const { return m_settings.frameInA; }  ///< Joint frame in body A (const).
	const btTransform& getBFrame() const { return m_settings.frameInB; }  ///< Joint frame in body B (const).
	/// Sets both joint frames (rigid frames only; refused otherwise).
	void setFrames(const btTransform& frameA, const btTransform& frameB);
	/// As btHingeConstraint::setAxis: new hinge axis in A (finite, non-zero, any length: normalized), B's frame
	/// re-derived from the current pose.
	void setAxis(btVector3 & axisInA);

	/// Only the two angular rows (no point rows): aligns the axes without holding the pivot.
	void setAngularOnly(bool angularOnly) { m_settings.angularOnly = angularOnly; }
	bool getAngularOnly() const { return m_settings.angularOnly; }  ///< Whether only the angular rows are used.
	/// Stock's row-formulation switch, kept for source compatibility (both values give the same rows).
	bool getUseFrameOffset() const { return m_settings.useFrameOffset; }
	/// Stock's row-formulation switch, kept for source compatibility (both values give the same rows).
	void setUseFrameOffset(bool frameOffsetOnOff) { m_settings.useFrameOffset = frameOffsetOnOff; }
	/// Stock's useReferenceFrameA: false makes getHingeAngle() −θ (Q11).
	bool getUseReferenceFrameA() const { return m_settings.useReferenceFrameA; }
	/// Sets stock's useReferenceFrameA (the angle's sign; the multi-turn angle follows).
	void setUseReferenceFrameA(bool useReferenceFrameA);

	/// btHingeConstraint's motor: a velocity drive. enableAngularMotor(false, …) turns the velocity drive off.
	void enableAngularMotor(bool enableMotor, btScalar targetVelocity, btScalar maxMotorImpulse);
	void enableMotor(bool enableMotor);                 ///< Turns the velocity drive on or off, keeping its target and impulse.
	void setMaxMotorImpulse(btScalar maxMotorImpulse);  ///< The velocity drive's maximum impulse per step (N·m·s, ≥ 0).
	/// The velocity drive's target angular velocity (rad/s).
	void setMotorTargetVelocity(btScalar motorTargetVelocity);
	/// As stock: sets the motor's target velocity so that the angle reaches targetAngle (clamped to the limit) in dt.
	/// Must be called every tick; setServoTarget holds an angle without that.
	void setMotorTarget(btScalar targetAngle, btScalar dt);
	/// qAinB: rotation of body A relative to body B, as stock: its twist about the hinge axis is the target angle
	/// (also with useReferenceFrameA, where stock takes it unchanged although getHingeAngle() changes sign).
	void setMotorTarget(const btQuaternion& qAinB, btScalar dt);
	/// Whether the velocity drive is on.
	bool getEnableAngularMotor() const { return m_settings.driveMode == BT_QHINGE_DRIVE_VELOCITY; }
	/// The velocity drive's target angular velocity (rad/s).
	btScalar getMotorTargetVelocity() const { return m_settings.motorTargetVelocity; }
	/// The velocity drive's maximum impulse per step (N·m·s).
	btScalar getMaxMotorImpulse() const { return m_settings.maxMotorImpulse; }

	/// Limit on the multi-turn angle (radians; may straddle ±π, may be wider than 2π). As stock: low > high frees the
	/// joint (the values are kept and reported), low == high locks it, and a range of exactly one turn (high − low =
	/// 2π, e.g. setLimit(−π, π)) never acts: the common way to say "no limit". An end beyond ±1e6 rad or at ±BT_LARGE_FLOAT
	/// means no stop on that side. softness: any finite value; biasFactor, relaxationFactor: any value within ±1e3
	/// (refused beyond: they scale the limit row's error), see btQuaternionHingeSettings. If the current multi-turn angle is outside [low, high], it is moved by whole turns
	/// to the branch nearest the range (so a stock-style range across ±π means what it means for btHingeConstraint).
	void setLimit(btScalar low, btScalar high, btScalar softness = btScalar(0.9f), btScalar biasFactor = btScalar(0.3f),
				  btScalar relaxationFactor = btScalar(1.0));
	/// Frees the joint (as setLimit(1, -1) would, but keeping the ends).
	void removeLimit();
	/// Stock's answer: a limit with a range (high > low). A lock (low == high) acts but reports false, and a range of
	/// exactly one turn (setLimit(−π, π)) reports true but never acts, as stock's; getSettings().hasLimit says whether
	/// any limit acts.
	bool hasLimit() const
	{
		return (m_settings.hasLimit || m_limitIsOneTurn) && m_settings.upperLimit > m_settings.lowerLimit;
	}
	btScalar getLowerLimit() const { return m_settings.lowerLimit; }  ///< Lower end of the limit as set (rad).
	btScalar getUpperLimit() const { return m_settings.upperLimit; }  ///< Upper end of the limit as set (rad).
	/// The limit's softness as set (btQuaternionHingeSettings::limitSoftness).
	btScalar getLimitSoftness() const { return m_settings.limitSoftness; }
	btScalar getLimitBiasFactor() const { return m_settings.limitBiasFactor; }  ///< The limit's bias factor as set.
	/// The limit's relaxation factor as set.
	btScalar getLimitRelaxationFactor() const { return m_settings.limitRelaxationFactor; }
	/// As stock: whether the limit row was active at the last getInfo1/testLimit, and its sign (+1 at the lower stop,
	/// −1 at the upper stop, 0 when free).
	int getSolveLimit() const { return m_limitSign != 0 ? 1 : 0; }
	/// +1 at the lower stop, −1 at the upper stop, 0 when free (as stock).
	btScalar getLimitSign() const { return btScalar(m_limitSign); }
	/// Updates the limit state from the given transforms (as stock).
	void testLimit(const btTransform& transA, const btTransform& transB);

	/// The hinge angle in (−π, π], stock's convention (Q11 with stock's sign: −θ unless useReferenceFrameA).
	btScalar getHingeAngle() const;
	/// The hinge angle at the given body transforms, as getHingeAngle().
	btScalar getHingeAngle(const btTransform& transA, const btTransform& transB) const;

	// ---- Beyond btHingeConstraint -------------------------------------------------------------------------------------
	/// The multi-turn angle (rad, getHingeAngle's sign): continuous across ±π, counts whole turns (Q11). It is tracked
	/// at every solver step while a limit, servo or spring needs it, and from the first call of this function on.
	btScalar getMultiTurnAngle();
	/// The multi-turn angle as last tracked, without tracking anything (for serialization): true, and `angle` set, when
	/// the joint holds one; false when it has not tracked the angle since its last reset (then `angle` is unchanged).
	bool getTrackedMultiTurnAngle(btScalar & angle) const
	{
		if (m_multiTurnValid) angle = m_multiTurnAngle;
		return m_multiTurnValid;
	}
	/// Declares the current pose to be at multi-turn angle `angle` (must equal getHingeAngle() modulo 2π within 1e-3
	/// rad; refused otherwise).
	void setMultiTurnAngle(btScalar angle);

	/// Servo: holds targetAngle (multi-turn, rad) moving at most maxSpeed (rad/s, > 0) with at most maxTorque (N·m,
	/// ≥ 0). Replaces any other drive. One call; no per-tick update needed.
	void setServoTarget(btScalar targetAngle, btScalar maxSpeed = SIMD_INFINITY, btScalar maxTorque = SIMD_INFINITY);
	/// Spring-damper toward restAngle (rad): frequency (Hz, > 0) and damping ratio (≥ 0), integrated implicitly
	/// (unconditionally stable for the pair of bodies). Replaces any other drive.
	void setSpring(btScalar restAngle, btScalar frequencyHz, btScalar dampingRatio);
	/// Turns off whatever drive is on (velocity motor, servo or spring).
	void disableDrive();
	btQuaternionHingeDriveMode getDriveMode() const { return m_settings.driveMode; }  ///< Which drive is on.
	/// Joint friction: maximum friction torque (N·m, ≥ 0); 0 turns it off.
	void setMaxFrictionTorque(btScalar maxTorque);
	/// Joint friction's maximum torque (N·m); 0 is off.
	btScalar getMaxFrictionTorque() const { return m_settings.maxFrictionTorque; }

	/// The joint's whole configuration (a joint built from it is the same joint).
	const btQuaternionHingeSettings& getSettings() const { return m_settings; }
	/// Why the joint gives no rows, if it does not (BT_QHINGE_FAULT_NONE otherwise).
	btQuaternionHingeFault getFault() const { return m_fault; }
	/// Clears a fault and re-enables the joint (after the user repaired the bodies' state). A fault stands until this
	/// call (setEnabled(true) alone gives no rows while it stands), and a refused frame edit is checked again here:
	/// while frameInA/frameInB are still not rigid the fault stays BT_QHINGE_FAULT_FRAME_EDITED_INVALID, disabled.
	void clearFault();
	/// Rows reported by the last getInfo1 (for tests and statistics).
	int getNumRowsLastStep() const { return m_numRows; }
	/// The joint's bilateral position-level rows at the given body transforms, for post-stabilizers (MATH.md Q13,
	/// Q14) and tests: the values C (3 linear rows unless angular-only, then the 2 quaternion rows, Q4/Q9 or the
	/// swing log, Q12) and their Jacobian J = ∂C/∂(v_A, ω_A, v_B, ω_B), row r at jacobian[12 r .. 12 r + 11] in that
	/// order (world frame). Returns the row count (5, or 2 when angular-only); C and jacobian hold room for 5 rows.
	int computePositionRows(const btTransform& transA, const btTransform& transB, btScalar* C, btScalar* jacobian) const;
	/// The limit's position-level row at the given body transforms, for post-stabilizers (MATH.md Q11): returns the
	/// multi-turn angle α (rad, getHingeAngle's sign) continued from previousAngle (the angle at transforms less than
	/// half a turn away), and sets gradient to its exact derivative as a world-frame axis: α̇ = gradient·(ω_B − ω_A).
	btScalar computeAngleRow(const btTransform& transA, const btTransform& transB, btScalar previousAngle,
							 btVector3& gradient) const;
	/// computePositionRows and computeAngleRow at once, from one evaluation of the joint frames (a stabilizer that
	/// needs both on a joint with a limit): the same values, bit for bit, at about half the cost of the two calls.
	int computePositionRows(const btTransform& transA, const btTransform& transB, btScalar* C, btScalar* jacobian,
							btScalar previousAngle, btScalar& angle, btVector3& angleGradient) const;
	/// The same rows for any hinge given by its two joint frames, frameInA and frameInB (in A's and B's centre-of-mass
	/// frames, ẑ the hinge axis, as btHingeConstraint::getAFrame/getBFrame): what btQuaternionHingeStabilizer projects a
	/// btHingeConstraint or a 6-dof set up as a hinge onto. angle: θ of frame B about ẑ of frame A (Q11,
	/// useReferenceFrameA's sign), continued from previousAngle; angleGradient its derivative, as computeAngleRow's.
	static int computeFramePositionRows(const btTransform& frameInA, const btTransform& frameInB, bool angularOnly,
										const btTransform& transA, const btTransform& transB, btScalar* C,
										btScalar* jacobian, btScalar previousAngle, btScalar& angle,
										btVector3& angleGradient);
	/// The same without the angle (a hinge with no limit row: the angle's atan2 saved).
	static int computeFramePositionRows(const btTransform& frameInA, const btTransform& frameInB, bool angularOnly,
										const btTransform& transA, const btTransform& transB, btScalar* C, btScalar* jacobian);
	/// θ alone, in (−π, π]: bit for bit the angle above continued from 0, without the rows (a limit's starting angle).
	static btScalar computeFrameAngle(const btTransform& frameInA, const btTransform& frameInB, const btTransform& transA,
									  const btTransform& transB);
	/// Draws the joint: pivot frames, the hinge axis and, with a limit, its arc (within one turn).
	void debugDraw(btIDebugDraw * drawer, btScalar size = btScalar(0.3)) const;

private:
	/// The joint frames in world at one pair of body transforms: frame A's axes (rows of R_Aᵀ), both pivots, and
	/// q = a* ⊗ b (Q2); frame B's basis only enters q.
	struct Pose
	{
		btMatrix3x3 axesA;
		btVector3 pivotA;
		btVector3 pivotB;
		btQuaternion q;
		btVector3 axial;  // R_A t, the axial rows' direction before the sign σ (HingeAngle.h), once axialKnown
		bool axialKnown;
	};
	void poseAt(const btTransform& transA, const btTransform& transB, Pose& pose) const;
	static void framePoseAt(const btTransform& frameInA, const btTransform& frameInB, const btTransform& transA,
							const btTransform& transB, Pose& pose);
	/// computePositionRows and computeAngleRow at a pose already evaluated (the frame* forms: for any frame pair,
	/// computeFramePositionRows; sigma the angle's sign, userSign).
	int positionRowsAt(const Pose& pose, const btTransform& transA, const btTransform& transB, btScalar* C,
					   btScalar* jacobian) const;
	static int framePositionRowsAt(const Pose& pose, const btTransform& transA, const btTransform& transB,
								   bool angularOnly, btScalar* C, btScalar* jacobian);
	btScalar angleRowAt(const Pose& pose, btScalar previousAngle, btVector3& gradient) const;
	static btScalar frameAngleRowAt(const Pose& pose, btScalar sigma, btScalar previousAngle, btVector3& gradient);
	void initFrames(const btTransform& frameA, const btTransform& frameB, bool useReferenceFrameA);  // + initFromSettings
	void initFromSettings();
	void refuseConstruction();
	void validateFramesIfEdited();
	void rebranchForLimit();
	void updateMultiTurnAngle(btScalar rawUserAngle);
	bool needsAngle() const;
	void computeRowCount(btConstraintInfo1 * info, const btTransform& transA, const btTransform& transB);
	int fillBilateralRows(btConstraintInfo2 * info, const btTransform& transA, const btTransform& transB,
						  const Pose& pose) const;
	void decoupleRows(btConstraintInfo2 * info, int rows) const;
	void fillRows(btConstraintInfo2 * info, const btTransform& transA, const btTransform& transB,
				  const btVector3& angVelA, const btVector3& angVelB);
	btScalar rowErp(int kind, btScalar globalErp) const;
	btScalar rowCfm(int kind, btScalar globalCfm) const;

	btQuaternionHingeSettings m_settings;
	btScalar m_multiTurnAngle;    // user convention (getHingeAngle's sign), continuous
	bool m_multiTurnValid;        // m_multiTurnAngle tracks the pose
	bool m_trackAlways;           // the user asked for the multi-turn angle once
	bool m_framesMayHaveChanged;  // a non-const frame reference was handed out
	btTransform m_checkedFrameA;  // the frames as last validated: an unchanged frame needs no check
	btTransform m_checkedFrameB;
	int m_limitSign;     // +1 lower stop row, −1 upper stop row, 0 none (as stock's getLimitSign)
	bool m_limitLocked;  // the rest of the last limit test (AxisRows.h's LimitState), for the limit row
	bool m_limitSpeculative;
	btScalar m_limitDistance;
	btScalar m_limitImpactSpeed;  // the speed the last step's speculative stop row met its stop with (0: none)
	btScalar m_lastTimeStep;      // h of the last getInfo2 (0 before the first)
	int m_numRows;
	btQuaternionHingeFault m_fault;
	Pose m_pose;  // computed in getInfo1 when an angle was needed, reused by the getInfo2 that follows
	bool m_poseCached;
	bool m_limitIsOneTurn;  // the last setLimit gave a range of exactly one turn: reported by hasLimit(), never acts
	// The basis and order of the solver's bilateral rows (SolverRowBasis.h's RowBasis, and the quaternion rows before
	// the point rows): a row-space change that Gauss–Seidel converges on differently, never another constraint. Set
	// only through quathinge::SolverRowBasisAccess, an in-tree hook for the row-basis sweep (docs/ROW_BASIS.md); not
	// part of the settings, not serialized.
	int m_rowBasis = 0;
	bool m_angularRowsFirst = false;
	friend struct quathinge::SolverRowBasisAccess;
};

/// The drop-in for btHingeAccumulatedAngleConstraint, stock's hinge subclass that counts turns: the same four
/// constructors and getAccumulatedHingeAngle / setAccumulatedHingeAngle with stock's meanings. The accumulated angle
/// is the multi-turn angle (getMultiTurnAngle: getHingeAngle's sign), tracked from construction on as stock's is.
/// One difference, deliberate: stock's update starts again from the wrapped angle whenever the hinge turned more than
/// 0.3 rad since the last update (a hinge turning faster than 18 rad/s at 60 Hz loses its count); the multi-turn
/// angle follows any turn of less than π per step. As with stock, the limit is not affected by this class.
/// \code
/// btQuaternionHingeAccumulatedAngleConstraint* wheel = new btQuaternionHingeAccumulatedAngleConstraint(
///     *a, *b, btVector3(0, -1, 0), btVector3(0, 1, 0), btVector3(0, 0, 1), btVector3(0, 0, 1));
/// world->addConstraint(wheel, true);
/// std::printf("%.2f turns\n", double(wheel->getAccumulatedHingeAngle() / SIMD_2_PI));  // turns since construction
/// \endcode
/// More: docs/MIGRATING.md.
ATTRIBUTE_ALIGNED16(class)
QUATHINGE_API btQuaternionHingeAccumulatedAngleConstraint : public btQuaternionHingeConstraint
{
public:
	BT_DECLARE_ALIGNED_ALLOCATOR();

	/// Pivots and axes in A's and B's local frames, as btQuaternionHingeConstraint's.
	btQuaternionHingeAccumulatedAngleConstraint(btRigidBody & rbA, btRigidBody & rbB, const btVector3& pivotInA,
												const btVector3& pivotInB, const btVector3& axisInA,
												const btVector3& axisInB, bool useReferenceFrameA = false);
	/// Body A hinged to the world at pivotInA about axisInA.
	btQuaternionHingeAccumulatedAngleConstraint(btRigidBody & rbA, const btVector3& pivotInA, const btVector3& axisInA,
												bool useReferenceFrameA = false);
	/// Joint frames in A's and B's local frames.
	btQuaternionHingeAccumulatedAngleConstraint(btRigidBody & rbA, btRigidBody & rbB, const btTransform& rbAFrame,
												const btTransform& rbBFrame, bool useReferenceFrameA = false);
	/// Body A hinged to the world with its joint frame rbAFrame.
	btQuaternionHingeAccumulatedAngleConstraint(btRigidBody & rbA, const btTransform& rbAFrame,
												bool useReferenceFrameA = false);
	/// The equivalent of a stock hinge (btQuaternionHingeConstraint's conversion); from a
	/// btHingeAccumulatedAngleConstraint its count of turns is carried over (setAccumulatedHingeAngle).
	explicit btQuaternionHingeAccumulatedAngleConstraint(const btHingeConstraint& stock);

	/// The hinge angle with its whole turns (rad), brought up to the current pose.
	btScalar getAccumulatedHingeAngle() { return getMultiTurnAngle(); }
	/// As stock (whose next update does this to the value stored): the angle becomes the current pose's angle plus the
	/// whole turns that bring it nearest accAngle when that is within 0.3 rad of accAngle, else the current wrapped
	/// angle (getHingeAngle()). accAngle must be finite and within ±1e6 rad (refused otherwise, naming it).
	void setAccumulatedHingeAngle(btScalar accAngle);
};

/// Puts `replacement` in `world` in place of `constraint`: in its place in the world's constraint order (the order
/// Bullet's solver meets them in; every other constraint keeps its place), with the same
/// disableCollisionsBetweenLinkedBodies choice as far as the world can tell it (addConstraint(c, true) registers c
/// with its bodies). Deletes nothing. (btReplaceHingeConstraints and btQuaternionHingeWorldImporter swap through it.)
QUATHINGE_API void btSwapConstraintInWorld(btDynamicsWorld* world, btTypedConstraint* constraint,
										   btTypedConstraint* replacement);

/// Replaces every btHingeConstraint in `world` by its equivalent btQuaternionHingeConstraint (a
/// btHingeAccumulatedAngleConstraint by a btQuaternionHingeAccumulatedAngleConstraint with its count), each in the stock
/// hinge's place in the world's constraint order (the order the solver meets them in), with the same
/// disableCollisionsBetweenLinkedBodies choice as far as the world can tell it; the other constraints keep their
/// places and choices too. Returns how many it replaced. It deletes nothing: the replacements (new'd here) are the
/// caller's, appended to *added (if not null), to remove from the world and delete before the bodies go. The stock
/// hinges taken out stay alive with whoever allocated them (a btBulletWorldImporter deletes its own in
/// deleteAllData()); to get back the ones to delete, use the overload with `removedYours`.
///
///     btAlignedObjectArray<btQuaternionHingeConstraint*> added;
///     btReplaceHingeConstraints(world, &added);
QUATHINGE_API int btReplaceHingeConstraints(btDynamicsWorld* world,
											btAlignedObjectArray<btQuaternionHingeConstraint*>* added = 0);

/// As btReplaceHingeConstraints(world, added), and appends to *removedYours (if not null) the stock hinges taken out
/// that the caller must delete: every one except those listed in *ownedElsewhere (if not null), which stay with their
/// owner. A world that a btBulletWorldImporter loaded (wholly or in part): pass the importer instead, the overload in
/// quathinge/btQuaternionHingeWorldImporter.h, which lists its constraints here; its hinges are deleted once, by its
/// deleteAllData(). A world whose hinges your app allocated: ownedElsewhere null.
///
///     btAlignedObjectArray<btQuaternionHingeConstraint*> added;   // yours: remove and delete before the bodies
///     btAlignedObjectArray<btHingeConstraint*> removed;           // yours: delete after the call
///     btReplaceHingeConstraints(world, &added, &removed, nullptr);
///     for (int i = 0; i < removed.size(); ++i) delete removed[i];
QUATHINGE_API int btReplaceHingeConstraints(btDynamicsWorld* world,
											btAlignedObjectArray<btQuaternionHingeConstraint*>* added,
											btAlignedObjectArray<btHingeConstraint*>* removedYours,
											const btAlignedObjectArray<btTypedConstraint*>* ownedElsewhere);

/// Deprecated: appends every stock hinge taken out to *removedStock, whoever owns it, so that deleting them all is a
/// double free on a world a btBulletWorldImporter loaded. Use the overload with `removedYours` (and the importer, or
/// nullptr when your app allocated every hinge).
[[deprecated(
	"btReplaceHingeConstraints(world, added, removedYours, importer or nullptr): removedStock mixes the "
	"hinges you delete with an importer's")]] QUATHINGE_API int
btReplaceHingeConstraints(btDynamicsWorld* world, btAlignedObjectArray<btQuaternionHingeConstraint*>* added,
						  btAlignedObjectArray<btHingeConstraint*>* removedStock);

#endif  // BT_QUATERNION_HINGE_CONSTRAINT_H
