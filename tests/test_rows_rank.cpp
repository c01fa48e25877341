// The quaternion rows keep full strength at every hinge angle (MATH.md Q8): orthogonal to the axis, unit length
// (Q9), mutually orthogonal, rank 2 — including ±π and beyond 2π; and the sign of q changes nothing (Q3).
#include "QuaternionHingeRows.h"
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/World.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace quathinge;
using qh_test::expRotation;

namespace
{
// Row geometry on the hinge, dimensionless (dot products of unit vectors): 1e-12 in double, 1e-5 in float.
const double kGeomTol = qh_test::kDouble ? 1e-12 : 1e-5;
const btScalar kPi = SIMD_PI;
}  // namespace

TEST(QuaternionRows, FullStrengthAtEveryHingeAngle)
{
	// Sweep θ over [−3π, 3π] (±π and ±2π included exactly) with a tilted frame A.
	const btQuaternion a = expRotation(btVector3(btScalar(0.3), btScalar(-0.7), btScalar(0.2)));
	const btVector3 axis = btMatrix3x3(a).getColumn(2);
	std::vector<btScalar> angles;
	for (int i = -60; i <= 60; ++i) angles.push_back(btScalar(i) * kPi / 20);
	for (btScalar special : {-kPi, kPi, 2 * kPi, -2 * kPi}) angles.push_back(special);
	for (btScalar theta : angles)
	{
		const btQuaternion b = a * btQuaternion(btVector3(0, 0, 1), theta);
		AngularRows rows;
		computeAngularRows(a, b, rows);
		EXPECT_FALSE(rows.logForm) << theta;
		EXPECT_NEAR(rows.rowU.dot(axis), 0, kGeomTol) << theta;
		EXPECT_NEAR(rows.rowV.dot(axis), 0, kGeomTol) << theta;
		EXPECT_NEAR(rows.rowU.length(), 1, kGeomTol) << theta;  // Q9
		EXPECT_NEAR(rows.rowV.length(), 1, kGeomTol) << theta;
		EXPECT_NEAR(rows.rowU.dot(rows.rowV), 0, kGeomTol) << theta;
		EXPECT_NEAR(rows.errorU, 0, kGeomTol) << theta;  // on the hinge C = 0 (Q4)
		EXPECT_NEAR(rows.errorV, 0, kGeomTol) << theta;
	}
}

TEST(QuaternionRows, RankTwoOffTheHingeAndInTheFlippedHemisphere)
{
	// Off the hinge the Gram determinant of the Q7 rows is c² = cos²(φ/2) > 0 (QuaternionHingeRows.h); past 90° the
	// log rows take over with a unit radial row, so rank 2 holds up to and including the exact flip.
	for (double swingDeg : {1.0, 30.0, 80.0, 100.0, 150.0, 179.0, 180.0})
		for (double twist : {0.0, 1.0, 3.1})
		{
			const btQuaternion a = btQuaternion::getIdentity();
			const btQuaternion b = expRotation(btVector3(btScalar(swingDeg / qh_test::kDeg), 0, 0)) *
								   btQuaternion(btVector3(0, 0, 1), btScalar(twist));
			AngularRows rows;
			computeAngularRows(a, b, rows);
			const double gram = rows.rowU.length2() * rows.rowV.length2() - std::pow(double(rows.rowU.dot(rows.rowV)), 2);
			EXPECT_GT(gram, 0.1) << "swing " << swingDeg << " twist " << twist;
			EXPECT_EQ(rows.logForm, swingDeg > 90) << swingDeg;
		}
}

TEST(QuaternionRows, NegatedQuaternionGivesTheSameEquation)
{
	// q and −q are the same rotation (Q3): rows and errors both change sign, which is the same row for the solver.
	const btQuaternion a = expRotation(btVector3(btScalar(0.1), btScalar(0.2), btScalar(0.3)));
	for (double swingDeg : {5.0, 120.0, 180.0})
	{
		const btQuaternion b = a * expRotation(btVector3(btScalar(swingDeg / qh_test::kDeg), 0, 0)) *
							   btQuaternion(btVector3(0, 0, 1), btScalar(2.0));
		AngularRows plus, minus;
		computeAngularRows(btMatrix3x3(a), relativeQuaternion(a, b), plus);
		computeAngularRows(btMatrix3x3(a), -relativeQuaternion(a, b), minus);
		EXPECT_NEAR((plus.rowU + minus.rowU).length(), 0, kGeomTol) << swingDeg;
		EXPECT_NEAR((plus.rowV + minus.rowV).length(), 0, kGeomTol) << swingDeg;
		EXPECT_NEAR(plus.errorU + minus.errorU, 0, kGeomTol) << swingDeg;
		EXPECT_NEAR(plus.errorV + minus.errorV, 0, kGeomTol) << swingDeg;
	}
}

TEST(QuaternionRows, CrossingPiChangesNothingTheSolverSees)
{
	// A body spinning through θ = π on a world hinge, pulled sideways so the rows work: the velocity stays continuous
	// (no jump at q0 = 0), the joint stays aligned.
	qh_test::World world(qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, -10));
	btRigidBody* base = world.addBox(0, btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)), btTransform::getIdentity());
	btRigidBody* arm = world.addBox(1, btVector3(btScalar(0.5), btScalar(0.05), btScalar(0.05)),
									btTransform(btQuaternion(btVector3(0, 0, 1), kPi - btScalar(0.3)), btVector3(0, 0, 0)));
	btTransform frame = btTransform::getIdentity();
	auto* hinge = world.add(new btQuaternionHingeConstraint(*base, *arm, frame, btTransform::getIdentity()));
	arm->setAngularVelocity(btVector3(0, 0, 6));
	double maxJump = 0, maxMis = 0;
	btVector3 previous = arm->getAngularVelocity();
	for (int i = 0; i < 60; ++i)
	{
		world.step();
		maxJump = std::max(maxJump, double((arm->getAngularVelocity() - previous).length()));
		previous = arm->getAngularVelocity();
		maxMis = std::max(maxMis, qh_test::misalignmentDeg(*base, hinge->getAFrame(), *arm, hinge->getBFrame()));
	}
	std::printf("[ figures  ] crossing π: max velocity change per step %.3g rad/s, max misalignment %.3g deg\n", maxJump,
				maxMis);
	// 0.5 rad/s per step: gravity along −z torques nothing about z, so any jump would be the rows' doing.
	EXPECT_LT(maxJump, 0.5);
	EXPECT_LT(maxMis, 0.1);  // degrees
}
