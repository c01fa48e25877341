// Serialization of btQuaternionHingeConstraint: the layout and its reasons are in btQuaternionHingeSerialization.h.
#include "quathinge/btQuaternionHingeSerialization.h"

#include "LinearMath/btSerializer.h"

#include <cmath>
#include <cstring>
#include <string>
#include "HingeAngle.h"
#include "InputChecks.h"

namespace
{
// The largest solver-iteration override a file may ask for (Bullet would run every one of them, every step).
const int kMaxSolverIterationsOverride = 1000;

const int kVersion = 1;
}

int btQuaternionHingeConstraint::calculateSerializeBufferSize() const
{
	return int(sizeof(btQuaternionHingeConstraintData));
}

const char* btQuaternionHingeConstraint::serialize(void* dataBuffer, btSerializer* serializer) const
{
	btQuaternionHingeConstraintData* data = static_cast<btQuaternionHingeConstraintData*>(dataBuffer);
	std::memset(data, 0, sizeof(*data));
	const btQuaternionHingeSettings& s = m_settings;

	// The stock prefix, filled as btHingeConstraint::serialize fills it.
	btHingeConstraintData& stock = data->m_stock;
	btTypedConstraint::serialize(&stock.m_typeConstraintData, serializer);
	stock.m_typeConstraintData.m_objectType = HINGE_CONSTRAINT_TYPE;  // stock readers build the nearest stock hinge
	s.frameInA.serialize(stock.m_rbAFrame);
	s.frameInB.serialize(stock.m_rbBFrame);
	stock.m_useReferenceFrameA = s.useReferenceFrameA;
	stock.m_angularOnly = s.angularOnly;
	stock.m_enableAngularMotor = s.driveMode == BT_QHINGE_DRIVE_VELOCITY;
	stock.m_motorTargetVelocity = s.motorTargetVelocity;
	stock.m_maxMotorImpulse = s.maxMotorImpulse;
	// stock's "no limit" is low > high
	stock.m_lowerLimit = s.hasLimit ? s.lowerLimit : btScalar(1);
	stock.m_upperLimit = s.hasLimit ? s.upperLimit : btScalar(-1);
	stock.m_limitSoftness = s.limitSoftness;
	stock.m_biasFactor = s.limitBiasFactor;
	stock.m_relaxationFactor = s.limitRelaxationFactor;

	std::memcpy(data->m_magic, kQuaternionHingeMagic, sizeof(data->m_magic));
	data->m_version = kVersion;
	data->m_flags = s.flags;
	data->m_hasLimit = s.hasLimit;
	data->m_driveMode = s.driveMode;
	data->m_useFrameOffset = s.useFrameOffset;
	data->m_multiTurnValid = m_multiTurnValid;
	data->m_lowerLimit = s.lowerLimit;
	data->m_upperLimit = s.upperLimit;
	data->m_motorTargetVelocity = s.motorTargetVelocity;
	data->m_maxMotorImpulse = s.maxMotorImpulse;
	data->m_servoTargetAngle = s.servoTargetAngle;
	data->m_servoMaxSpeed = s.servoMaxSpeed;
	data->m_servoMaxTorque = s.servoMaxTorque;
	data->m_springRestAngle = s.springRestAngle;
	data->m_springFrequency = s.springFrequency;
	data->m_springDampingRatio = s.springDampingRatio;
	data->m_maxFrictionTorque = s.maxFrictionTorque;
	for (int i = 0; i < 6; ++i)
	{
		data->m_rowErp[i] = s.rowErp[i];
		data->m_rowCfm[i] = s.rowCfm[i];
	}
	data->m_stopErp = s.stopErp;
	data->m_stopCfm = s.stopCfm;
	data->m_multiTurnAngle = m_multiTurnAngle;
	return btHingeConstraintDataName;
}

