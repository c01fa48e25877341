// A joint to a moving kinematic body (docs/MIGRATING.md, "Every difference"). Bullet moves a kinematic body to its
// end-of-step pose before its solver runs; btQuaternionHingeConstraint measures its error at the body's pose at the
// step's start, so the joint follows the body without a lead, where stock's btHingeConstraint, measuring at the
// end-of-step pose, lets its other body run a step ahead (h·v). A pendulum hung from a kinematic body that a motion
// state moves at 1 m/s along x, float or double, 60 Hz, 10 iterations, no stabilizer.
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/World.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

using namespace qh_test;

namespace
{
const double kSpeed = 1;          // m/s, the kinematic body's along x
const double kHz = 60;            // the step rate
const double kSettle = 0.5;       // s: measured from here on (the start's transient left out)
const double kNoLeadShare = 0.1;  // the quaternion hinge's largest separation, as a share of a step's motion h·v (its
								  // swing's own drift: 4% measured)

// The largest pivot separation (m) from kSettle to 2 s of a pendulum (a 1 kg box, its pivot 0.5 m above its centre)
// hung by `quaternion` or stock's hinge from a kinematic box moved at kSpeed.
double largestSeparation(bool quaternion)
{
	World w;
	btRigidBody* anchor = w.addBox(0, btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)),
								   btTransform(btQuaternion::getIdentity(), btVector3(0, 10, 0)));
	anchor->setCollisionFlags(anchor->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
	anchor->setActivationState(DISABLE_DEACTIVATION);
	btDefaultMotionState motion(anchor->getWorldTransform());
	anchor->setMotionState(&motion);
	btRigidBody* bob = w.addBox(1, btVector3(btScalar(0.1), btScalar(0.5), btScalar(0.1)),
								btTransform(btQuaternion::getIdentity(), btVector3(0, btScalar(9.5), 0)));
	bob->setActivationState(DISABLE_DEACTIVATION);
	const btVector3 pivotA(0, 0, 0), pivotB(0, btScalar(0.5), 0), axis(0, 0, 1);
	btTransform frameA, frameB;
	if (quaternion)
	{
		auto* joint = w.add(new btQuaternionHingeConstraint(*anchor, *bob, pivotA, pivotB, axis, axis));
		frameA = joint->getAFrame();
		frameB = joint->getBFrame();
	}
	else
	{
		auto* joint = w.add(new btHingeConstraint(*anchor, *bob, pivotA, pivotB, axis, axis));
		frameA = joint->getAFrame();
		frameB = joint->getBFrame();
	}
	double largest = 0;
	const int steps = int(2 * kHz);
	for (int i = 0; i < steps; ++i)
	{
		const double t = (i + 1) / kHz;  // the step's end, where the kinematic body is put
		motion.setWorldTransform(btTransform(btQuaternion::getIdentity(), btVector3(btScalar(kSpeed * t), 10, 0)));
		w.step(1, btScalar(1 / kHz));
		if (t >= kSettle) largest = std::max(largest, separation(*anchor, frameA, *bob, frameB));
	}
	anchor->setMotionState(nullptr);
	return largest;
}
}  // namespace

TEST(KinematicPartner, TheJointFollowsAMovingKinematicBodyWithoutALead)
{
	const double lead = kSpeed / kHz;  // m: a step's motion
	const double quaternion = largestSeparation(true), stock = largestSeparation(false);
	std::printf("[kinematic partner] largest separation from %.1f s: quaternion %.3g m, stock %.3g m (h·v %.3g m)\n",
				kSettle, quaternion, stock, lead);
	EXPECT_LE(quaternion, kNoLeadShare * lead);
	EXPECT_GT(stock, 0.5 * lead) << "stock's hinge no longer runs ahead of a kinematic body: the difference is gone";
}
