// Starts with the axes flipped by 90°, 179° and exactly 180° recover below 1° within 1 s at 60 Hz (MATH.md Q12: the
// swing-logarithm rows keep a unit-strength escape direction where the bare quaternion rows vanish).
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/World.h"

#include <gtest/gtest.h>

namespace
{
const double kRecoveredDeg = 1.0;  // misalignment counted as recovered, degrees
const int kBudgetSteps = 60;      // 1 s at 60 Hz

// Two boxes, the second turned by `deg` about x; returns the time (s) after which the misalignment stays below 1°,
// or −1.
template <class Joint>
double recoveryTime(double deg, double* finalDeg)
{
	qh_test::World world(qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, 0));
	btRigidBody* a = world.addBox(1, btVector3(btScalar(0.5), btScalar(0.1), btScalar(0.2)), btTransform::getIdentity());
	btRigidBody* b = world.addBox(1, btVector3(btScalar(0.5), btScalar(0.1), btScalar(0.2)),
								  btTransform(btQuaternion(btVector3(1, 0, 0), btScalar(deg / qh_test::kDeg))));
	const btTransform f = btTransform::getIdentity();
	Joint* joint = world.add(new Joint(*a, *b, f, f));
	double recovered = -1;
	for (int i = 1; i <= 2 * kBudgetSteps; ++i)
	{
		world.step();
		const double mis = qh_test::misalignmentDeg(*a, joint->getAFrame(), *b, joint->getBFrame());
		if (mis < kRecoveredDeg && recovered < 0) recovered = i / 60.0;
		if (mis >= kRecoveredDeg) recovered = -1;
		*finalDeg = mis;
	}
	return recovered;
}
}  // namespace

TEST(FlippedStart, RecoversWithinOneSecondFromEveryStart)
{
	// 90°, 179°, exactly 180°: the quaternion hinge recovers below 1° within 1 s; stock's time is printed beside it.
	for (double deg : {90.0, 179.0, 180.0})
	{
		double finalQuat = 0, finalStock = 0;
		const double tq = recoveryTime<btQuaternionHingeConstraint>(deg, &finalQuat);
		const double ts = recoveryTime<btHingeConstraint>(deg, &finalStock);
		std::printf("[ figures  ] flipped %.0f deg: quaternion recovers in %.3f s, stock in %.3f s (-1: not within 2 s; final %.3g deg)\n",
					deg, tq, ts, finalStock);
		EXPECT_GT(tq, 0) << deg;
		EXPECT_LE(tq, 1.0) << deg;
		EXPECT_LT(finalQuat, kRecoveredDeg) << deg;
	}
}