bool btQuaternionHingeReadSettings(const void* buffer, size_t size, btQuaternionHingeSettings& s, std::string* why)
{
	if (size < sizeof(btQuaternionHingeConstraintData))
	{
		if (why) *why = "buffer smaller than btQuaternionHingeConstraintData (a plain btHingeConstraintData?)";
		return false;
	}
	btQuaternionHingeConstraintData data;
	std::memcpy(&data, buffer, sizeof(data));
	if (std::memcmp(data.m_magic, kQuaternionHingeMagic, sizeof(data.m_magic)) != 0)
	{
		if (why) *why = "no QuatHinge tail (magic mismatch): a stock btHingeConstraintData";
		return false;
	}
	if (data.m_version != kVersion)
	{
		if (why) *why = "unknown QuatHinge serialization version " + std::to_string(data.m_version);
		return false;
	}
	s = btQuaternionHingeSettings();
	s.frameInA.deSerialize(data.m_stock.m_rbAFrame);
	s.frameInB.deSerialize(data.m_stock.m_rbBFrame);
	s.useReferenceFrameA = data.m_stock.m_useReferenceFrameA != 0;
	s.angularOnly = data.m_stock.m_angularOnly != 0;
	s.useFrameOffset = data.m_useFrameOffset != 0;
	s.hasLimit = data.m_hasLimit != 0;
	s.lowerLimit = btScalar(data.m_lowerLimit);
	s.upperLimit = btScalar(data.m_upperLimit);
	s.limitSoftness = btScalar(data.m_stock.m_limitSoftness);
	s.limitBiasFactor = btScalar(data.m_stock.m_biasFactor);
	s.limitRelaxationFactor = btScalar(data.m_stock.m_relaxationFactor);
	s.driveMode = btQuaternionHingeDriveMode(data.m_driveMode);
	s.motorTargetVelocity = btScalar(data.m_motorTargetVelocity);
	s.maxMotorImpulse = btScalar(data.m_maxMotorImpulse);
	s.servoTargetAngle = btScalar(data.m_servoTargetAngle);
	s.servoMaxSpeed = btScalar(data.m_servoMaxSpeed);
	s.servoMaxTorque = btScalar(data.m_servoMaxTorque);
	s.springRestAngle = btScalar(data.m_springRestAngle);
	s.springFrequency = btScalar(data.m_springFrequency);
	s.springDampingRatio = btScalar(data.m_springDampingRatio);
	s.maxFrictionTorque = btScalar(data.m_maxFrictionTorque);
	for (int i = 0; i < 6; ++i)
	{
		s.rowErp[i] = btScalar(data.m_rowErp[i]);
		s.rowCfm[i] = btScalar(data.m_rowCfm[i]);
	}
	s.stopErp = btScalar(data.m_stopErp);
	s.stopCfm = btScalar(data.m_stopCfm);
	s.flags = data.m_flags;
	return true;
}

btQuaternionHingeConstraint* btQuaternionHingeDeserialize(const void* buffer, size_t size, btRigidBody& rbA,
														  btRigidBody& rbB)
{
	btQuaternionHingeSettings settings;
	std::string why;
	if (!btQuaternionHingeReadSettings(buffer, size, settings, &why))
		return quathinge::check::fail("btQuaternionHingeDeserialize", ("data: " + why).c_str()), nullptr;
	btQuaternionHingeConstraintData data;
	std::memcpy(&data, buffer, sizeof(data));
	// btTypedConstraint's own fields from the file, checked as the joint's setters check theirs (its setters do not)
	const auto& typed = data.m_stock.m_typeConstraintData;
	const double threshold = double(typed.m_breakingImpulseThreshold);
	if (!(threshold >= 0))
		return quathinge::check::fail("btQuaternionHingeDeserialize", ("data: breakingImpulseThreshold (" +
									std::to_string(threshold) + ") must be >= 0 (SIMD_INFINITY: never breaks)").c_str()), nullptr;
	const int iterations = typed.m_overrideNumSolverIterations;
	if (iterations != -1 && (iterations < 1 || iterations > kMaxSolverIterationsOverride))
		return quathinge::check::fail("btQuaternionHingeDeserialize", ("data: overrideNumSolverIterations (" +
									std::to_string(iterations) + ") must be -1 (none) or in [1, " +
									std::to_string(kMaxSolverIterationsOverride) + "]").c_str()), nullptr;
	const double drawSize = double(typed.m_dbgDrawSize);
	if (!(drawSize >= 0) || !std::isfinite(drawSize))
		return quathinge::check::fail("btQuaternionHingeDeserialize", ("data: dbgDrawSize (" + std::to_string(drawSize) +
									") must be finite and >= 0").c_str()), nullptr;
	btQuaternionHingeConstraint* joint = new btQuaternionHingeConstraint(rbA, rbB, settings);
	if (joint->getFault() == BT_QHINGE_FAULT_INVALID_ARGUMENT)  // refused without exceptions (reported already)
	{
		delete joint;
		return nullptr;
	}
	joint->setBreakingImpulseThreshold(btScalar(typed.m_breakingImpulseThreshold));
	joint->setEnabled(typed.m_isEnabled != 0);
	joint->setUserConstraintType(typed.m_userConstraintType);
	joint->setUserConstraintId(typed.m_userConstraintId);
	joint->setOverrideNumSolverIterations(typed.m_overrideNumSolverIterations);
	joint->enableFeedback(typed.m_needsFeedback != 0);
	joint->setDbgDrawSize(btScalar(typed.m_dbgDrawSize));
	// unless the bodies were not restored to the saved pose: the angle then restarts from the pose (setMultiTurnAngle's
	// test, asked first so that nothing is refused)
	if (data.m_multiTurnValid && btFabs(btScalar(data.m_multiTurnAngle)) <= quathinge::check::kMaxAngle &&
		btFabs(quathinge::wrapAngle(btScalar(data.m_multiTurnAngle) - joint->getHingeAngle())) <= btScalar(1e-3))
		joint->setMultiTurnAngle(btScalar(data.m_multiTurnAngle));
	return joint;
}
