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
	// q and −q are the same rotation (Q3): negating b (or q itself) negates rows and errors together, which is the
	// same row for the solver — in the Q7 form, the log form and at the exact flip.
	const btQuaternion a = expRotation(btVector3(btScalar(0.1), btScalar(0.2), btScalar(0.3)));
	for (double swingDeg : {0.0, 5.0, 89.0, 91.0, 120.0, 179.0, 180.0})
		for (double twist : {0.0, 2.0, 3.14159265358979323846, -3.0})
		{
			const btQuaternion b = a * expRotation(btVector3(btScalar(swingDeg / qh_test::kDeg), 0, 0)) *
								   btQuaternion(btVector3(0, 0, 1), btScalar(twist));
			AngularRows plus, minusB, minusQ;
			computeAngularRows(a, b, plus);
			computeAngularRows(a, -b, minusB);
			computeAngularRows(btMatrix3x3(a), -relativeQuaternion(a, b), minusQ);
			for (const AngularRows* minus : {&minusB, &minusQ})
			{
				EXPECT_NEAR((plus.rowU + minus->rowU).length(), 0, kGeomTol) << swingDeg << " " << twist;
				EXPECT_NEAR((plus.rowV + minus->rowV).length(), 0, kGeomTol) << swingDeg << " " << twist;
				EXPECT_NEAR(plus.errorU + minus->errorU, 0, kGeomTol) << swingDeg << " " << twist;
				EXPECT_NEAR(plus.errorV + minus->errorV, 0, kGeomTol) << swingDeg << " " << twist;
				EXPECT_EQ(plus.logForm, minus->logForm);
			}
			EXPECT_GT(plus.rowU.length() + plus.rowV.length(), 1);  // the rows did not vanish (the flip included)
		}
}

namespace
{
// A ball on a 0.5 m stick hinged to the world about z, gravity along −z: gravity's torque about the pivot is
// perpendicular to the hinge, so the two angular rows carry it at every step while the ball spins about the axis.
// frameTurn rotates body B's joint frame about its hinge axis: the same physical joint, with the joint angle offset.
const double kTiltDeg = 3;  // initial misalignment, degrees
struct SpinningBall
{
	qh_test::World world{qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, -10)};
	btRigidBody* ball;
	btQuaternionHingeConstraint* hinge;
	SpinningBall(btScalar startAngle, btScalar frameTurn)
	{
		btRigidBody* base = world.addBox(0, btVector3(btScalar(0.05), btScalar(0.05), btScalar(0.05)), btTransform::getIdentity());
		base->setCollisionFlags(base->getCollisionFlags() | btCollisionObject::CF_NO_CONTACT_RESPONSE);
		// a cube: its inertia is isotropic, so the solver's result cannot depend on the basis of the two rows
		const btQuaternion turn(btVector3(0, 0, 1), startAngle);
		// tilted off the hinge by kTiltDeg about the stick, so the rows' errors are not zero: a sign mismatch between
		// a row and its error would push the wrong way
		const btQuaternion tilt(btVector3(1, 0, 0), btScalar(kTiltDeg / qh_test::kDeg));
		ball = world.addBox(1, btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)),
							btTransform(turn * tilt, quatRotate(turn, btVector3(btScalar(0.5), 0, 0))));
		ball->setDamping(0, 0);
		const btTransform frameB(btQuaternion(btVector3(0, 0, 1), frameTurn), btVector3(btScalar(-0.5), 0, 0));
		hinge = world.add(new btQuaternionHingeConstraint(*base, *ball, btTransform::getIdentity(), frameB, true));
		ball->setAngularVelocity(btVector3(0, 0, 6));
		ball->setLinearVelocity(btVector3(0, 0, 6).cross(ball->getCenterOfMassPosition()));
	}
	// q = a* ⊗ b as the joint computes it (one matrix-to-quaternion conversion): its sign is Bullet's choice.
	btQuaternion relative() const
	{
		btQuaternion q;
		const btMatrix3x3 a = hinge->getRigidBodyA().getCenterOfMassTransform().getBasis() * hinge->getAFrame().getBasis();
		const btMatrix3x3 b = ball->getCenterOfMassTransform().getBasis() * hinge->getBFrame().getBasis();
		a.transposeTimes(b).getRotation(q);
		return q;
	}
};
}  // namespace

