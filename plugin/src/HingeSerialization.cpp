// Serialization of btQuaternionHingeConstraint: the layout and its reasons are in btQuaternionHingeSerialization.h.
// Only the joint's public API is used here; the joint's serialize() overrides forward to these functions.
#include "quathinge/btQuaternionHingeSerialization.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include "HingeAngle.h"
#include "InputChecks.h"

namespace
{
// The largest solver-iteration override a file may ask for (Bullet would run every one of them, every step).
const int kMaxSolverIterationsOverride = 1000;

// SIMD_INFINITY ("never breaks", "no speed or torque cap") is FLT_MAX in a float build and DBL_MAX in a double one; the
// chunk stores it as +∞ so that each reader gets its own SIMD_INFINITY back.
double writeUnbounded(btScalar value) { return value >= SIMD_INFINITY ? HUGE_VAL : double(value); }
btScalar readUnbounded(double value) { return value == HUGE_VAL ? SIMD_INFINITY : btScalar(value); }

// The settings' real-valued and boolean fields and where the chunk keeps them (doubles and ints): one table that
// writing and reading both walk. unbounded: SIMD_INFINITY is stored as +∞ (writeUnbounded).
struct RealField
{
	btScalar btQuaternionHingeSettings::*setting;
	double btQuaternionHingeChunkData::*chunk;
	bool unbounded;
};
const RealField kRealFields[] = {
	{&btQuaternionHingeSettings::lowerLimit, &btQuaternionHingeChunkData::m_lowerLimit, false},
	{&btQuaternionHingeSettings::upperLimit, &btQuaternionHingeChunkData::m_upperLimit, false},
	{&btQuaternionHingeSettings::limitSoftness, &btQuaternionHingeChunkData::m_limitSoftness, false},
	{&btQuaternionHingeSettings::limitBiasFactor, &btQuaternionHingeChunkData::m_limitBiasFactor, false},
	{&btQuaternionHingeSettings::limitRelaxationFactor, &btQuaternionHingeChunkData::m_limitRelaxationFactor, false},
	{&btQuaternionHingeSettings::motorTargetVelocity, &btQuaternionHingeChunkData::m_motorTargetVelocity, false},
	{&btQuaternionHingeSettings::maxMotorImpulse, &btQuaternionHingeChunkData::m_maxMotorImpulse, false},
	{&btQuaternionHingeSettings::servoTargetAngle, &btQuaternionHingeChunkData::m_servoTargetAngle, false},
	{&btQuaternionHingeSettings::servoMaxSpeed, &btQuaternionHingeChunkData::m_servoMaxSpeed, true},
	{&btQuaternionHingeSettings::servoMaxTorque, &btQuaternionHingeChunkData::m_servoMaxTorque, true},
	{&btQuaternionHingeSettings::springRestAngle, &btQuaternionHingeChunkData::m_springRestAngle, false},
	{&btQuaternionHingeSettings::springFrequency, &btQuaternionHingeChunkData::m_springFrequency, false},
	{&btQuaternionHingeSettings::springDampingRatio, &btQuaternionHingeChunkData::m_springDampingRatio, false},
	{&btQuaternionHingeSettings::maxFrictionTorque, &btQuaternionHingeChunkData::m_maxFrictionTorque, false},
	{&btQuaternionHingeSettings::stopErp, &btQuaternionHingeChunkData::m_stopErp, false},
	{&btQuaternionHingeSettings::stopCfm, &btQuaternionHingeChunkData::m_stopCfm, false},
};
struct BoolField
{
	bool btQuaternionHingeSettings::*setting;
	int btQuaternionHingeChunkData::*chunk;
};
const BoolField kBoolFields[] = {
	{&btQuaternionHingeSettings::hasLimit, &btQuaternionHingeChunkData::m_hasLimit},
	{&btQuaternionHingeSettings::useFrameOffset, &btQuaternionHingeChunkData::m_useFrameOffset},
	{&btQuaternionHingeSettings::useReferenceFrameA, &btQuaternionHingeChunkData::m_useReferenceFrameA},
	{&btQuaternionHingeSettings::angularOnly, &btQuaternionHingeChunkData::m_angularOnly},
};

void writeFrame(const btTransform& frame, btTransformDoubleData& out)
{
	for (int i = 0; i < 3; ++i) frame.getBasis().getRow(i).serializeDouble(out.m_basis.m_el[i]);
	frame.getOrigin().serializeDouble(out.m_origin);
}
}  // namespace

int btQuaternionHingeSerializeBufferSize() { return int(sizeof(btHingeConstraintData)); }

