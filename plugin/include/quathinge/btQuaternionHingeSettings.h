/** \file
The joint's configuration and the enums of its API: btQuaternionHingeSettings (a plain struct with defaults, what
btQuaternionHingeConstraint::getSettings returns and a constructor takes), the drive modes, the ERP/CFM override bits
and the reasons a joint disables itself. Included by btQuaternionHingeConstraint.h; docs/MIGRATING.md maps stock's
settings onto these.
*/
#ifndef BT_QUATERNION_HINGE_SETTINGS_H
#define BT_QUATERNION_HINGE_SETTINGS_H

#include "LinearMath/btScalar.h"
#include "LinearMath/btTransform.h"

/// How the axial drive row (at most one) behaves.
enum btQuaternionHingeDriveMode : int  // fixed type: a corrupt value in a settings struct is defined, and refused
{
	BT_QHINGE_DRIVE_OFF = 0,       ///< no drive row
	BT_QHINGE_DRIVE_VELOCITY = 1,  ///< btHingeConstraint's angular motor: target velocity, maximum impulse per step
	BT_QHINGE_DRIVE_SERVO = 2,     ///< holds a target (multi-turn) angle with a maximum speed and a maximum torque
	BT_QHINGE_DRIVE_SPRING = 3     ///< implicit spring-damper toward a rest angle, set by frequency and damping ratio
};

/// Bits of getFlags(): which per-joint ERP/CFM values override the solver's globals (btHingeFlags' meaning, extended
/// per row). Bit (BT_QHINGE_FLAGS_ERP_ROW0 << r) / (BT_QHINGE_FLAGS_CFM_ROW0 << r) is row kind r (0..5, see setParam).
enum btQuaternionHingeFlags
{
	BT_QHINGE_FLAGS_CFM_STOP = 1,       ///< same value as BT_HINGE_FLAGS_CFM_STOP
	BT_QHINGE_FLAGS_ERP_STOP = 2,       ///< same value as BT_HINGE_FLAGS_ERP_STOP
	BT_QHINGE_FLAGS_CFM_NORM = 4,       ///< same value as BT_HINGE_FLAGS_CFM_NORM: some row has its own CFM
	BT_QHINGE_FLAGS_ERP_NORM = 8,       ///< same value as BT_HINGE_FLAGS_ERP_NORM: some row has its own ERP
	BT_QHINGE_FLAGS_ERP_ROW0 = 16,      ///< row kind 0's own ERP; kind r's bit is this shifted left by r
	BT_QHINGE_FLAGS_CFM_ROW0 = 16 << 6  ///< row kind 0's own CFM; kind r's bit is this shifted left by r
};

/// Why a joint disabled itself (getFault()).
enum btQuaternionHingeFault
{
	BT_QHINGE_FAULT_NONE = 0,                  ///< no fault: the joint gives its rows
	BT_QHINGE_FAULT_NONFINITE_BODY_STATE = 1,  ///< a body's transform or velocity was NaN/Inf when the solver asked for rows
	BT_QHINGE_FAULT_NO_DYNAMIC_BODY = 2,       ///< both bodies have zero inverse mass and inertia: no row can act
	BT_QHINGE_FAULT_FRAME_EDITED_INVALID = 3,  ///< a frame edited through a non-const reference is not a rigid transform
	/// a constructor refused its arguments in a build without exceptions (btQuaternionHingeErrors.h): the joint stays
	/// disabled with no rows; clearFault() does not clear it
	BT_QHINGE_FAULT_INVALID_ARGUMENT = 4
};

/// The joint's whole configuration: a plain struct with defaults. Angles are in the getHingeAngle() convention
/// (radians; sign as btHingeConstraint's). A live joint hands its settings back (getSettings()), and a joint can be
/// built from them (btQuaternionHingeConstraint's constructor from settings), which is how serialization restores it.
/// \code
/// btQuaternionHingeSettings settings;  // frames at the centres of mass, no limit, no drive
/// settings.frameInA.setOrigin(btVector3(0, -1, 0));
/// settings.frameInB.setOrigin(btVector3(0, 1, 0));
/// settings.driveMode = BT_QHINGE_DRIVE_SPRING;  // toward springRestAngle at springFrequency (Hz)
/// world->addConstraint(new btQuaternionHingeConstraint(*a, *b, settings), true);
/// \endcode
/// More: docs/MIGRATING.md (stock's setters and these fields).
struct btQuaternionHingeSettings
{
	/// Joint frames in body A's and body B's local (centre-of-mass) frames. Origin: the pivot (m). Basis: orthonormal,
	/// right-handed; its z column is the hinge axis, x and y span the plane orthogonal to it (MATH.md, Notation).
	btTransform frameInA = btTransform::getIdentity();
	btTransform frameInB = btTransform::getIdentity();  ///< Joint frame in body B's local frame (as frameInA).
	/// btHingeConstraint's useReferenceFrameA: false makes getHingeAngle() the negative of the quaternion angle θ (Q11).
	bool useReferenceFrameA = false;
	/// Only the two angular rows (no point-to-point rows): the joint aligns axes but does not hold the pivot.
	bool angularOnly = false;
	/// Kept for btHingeConstraint source compatibility; the quaternion rows have a single exact form, so both values
	/// give the same rows (docs/MIGRATING.md).
	bool useFrameOffset = true;

