/** \file
The serialized form of btQuaternionHingeConstraint: two chunks, so that a stock Bullet reads the file as it reads any.

btQuaternionHingeConstraint::serialize (a thin call of btQuaternionHingeSerialize below) writes
- the joint's own chunk: exactly a btHingeConstraintData (btHingeConstraintFloatData in a float build,
  btHingeConstraintDoubleData2 in a double build: stock's struct, stock's size, stock's name, object type
  HINGE_CONSTRAINT_TYPE), filled as btHingeConstraint::serialize fills it. A plain Bullet reader — the world importer,
  an old app — loads it as the closest btHingeConstraint: frames, limit (stock wraps its ends into (−π, π]), velocity
  motor, angular-only, breaking threshold, enabled, solver-iteration override, debug-draw size. It loses what stock
  cannot express: multi-turn limits, servo, spring, friction, per-row ERP/CFM.
- a second chunk, btQuaternionHingeChunkData: every setting and every btTypedConstraint field, in one layout for both
  precisions (ints and doubles), written through the serializer as an opaque byte array ("char", BT_ARRAY_CODE, as
  Bullet writes names), under the old pointer btQuaternionHingeChunkKey(joint's old pointer). Bullet's file loader
  keeps such chunks as they are and nothing in stock Bullet looks them up, so a stock reader ignores it; a QuatHinge
  reader finds it from the joint's chunk (btQuaternionHingeWorldImporter.h does this for .bullet files).
A float build's file read by a double build and the reverse: the joint chunk is read by Bullet's own converters, the
QuatHinge chunk is the same in both (values rounded to the reader's btScalar; SIMD_INFINITY — an unbreakable joint, an
uncapped servo — is stored as +∞ and read back as the reader's SIMD_INFINITY); tests/test_serialize_file.cpp loads
files written by both builds (tests/data/) in each.

\code
btDefaultSerializer serializer;
world->serialize(&serializer);  // each quaternion hinge: its stock chunk and its QuatHinge chunk
\endcode
Loading them back: btQuaternionHingeWorldImporter (btQuaternionHingeWorldImporter.h). More: docs/STABILIZER.md,
"Upgrading a world, and files".
*/
#ifndef BT_QUATERNION_HINGE_SERIALIZATION_H
#define BT_QUATERNION_HINGE_SERIALIZATION_H

#include "quathinge/btQuaternionHingeConstraint.h"

#include "BulletDynamics/ConstraintSolver/btHingeConstraint.h"
#include "LinearMath/btSerializer.h"

#include <cstddef>

/// "QHINGE" + NUL + NUL: the first bytes of a btQuaternionHingeChunkData.
const char kQuaternionHingeMagic[8] = {'Q', 'H', 'I', 'N', 'G', 'E', '\0', '\0'};
/// The layout version btQuaternionHingeSerialize writes (1 was a tail appended to the joint's chunk).
const int kQuaternionHingeChunkVersion = 2;