void btQuaternionHingeFillChunk(const btQuaternionHingeConstraint& joint, btQuaternionHingeChunkData& data)
{
	std::memset(&data, 0, sizeof(data));
	const btQuaternionHingeSettings& s = joint.getSettings();
	std::memcpy(data.m_magic, kQuaternionHingeMagic, sizeof(data.m_magic));
	data.m_version = kQuaternionHingeChunkVersion;
	data.m_size = int(sizeof(data));
	data.m_flags = s.flags;
	data.m_driveMode = s.driveMode;
	for (const BoolField& f : kBoolFields) data.*f.chunk = s.*f.setting;
	btScalar multiTurn = 0;
	data.m_multiTurnValid = joint.getTrackedMultiTurnAngle(multiTurn);
	data.m_multiTurnAngle = multiTurn;
	data.m_isEnabled = joint.isEnabled();
	data.m_userConstraintType = joint.getUserConstraintType();
	data.m_userConstraintId = joint.getUserConstraintId();
	data.m_overrideNumSolverIterations = joint.getOverrideNumSolverIterations();
	data.m_needsFeedback = joint.needsFeedback();
	writeFrame(s.frameInA, data.m_frameInA);
	writeFrame(s.frameInB, data.m_frameInB);
	for (const RealField& f : kRealFields)
		data.*f.chunk = f.unbounded ? writeUnbounded(s.*f.setting) : double(s.*f.setting);
	for (int i = 0; i < 6; ++i)
	{
		data.m_rowErp[i] = s.rowErp[i];
		data.m_rowCfm[i] = s.rowCfm[i];
	}
	data.m_breakingImpulseThreshold = writeUnbounded(joint.getBreakingImpulseThreshold());
	data.m_dbgDrawSize = const_cast<btQuaternionHingeConstraint&>(joint).getDbgDrawSize();  // Bullet's getter is not const
}

const char* btQuaternionHingeSerialize(const btQuaternionHingeConstraint& joint, void* dataBuffer,
									   btSerializer* serializer)
{
	btHingeConstraintData* stock = static_cast<btHingeConstraintData*>(dataBuffer);
	std::memset(stock, 0, sizeof(*stock));
	const btQuaternionHingeSettings& s = joint.getSettings();

	// The joint's chunk, filled as btHingeConstraint::serialize fills it.
	joint.btTypedConstraint::serialize(&stock->m_typeConstraintData, serializer);
	stock->m_typeConstraintData.m_objectType = HINGE_CONSTRAINT_TYPE;  // stock readers build the nearest stock hinge
	s.frameInA.serialize(stock->m_rbAFrame);
	s.frameInB.serialize(stock->m_rbBFrame);
	stock->m_useReferenceFrameA = s.useReferenceFrameA;
	stock->m_angularOnly = s.angularOnly;
	stock->m_enableAngularMotor = s.driveMode == BT_QHINGE_DRIVE_VELOCITY;
	stock->m_motorTargetVelocity = s.motorTargetVelocity;
	stock->m_maxMotorImpulse = s.maxMotorImpulse;
	// stock's "no limit" is low > high
	stock->m_lowerLimit = s.hasLimit ? s.lowerLimit : btScalar(1);
	stock->m_upperLimit = s.hasLimit ? s.upperLimit : btScalar(-1);
	stock->m_limitSoftness = s.limitSoftness;
	stock->m_biasFactor = s.limitBiasFactor;
	stock->m_relaxationFactor = s.limitRelaxationFactor;

	// The QuatHinge chunk, under a key derived from the joint's own old pointer (the one finalizeChunk will give the
	// joint's chunk: getUniquePointer hands out the same pointer for the same object every time).
	void* jointOld = serializer->getUniquePointer(const_cast<btTypedConstraint*>(static_cast<const btTypedConstraint*>(&joint)));
	if (jointOld)
	{
		btChunk* chunk = serializer->allocate(sizeof(char), int(sizeof(btQuaternionHingeChunkData)));
		btQuaternionHingeChunkData data;
		btQuaternionHingeFillChunk(joint, data);
		std::memcpy(chunk->m_oldPtr, &data, sizeof(data));
		// registered under the settings' address (unique to this joint), then given the derived old pointer
		serializer->finalizeChunk(chunk, "char", BT_ARRAY_CODE, const_cast<btQuaternionHingeSettings*>(&s));
		chunk->m_oldPtr = btQuaternionHingeChunkKey(jointOld);
	}
	return btHingeConstraintDataName;
}

