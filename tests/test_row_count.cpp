// The joint reports only the rows it uses: 5 bare, 2 angular-only, +1 per active limit, drive and friction.
#include "quathinge/btQuaternionHingeConstraint.h"

#include <btBulletDynamicsCommon.h>

#include <gtest/gtest.h>

#include <cmath>

namespace
{
int rows(btQuaternionHingeConstraint& joint)
{
	btTypedConstraint::btConstraintInfo1 info;
	joint.getInfo1(&info);
	EXPECT_EQ(info.m_numConstraintRows, joint.getNumRowsLastStep());
	return info.m_numConstraintRows;
}
}  // namespace

TEST(RowCount, OnlyTheRowsInUse)
{
	// Each feature adds its row only while it is on (and the limit only near or past a stop).
	btBoxShape shape(btVector3(1, 1, 1));
	btRigidBody a(0, nullptr, &shape, btVector3(0, 0, 0)), b(1, nullptr, &shape, btVector3(1, 1, 1));
	btQuaternionHingeConstraint joint(a, b, btTransform::getIdentity(), btTransform::getIdentity());
	EXPECT_EQ(rows(joint), 5);
	joint.setAngularOnly(true);
	EXPECT_EQ(rows(joint), 2);
	joint.setAngularOnly(false);
	joint.setLimit(-2, 2);  // far from both stops (margin 0.2 rad)
	EXPECT_EQ(rows(joint), 5);
	joint.setLimit(btScalar(0.05), 2);  // past the lower stop
	EXPECT_EQ(rows(joint), 6);
	joint.removeLimit();
	joint.enableAngularMotor(true, 1, 1);
	EXPECT_EQ(rows(joint), 6);
	joint.enableAngularMotor(true, 1, 0);  // a motor with no impulse does nothing: no row
	EXPECT_EQ(rows(joint), 5);
	joint.setServoTarget(1, 2, 3);
	EXPECT_EQ(rows(joint), 6);
	joint.setSpring(0, 1, btScalar(0.5));
	EXPECT_EQ(rows(joint), 6);
	joint.setMaxFrictionTorque(1);
	EXPECT_EQ(rows(joint), 7);
	joint.setLimit(btScalar(0.05), 2);
	EXPECT_EQ(rows(joint), 8);
	joint.disableDrive();
	joint.setMaxFrictionTorque(0);
	joint.removeLimit();
	EXPECT_EQ(rows(joint), 5);
	// angular-only: the same axial rows on top of the 2 quaternion rows
	joint.setAngularOnly(true);
	joint.enableAngularMotor(true, 1, 1);
	EXPECT_EQ(rows(joint), 3);
	joint.setMaxFrictionTorque(1);
	EXPECT_EQ(rows(joint), 4);
	joint.setLimit(btScalar(0.05), 2);
	EXPECT_EQ(rows(joint), 5);
	joint.enableAngularMotor(false, 0, 0);  // stock's way to turn the motor off
	EXPECT_EQ(rows(joint), 4);
}

TEST(RowCount, LimitRowOnlyNearAStop)
{
	// Softness 0.9 on [−2, 2]: the row is off in the middle, on within 0.2 rad of a stop and past it; locked
	// (low == high) it is always on.
	btBoxShape shape(btVector3(1, 1, 1));
	btRigidBody a(0, nullptr, &shape, btVector3(0, 0, 0)), b(1, nullptr, &shape, btVector3(1, 1, 1));
	btQuaternionHingeConstraint joint(a, b, btTransform::getIdentity(), btTransform::getIdentity(), true);
	joint.setLimit(-2, 2);
	// (steps below π between calls: the multi-turn angle follows the pose only so, Q11)
	for (double angle : {0.0, 1.5, 1.9, 2.1, 1.5, 0.0, -1.5, -1.9, -2.1, -1.5, 0.0})
	{
		b.setCenterOfMassTransform(btTransform(btQuaternion(btVector3(0, 0, 1), btScalar(angle))));
		EXPECT_EQ(rows(joint), std::fabs(angle) > 1.8 ? 6 : 5) << angle;
	}
	joint.setLimit(btScalar(0.3), btScalar(0.3));
	EXPECT_EQ(rows(joint), 6);
}