/// The QuatHinge chunk. Fixed types only (int, double), so float and double builds write and read the same bytes.
struct btQuaternionHingeChunkData
{
	///@{
	/// Header: kQuaternionHingeMagic, the layout version (kQuaternionHingeChunkVersion) and the writer's
	/// sizeof(btQuaternionHingeChunkData).
	char m_magic[8];
	int m_version;
	int m_size;  // sizeof(btQuaternionHingeChunkData) of the writer
	///@}
	///@{
	/// The joint's flags and switches, as btQuaternionHingeSettings has them (0 or 1; the drive mode as
	/// btQuaternionHingeDriveMode); m_multiTurnValid: whether m_multiTurnAngle was being tracked.
	int m_flags;
	int m_hasLimit;
	int m_driveMode;
	int m_useFrameOffset;
	int m_useReferenceFrameA;
	int m_angularOnly;
	int m_multiTurnValid;
	///@}
	///@{
	/// btTypedConstraint's state: enabled, user type and id, solver-iteration override, joint feedback wanted.
	int m_isEnabled;
	int m_userConstraintType;
	int m_userConstraintId;
	int m_overrideNumSolverIterations;
	int m_needsFeedback;
	///@}
	///@{
	/// The joint's settings (btQuaternionHingeSettings, same names and units): frames, limit (full range, not
	/// wrapped), motor, servo, spring, friction, ERP and CFM per row kind, the multi-turn angle, the breaking
	/// threshold and the debug-draw size.
	btTransformDoubleData m_frameInA, m_frameInB;
	double m_lowerLimit, m_upperLimit;  // full range, not wrapped
	double m_limitSoftness, m_limitBiasFactor, m_limitRelaxationFactor;
	double m_motorTargetVelocity, m_maxMotorImpulse;
	double m_servoTargetAngle, m_servoMaxSpeed, m_servoMaxTorque;
	double m_springRestAngle, m_springFrequency, m_springDampingRatio;
	double m_maxFrictionTorque;
	double m_rowErp[6], m_rowCfm[6];
	double m_stopErp, m_stopCfm;
	double m_multiTurnAngle;
	double m_breakingImpulseThreshold;
	double m_dbgDrawSize;
	///@}
};

/// The old pointer under which the QuatHinge chunk of the joint written under `jointOldPointer` (the joint chunk's
/// old pointer, as the serializer gave it) is stored: the pointer with its top bit flipped, which no pointer a
/// serializer hands out has set (unique ids are small, addresses are user-space).
inline void* btQuaternionHingeChunkKey(const void* jointOldPointer)
{
	const size_t topBit = size_t(1) << (sizeof(void*) * 8 - 1);
	return reinterpret_cast<void*>(reinterpret_cast<size_t>(jointOldPointer) ^ topBit);
}

/// Writes `joint` as described above: the btHingeConstraintData into `dataBuffer`
/// (btQuaternionHingeSerializeBufferSize() bytes) and the QuatHinge chunk through `serializer`. Returns the struct
/// name, btHingeConstraintDataName. The QuatHinge chunk is left out when the serializer gives the joint no unique
/// pointer (a skipped pointer): the file then holds the nearest stock hinge only.
QUATHINGE_API const char* btQuaternionHingeSerialize(const btQuaternionHingeConstraint& joint, void* dataBuffer,
													 btSerializer* serializer);
/// sizeof(btHingeConstraintData).
QUATHINGE_API int btQuaternionHingeSerializeBufferSize();

/// The QuatHinge chunk of a joint, as btQuaternionHingeSerialize writes it (for callers that keep it elsewhere).
QUATHINGE_API void btQuaternionHingeFillChunk(const btQuaternionHingeConstraint& joint, btQuaternionHingeChunkData& data);

/// Reads the settings from a QuatHinge chunk of `size` bytes. Returns false, and sets *why (when `why` is not null)
/// to a static message, when the chunk is smaller than the layout it claims, is not a QuatHinge chunk, or has another
/// version. Values are not checked here (btQuaternionHingeDeserialize checks them).
QUATHINGE_API bool btQuaternionHingeReadSettings(const void* data, size_t size, btQuaternionHingeSettings& settings,
												 const char** why = 0);

/// Builds the joint from a QuatHinge chunk: settings (as above) plus what btTypedConstraint keeps (breaking threshold,
/// enabled, user type and id, solver-iteration override, feedback flag, debug-draw size) and the multi-turn angle
/// (kept when the bodies stand at that angle plus whole turns). Refused (thrown as std::invalid_argument, or through
/// the error callback with null returned in a build without exceptions; "data: <field> …") on a chunk
/// btQuaternionHingeReadSettings refuses, on settings the constructor from settings refuses, or on btTypedConstraint
/// fields out of range: breaking threshold < 0 or NaN, solver-iteration override other than −1 or 1…1000 (a larger
/// one would stall the solver), debug-draw size not finite or < 0.
QUATHINGE_API btQuaternionHingeConstraint* btQuaternionHingeDeserialize(const void* data, size_t size, btRigidBody& rbA,
																		btRigidBody& rbB);

#endif