bool btQuaternionHingeReadSettings(const void* buffer, size_t size, btQuaternionHingeSettings& s, const char** why)
{
	const char* reason = 0;
	btQuaternionHingeChunkData data;
	std::memset(&data, 0, sizeof(data));
	if (size < sizeof(data.m_magic) + 2 * sizeof(int))
		reason = "smaller than a QuatHinge chunk header";
	else
	{
		std::memcpy(&data, buffer, sizeof(data.m_magic) + 2 * sizeof(int));
		if (std::memcmp(data.m_magic, kQuaternionHingeMagic, sizeof(data.m_magic)) != 0)
			reason = "not a QuatHinge chunk (magic mismatch)";
		else if (data.m_version != kQuaternionHingeChunkVersion)
			reason = "unknown QuatHinge chunk version";
		else if (data.m_size != int(sizeof(data)) || size < sizeof(data))
			reason = "QuatHinge chunk size does not match its version";
	}
	if (reason)
	{
		if (why) *why = reason;
		return false;
	}
	std::memcpy(&data, buffer, sizeof(data));  // copied: the chunk may sit unaligned in a file buffer
	s = btQuaternionHingeSettings();
	s.frameInA.deSerializeDouble(data.m_frameInA);
	s.frameInB.deSerializeDouble(data.m_frameInB);
	for (const BoolField& f : kBoolFields) s.*f.setting = data.*f.chunk != 0;
	for (const RealField& f : kRealFields)
		s.*f.setting = f.unbounded ? readUnbounded(data.*f.chunk) : btScalar(data.*f.chunk);
	s.driveMode = btQuaternionHingeDriveMode(data.m_driveMode);
	for (int i = 0; i < 6; ++i)
	{
		s.rowErp[i] = btScalar(data.m_rowErp[i]);
		s.rowCfm[i] = btScalar(data.m_rowCfm[i]);
	}
	s.flags = data.m_flags;
	return true;
}

btQuaternionHingeConstraint* btQuaternionHingeDeserialize(const void* buffer, size_t size, btRigidBody& rbA,
														  btRigidBody& rbB)
{
	const char* fn = "btQuaternionHingeDeserialize";
	char message[160];
	btQuaternionHingeSettings settings;
	const char* why = 0;
	if (!btQuaternionHingeReadSettings(buffer, size, settings, &why))
	{
		std::snprintf(message, sizeof(message), "data: %s", why);
		return quathinge::check::fail(fn, message), nullptr;
	}
	btQuaternionHingeChunkData data;
	std::memcpy(&data, buffer, sizeof(data));
	// btTypedConstraint's own fields from the file, checked as the joint's setters check theirs (its setters do not)
	const double threshold = data.m_breakingImpulseThreshold;
	if (!(threshold >= 0))
	{
		std::snprintf(message, sizeof(message),
					  "data: breakingImpulseThreshold (%g) must be >= 0 (SIMD_INFINITY: never breaks)", threshold);
		return quathinge::check::fail(fn, message), nullptr;
	}
	const int iterations = data.m_overrideNumSolverIterations;
	if (iterations != -1 && (iterations < 1 || iterations > kMaxSolverIterationsOverride))
	{
		std::snprintf(message, sizeof(message), "data: overrideNumSolverIterations (%d) must be -1 (none) or in [1, %d]",
					  iterations, kMaxSolverIterationsOverride);
		return quathinge::check::fail(fn, message), nullptr;
	}
	const double drawSize = data.m_dbgDrawSize;
	if (!(drawSize >= 0) || !std::isfinite(drawSize))
	{
		std::snprintf(message, sizeof(message), "data: dbgDrawSize (%g) must be finite and >= 0", drawSize);
		return quathinge::check::fail(fn, message), nullptr;
	}
	btQuaternionHingeConstraint* joint = new btQuaternionHingeConstraint(rbA, rbB, settings);
	if (joint->getFault() == BT_QHINGE_FAULT_INVALID_ARGUMENT)  // refused without exceptions (reported already)
	{
		delete joint;
		return nullptr;
	}
	joint->setBreakingImpulseThreshold(readUnbounded(threshold));
	joint->setEnabled(data.m_isEnabled != 0);
	joint->setUserConstraintType(data.m_userConstraintType);
	joint->setUserConstraintId(data.m_userConstraintId);
	joint->setOverrideNumSolverIterations(iterations);
	joint->enableFeedback(data.m_needsFeedback != 0);
	joint->setDbgDrawSize(btScalar(drawSize));
	// unless the bodies were not restored to the saved pose: the angle then restarts from the pose (setMultiTurnAngle's
	// test, asked first so that nothing is refused)
	const btScalar angle = btScalar(data.m_multiTurnAngle);
	if (data.m_multiTurnValid && std::isfinite(data.m_multiTurnAngle) && btFabs(angle) <= quathinge::check::kMaxAngle &&
		btFabs(quathinge::wrapAngle(angle - joint->getHingeAngle())) <= btScalar(1e-3))
		joint->setMultiTurnAngle(angle);
	return joint;
}