TEST(QuaternionRows, TrajectoryDoesNotDependOnTheQuaternionSign)
{
	// Started at θ = π − 0.3 and spinning through π (and on, through the places where Bullet's matrix-to-quaternion
	// conversion flips the sign of q), the ball moves exactly as the same joint whose angle is offset by π (it
	// crosses 0 instead, and its sign flips elsewhere): no jump in velocity at π or at a sign flip.
	// Agreement: both joints' row pairs span the same plane and give the same error vector Σ C_i g_i (Q3, Q8); they
	// differ only in the basis of the pair, which off the hinge is not orthonormal (Gram off-diagonal −2 q_x q_y,
	// Q7), so 10 Gauss–Seidel sweeps differ at second order in the swing: (3° / 2)² ≈ 7e-4 of the ≈ 0.6 rad/s
	// correction (erp·fps·φ), ≈ 4e-4 rad/s. A row whose sign disagreed with its error would push the wrong way by
	// that whole 0.6 rad/s.
	const double kVelocityTol = 1e-3;    // rad/s (and m/s)
	const double kPositionTol = 1e-3;    // m: the velocity bound over the 1 s run
	const double kStartAngleTol = 1e-5;  // rad: the angle the scene was built at, read back
	const double kTurnCountTol = 1e-3;   // rad: multi-turn angle against the integrated spin
	const double kAlignedDeg = 0.1;      // degrees: misalignment left after 1 s
	SpinningBall nearPi(kPi - btScalar(0.3), 0), nearZero(kPi - btScalar(0.3), kPi);
	EXPECT_NEAR(nearPi.hinge->getHingeAngle(), kPi - 0.3, kStartAngleTol);
	EXPECT_NEAR(nearZero.hinge->getHingeAngle(), -0.3, kStartAngleTol);
	nearPi.hinge->getMultiTurnAngle();  // start counting turns
	double maxDv = 0, maxDx = 0, maxMis = 0, finalMis = 0, integral = kPi - 0.3;
	int signFlipsPi = 0, signFlipsZero = 0;
	btQuaternion previousPi = nearPi.relative(), previousZero = nearZero.relative();
	for (int i = 0; i < 60; ++i)
	{
		nearPi.world.step();
		nearZero.world.step();
		integral += double(nearPi.ball->getAngularVelocity().z()) / 60;  // semi-implicit Euler: x += h·v(n+1)
		maxDv = std::max(maxDv, double((nearPi.ball->getAngularVelocity() - nearZero.ball->getAngularVelocity()).length()));
		maxDv = std::max(maxDv, double((nearPi.ball->getLinearVelocity() - nearZero.ball->getLinearVelocity()).length()));
		maxDx = std::max(maxDx, double((nearPi.ball->getCenterOfMassPosition() - nearZero.ball->getCenterOfMassPosition()).length()));
		finalMis = qh_test::misalignmentDeg(nearPi.hinge->getRigidBodyA(), nearPi.hinge->getAFrame(), *nearPi.ball,
											nearPi.hinge->getBFrame());
		maxMis = std::max(maxMis, finalMis);
		const btQuaternion qPi = nearPi.relative(), qZero = nearZero.relative();
		signFlipsPi += qPi.dot(previousPi) < 0;
		signFlipsZero += qZero.dot(previousZero) < 0;
		previousPi = qPi;
		previousZero = qZero;
	}
	std::printf(
		"[ figures  ] spin through π vs the same joint offset by π: max velocity difference %.3g, position "
		"difference %.3g m; misalignment from %g deg: max %.3g, final %.3g deg; quaternion sign flips %d and %d\n",
		maxDv, maxDx, kTiltDeg, maxMis, finalMis, signFlipsPi, signFlipsZero);
	EXPECT_GE(signFlipsPi, 1);  // the case under test happened
	EXPECT_GE(signFlipsZero, 1);
	EXPECT_LT(maxDv, kVelocityTol);
	EXPECT_LT(maxDx, kPositionTol);
	EXPECT_LE(maxMis, kTiltDeg);  // degrees: the rows pulled the axes together through π and the sign flips
	EXPECT_LT(finalMis, kAlignedDeg);
	// rad: the turn count followed the spin through π and on past 2π (the spin itself slows a little: velocity-level
	// joints lose energy, MATH.md "Beyond the rows")
	EXPECT_NEAR(nearPi.hinge->getMultiTurnAngle(), integral, kTurnCountTol);
	EXPECT_GT(integral, 2 * kPi);
}
