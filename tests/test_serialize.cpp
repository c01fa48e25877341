// Serialization writes everything a reader needs: every setting round-trips field by field through the QuatHinge
// chunk, and the joint's own chunk is a stock btHingeConstraintData. Whole files: test_serialize_file.cpp.
#include "quathinge/btQuaternionHingeSerialization.h"

#include <btBulletDynamicsCommon.h>
#include "support/Refusal.h"
#include <gtest/gtest.h>

#include <cstddef>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <vector>

namespace
{
// What serialize() writes: the joint's chunk (stock's struct) and the QuatHinge chunk it hands the serializer.
struct Written
{
	std::vector<unsigned char> stock, quat;
	int quatDnaNumber = 0;
};

Written serialize(const btQuaternionHingeConstraint& joint)
{
	btDefaultSerializer serializer;
	serializer.startSerialization();
	Written w;
	w.stock.resize(size_t(joint.calculateSerializeBufferSize()));
	const char* name = joint.serialize(w.stock.data(), &serializer);
	EXPECT_STREQ(name, btHingeConstraintDataName);
	EXPECT_EQ(w.stock.size(), sizeof(btHingeConstraintData));  // exactly stock's struct: stock readers copy no more
	void* self = const_cast<btTypedConstraint*>(static_cast<const btTypedConstraint*>(&joint));
	void* key = btQuaternionHingeChunkKey(serializer.getUniquePointer(self));
	for (int i = 0; i < serializer.getNumChunks(); ++i)
	{
		const btChunk* chunk = serializer.getChunk(i);
		if (chunk->m_oldPtr != key) continue;
		const unsigned char* data = reinterpret_cast<const unsigned char*>(chunk + 1);
		w.quat.assign(data, data + chunk->m_length);
		w.quatDnaNumber = chunk->m_dna_nr;
	}
	serializer.finishSerialization();
	return w;
}
}  // namespace

TEST(Serialization, EverySettingRoundTrips)
{
	// A joint with every feature set is written and read back; each field compares equal.
	btBoxShape shape(btVector3(1, 1, 1));
	btRigidBody a(1, nullptr, &shape, btVector3(1, 1, 1)), b(1, nullptr, &shape, btVector3(1, 1, 1));
	const btTransform fa(btQuaternion(btVector3(1, 0, 0), btScalar(0.3)), btVector3(0, 1, 0));
	const btTransform fb(btQuaternion(btVector3(0, 1, 0), btScalar(0.2)), btVector3(0, -1, 0));
	btQuaternionHingeConstraint joint(a, b, fa, fb, true);
	joint.setAngularOnly(true);
	joint.setUseFrameOffset(false);
	joint.setLimit(-7, 9, btScalar(0.7), btScalar(0.2), btScalar(0.4));  // wider than 2π: stock cannot hold it
	joint.setSpring(btScalar(0.25), 3, btScalar(0.6));
	joint.setMotorTargetVelocity(btScalar(1.25));
	joint.setMaxMotorImpulse(btScalar(4.5));
	joint.setMaxFrictionTorque(btScalar(0.75));
	joint.setParam(BT_CONSTRAINT_ERP, btScalar(0.4), 3);
	joint.setParam(BT_CONSTRAINT_CFM, btScalar(0.01), 1);
	joint.setParam(BT_CONSTRAINT_STOP_ERP, btScalar(0.7));
	joint.setParam(BT_CONSTRAINT_STOP_CFM, btScalar(0.02));
	joint.setBreakingImpulseThreshold(77);
	joint.setUserConstraintType(5);
	joint.setOverrideNumSolverIterations(23);
	joint.setUserConstraintId(31);
	joint.setDbgDrawSize(btScalar(0.7));
	joint.setEnabled(false);
	b.setWorldTransform(btTransform(btQuaternion(btVector3(0, 0, 1), btScalar(0.4))));
	joint.setMultiTurnAngle(joint.getHingeAngle() - SIMD_2_PI);  // one turn down (≈ −5.9 rad), inside [−7, 9]
	const btScalar multiTurn = joint.getMultiTurnAngle();
	const Written written = serialize(joint);
	const std::vector<unsigned char>& buffer = written.quat;
	ASSERT_EQ(buffer.size(), sizeof(btQuaternionHingeChunkData));

	btQuaternionHingeSettings s;
	const char* why = "";
	ASSERT_TRUE(btQuaternionHingeReadSettings(buffer.data(), buffer.size(), s, &why)) << why;
	const btQuaternionHingeSettings& o = joint.getSettings();
	EXPECT_EQ(s.frameInA.getOrigin(), o.frameInA.getOrigin());
	EXPECT_EQ(s.frameInB.getOrigin(), o.frameInB.getOrigin());
	EXPECT_EQ(s.frameInA.getBasis(), o.frameInA.getBasis());
	EXPECT_EQ(s.frameInB.getBasis(), o.frameInB.getBasis());
	EXPECT_EQ(s.useReferenceFrameA, o.useReferenceFrameA);
	EXPECT_EQ(s.angularOnly, o.angularOnly);
	EXPECT_EQ(s.useFrameOffset, o.useFrameOffset);
	EXPECT_EQ(s.hasLimit, o.hasLimit);
	EXPECT_EQ(s.lowerLimit, o.lowerLimit);
	EXPECT_EQ(s.upperLimit, o.upperLimit);
	EXPECT_EQ(s.limitSoftness, o.limitSoftness);
	EXPECT_EQ(s.limitBiasFactor, o.limitBiasFactor);
	EXPECT_EQ(s.limitRelaxationFactor, o.limitRelaxationFactor);
	EXPECT_EQ(s.driveMode, o.driveMode);
	EXPECT_EQ(s.motorTargetVelocity, o.motorTargetVelocity);
	EXPECT_EQ(s.maxMotorImpulse, o.maxMotorImpulse);
	EXPECT_EQ(s.servoTargetAngle, o.servoTargetAngle);
	EXPECT_EQ(s.servoMaxSpeed, o.servoMaxSpeed);
	EXPECT_EQ(s.servoMaxTorque, o.servoMaxTorque);
	EXPECT_EQ(s.springRestAngle, o.springRestAngle);
	EXPECT_EQ(s.springFrequency, o.springFrequency);
	EXPECT_EQ(s.springDampingRatio, o.springDampingRatio);
	EXPECT_EQ(s.maxFrictionTorque, o.maxFrictionTorque);
	for (int i = 0; i < 6; ++i)
	{
		EXPECT_EQ(s.rowErp[i], o.rowErp[i]) << i;
		EXPECT_EQ(s.rowCfm[i], o.rowCfm[i]) << i;
	}
	EXPECT_EQ(s.stopErp, o.stopErp);
	EXPECT_EQ(s.stopCfm, o.stopCfm);
	EXPECT_EQ(s.flags, o.flags);

	// The whole joint back, including what btTypedConstraint keeps.
	std::unique_ptr<btQuaternionHingeConstraint> restored(btQuaternionHingeDeserialize(buffer.data(), buffer.size(), a, b));
	EXPECT_EQ(restored->getBreakingImpulseThreshold(), btScalar(77));
	EXPECT_EQ(restored->getUserConstraintType(), 5);
	EXPECT_EQ(restored->getOverrideNumSolverIterations(), 23);
	EXPECT_EQ(restored->getDriveMode(), BT_QHINGE_DRIVE_SPRING);
	EXPECT_EQ(restored->getParam(BT_CONSTRAINT_CFM, 1), btScalar(0.01));
	EXPECT_EQ(restored->getUserConstraintId(), 31);
	EXPECT_EQ(restored->getDbgDrawSize(), btScalar(0.7));
	EXPECT_FALSE(restored->isEnabled());
	// the turn count survives (rad; written in double, so exact in either precision)
	EXPECT_EQ(restored->getMultiTurnAngle(), multiTurn);
}

