/*
The serialized form of btQuaternionHingeConstraint.

btQuaternionHingeConstraint::serialize writes one btQuaternionHingeConstraintData:
- `m_stock`: a complete btHingeConstraintData (object type HINGE_CONSTRAINT_TYPE), so any Bullet reader — the
  world importer, an old app — loads the joint as the closest stock btHingeConstraint (it loses what stock cannot
  express: multi-turn limits, servo, spring, friction, per-row ERP/CFM);
- then a tail, identified by kQuaternionHingeMagic and a version, with every other setting in double precision (so a
  file written by a float build restores in a double build and back), and the multi-turn angle.
The serializer's struct name is stock's (btHingeConstraintDataName), so Bullet's DNA describes the prefix; the tail is
read from the raw chunk with btQuaternionHingeReadSettings.
*/
#ifndef BT_QUATERNION_HINGE_SERIALIZATION_H
#define BT_QUATERNION_HINGE_SERIALIZATION_H

#include "quathinge/btQuaternionHingeConstraint.h"

#include "BulletDynamics/ConstraintSolver/btHingeConstraint.h"

#include <cstddef>
#include <string>

/// "QHINGE" + version byte 1 + NUL.
const char kQuaternionHingeMagic[8] = {'Q', 'H', 'I', 'N', 'G', 'E', '\1', '\0'};

struct btQuaternionHingeConstraintData
{
	btHingeConstraintData m_stock;
	char m_magic[8];
	int m_version;
	int m_flags;
	int m_hasLimit;
	int m_driveMode;
	int m_useFrameOffset;
	int m_multiTurnValid;
	double m_lowerLimit, m_upperLimit;  // full precision, not wrapped
	double m_motorTargetVelocity, m_maxMotorImpulse;
	double m_servoTargetAngle, m_servoMaxSpeed, m_servoMaxTorque;
	double m_springRestAngle, m_springFrequency, m_springDampingRatio;
	double m_maxFrictionTorque;
	double m_rowErp[6], m_rowCfm[6];
	double m_stopErp, m_stopCfm;
	double m_multiTurnAngle;
};

/// Reads the settings back from a serialized buffer of `size` bytes. Returns false (and says why in *why) when the
/// buffer is too small, is a plain btHingeConstraintData without the tail, or has an unknown version.
QUATHINGE_API bool btQuaternionHingeReadSettings(const void* data, size_t size, btQuaternionHingeSettings& settings,
								   std::string* why = 0);

/// Builds the joint from a serialized buffer: settings (as above) plus what btTypedConstraint keeps (breaking
/// threshold, enabled, user type and id, solver-iteration override, feedback flag, debug-draw size) and the
/// multi-turn angle. Throws std::invalid_argument on a buffer btQuaternionHingeReadSettings refuses, or whose
/// btTypedConstraint fields are out of range: breaking threshold < 0 or NaN, solver-iteration override other than −1
/// or 1…1000 (a larger one would stall the solver), debug-draw size not finite or < 0.
QUATHINGE_API btQuaternionHingeConstraint* btQuaternionHingeDeserialize(const void* data, size_t size, btRigidBody& rbA,
														  btRigidBody& rbB);

#endif