	/// Limit on the multi-turn angle (rad). hasLimit: the limit acts (then lowerLimit ≤ upperLimit; the range may be
	/// wider than 2π and may straddle ±π; lowerLimit == upperLimit locks the hinge; a range of exactly 2π never acts,
	/// as stock's: setLimit leaves hasLimit false for it). Without it the values are kept as
	/// given (stock's never-limited hinge reports 1 and −1, and so do these defaults).
	bool hasLimit = false;
	btScalar lowerLimit = 1;   ///< Lower end of the limit (rad, multi-turn angle).
	btScalar upperLimit = -1;  ///< Upper end of the limit (rad, multi-turn angle).
	/// Any finite value, used within [0, 1]: the limit row is switched on speculatively once the angle is within
	/// (1 − softness)·(upper − lower)/2 of a stop; until the stop is reached it only forbids crossing it within the
	/// step. 1: row only at or past the stop. (Stock stores it and never uses it.)
	btScalar limitSoftness = btScalar(0.9f);  // stock's float literals (0.9f, 0.3f), the same bits in a double build
	/// Any value within ±1e3 (0.3 by default; stock documents it as a fraction and stores anything). Multiplies the
	/// limit row's error correction and bounce.
	btScalar limitBiasFactor = btScalar(0.3f);
	/// Any value within ±1e3: bounce on hitting a stop when > 0; restitution = bias · relaxation.
	btScalar limitRelaxationFactor = btScalar(1.0);

	/// Which drive acts along the axis: none, velocity motor, servo or spring.
	btQuaternionHingeDriveMode driveMode = BT_QHINGE_DRIVE_OFF;
	/// Velocity drive: target angular velocity (rad/s) and maximum impulse per step (N·m·s, ≥ 0), as btHingeConstraint.
	btScalar motorTargetVelocity = 0;
	btScalar maxMotorImpulse = 0;  ///< Velocity drive: maximum impulse per step (N·m·s, ≥ 0).
	/// Servo: target multi-turn angle (rad), maximum speed (rad/s, > 0), maximum torque (N·m, ≥ 0).
	btScalar servoTargetAngle = 0;
	btScalar servoMaxSpeed = SIMD_INFINITY;   ///< Servo: maximum speed (rad/s, > 0).
	btScalar servoMaxTorque = SIMD_INFINITY;  ///< Servo: maximum torque (N·m, ≥ 0).
	/// Spring: rest angle (rad), frequency (Hz, > 0), damping ratio (≥ 0; 1 is critical).
	btScalar springRestAngle = 0;
	btScalar springFrequency = 1;     ///< Spring: frequency (Hz, > 0).
	btScalar springDampingRatio = 1;  ///< Spring: damping ratio (≥ 0; 1 is critical).
	/// Joint friction: maximum friction torque (N·m, ≥ 0); 0 is off (no row).
	btScalar maxFrictionTorque = 0;

	/// Per-row ERP/CFM overrides; a row kind uses the solver's global value unless its bit is set in flags.
	/// Row kinds: 0..2 linear, 3..4 angular (quaternion), 5 axial (drive). STOP values act on the limit row.
	btScalar rowErp[6] = {0, 0, 0, 0, 0, 0};
	/// Per-row-kind CFM overrides (row kinds as rowErp), used where flags has the kind's CFM bit.
	btScalar rowCfm[6] = {0, 0, 0, 0, 0, 0};
	btScalar stopErp = 0;  ///< ERP of the limit row (setParam(BT_CONSTRAINT_STOP_ERP)), used when flags has its bit.
	btScalar stopCfm = 0;  ///< CFM of the limit row (setParam(BT_CONSTRAINT_STOP_CFM)), used when flags has its bit.
	int flags = 0;         ///< Which overrides are set: BT_QHINGE_FLAGS_* bits (as btHingeFlags for stock's).
};

#endif  // BT_QUATERNION_HINGE_SETTINGS_H