TEST(Serialization, JointChunkIsAStockHingeAndOtherBytesAreRefused)
{
	// A Bullet reader sees a btHingeConstraintData of HINGE_CONSTRAINT_TYPE; the QuatHinge chunk is an opaque byte
	// array (no DNA struct: Bullet's loader keeps it as it is); a stock chunk, a short chunk or another version is
	// refused with a static message.
	btBoxShape shape(btVector3(1, 1, 1));
	btRigidBody a(1, nullptr, &shape, btVector3(1, 1, 1)), b(1, nullptr, &shape, btVector3(1, 1, 1));
	btQuaternionHingeConstraint joint(a, b, btTransform::getIdentity(), btTransform::getIdentity());
	joint.enableAngularMotor(true, 2, 3);
	const Written written = serialize(joint);
	EXPECT_LT(written.quatDnaNumber, 0);
	btHingeConstraintData stock;
	std::memcpy(&stock, written.stock.data(), sizeof(stock));
	EXPECT_EQ(stock.m_typeConstraintData.m_objectType, int(HINGE_CONSTRAINT_TYPE));
	EXPECT_EQ(stock.m_enableAngularMotor, 1);
	EXPECT_EQ(stock.m_motorTargetVelocity, 2);
	EXPECT_GT(stock.m_lowerLimit, stock.m_upperLimit);  // stock's "no limit"
	btQuaternionHingeSettings s;
	const char* why = nullptr;
	EXPECT_FALSE(btQuaternionHingeReadSettings(written.stock.data(), written.stock.size(), s, &why));
	ASSERT_NE(why, nullptr);
	EXPECT_NE(std::strstr(why, "magic"), nullptr) << why;
	why = nullptr;
	EXPECT_FALSE(btQuaternionHingeReadSettings(written.quat.data(), written.quat.size() - 8, s, &why));
	ASSERT_NE(why, nullptr);
	EXPECT_NE(std::strstr(why, "size"), nullptr) << why;
	std::vector<unsigned char> otherVersion = written.quat;
	const int version = 1;
	std::memcpy(otherVersion.data() + offsetof(btQuaternionHingeChunkData, m_version), &version, sizeof(version));
	why = nullptr;
	EXPECT_FALSE(btQuaternionHingeReadSettings(otherVersion.data(), otherVersion.size(), s, &why));
	ASSERT_NE(why, nullptr);
	EXPECT_NE(std::strstr(why, "version"), nullptr) << why;
	EXPECT_TRUE(btQuaternionHingeReadSettings(written.quat.data(), written.quat.size(), s));  // why may be null
	EXPECT_REFUSED(delete btQuaternionHingeDeserialize(written.stock.data(), written.stock.size(), a, b), "data");
	EXPECT_REFUSED(delete btQuaternionHingeDeserialize(otherVersion.data(), otherVersion.size(), a, b), "data");
}
