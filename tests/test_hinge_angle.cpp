// getHingeAngle reproduces btHingeConstraint's angle (sign convention included, MATH.md Q11), and the multi-turn
// angle counts whole turns.
#include "HingeAngle.h"
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/World.h"

#include "support/Refusal.h"
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

using qh_test::expRotation;

namespace
{
// Angle agreement (rad): 1e-9 in double, 1e-5 in float (a few ulps of atan2 on unit vectors).
const double kAngleTol = qh_test::kDouble ? 1e-9 : 1e-5;
// Against a real btHingeConstraint (rad): stock computes the angle from its own (unnormalized) frame columns.
const double kStockAngleTol = qh_test::kDouble ? 1e-6 : 1e-4;
// Frame columns chosen by the constructors, compared with stock's normalized ones (dimensionless).
const double kFrameTol = qh_test::kDouble ? 1e-12 : 1e-5;
// Multi-turn angle against the integrated motor target: 1% (the motor's impulse bound lets it lag a little at start).
const double kTurnsRelTol = 0.01;  // dimensionless
// The multi-turn angle wrapped back into (−π, π] against getHingeAngle (rad): float round-off of a 63 rad value.
const double kWrapTol = 1e-4;

// Stock's formula, written out independently: atan2 of B's y axis on A's x and y axes, sign −1 unless
// useReferenceFrameA (btHingeConstraint::getHingeAngle).
double stockFormula(const btTransform& a, const btTransform& fa, const btTransform& b, const btTransform& fb, bool refA)
{
	const btVector3 x = a.getBasis() * fa.getBasis().getColumn(0);
	const btVector3 y = a.getBasis() * fa.getBasis().getColumn(1);
	const btVector3 swing = b.getBasis() * fb.getBasis().getColumn(1);
	return (refA ? -1.0 : 1.0) * std::atan2(double(swing.dot(x)), double(swing.dot(y)));
}
}  // namespace

TEST(HingeAngle, MatchesStockFormulaOverTheSweep)
{
	// On the hinge both are the rotation about the axis; over θ ∈ (−π, π) they agree for both reference frames.
	btBoxShape shape(btVector3(1, 1, 1));
	btRigidBody a(1, nullptr, &shape, btVector3(1, 1, 1)), b(1, nullptr, &shape, btVector3(1, 1, 1));
	const btTransform poseA(expRotation(btVector3(btScalar(0.4), btScalar(0.1), btScalar(-0.2))), btVector3(1, 2, 3));
	a.setWorldTransform(poseA);
	for (bool refA : {false, true})
		for (int i = -99; i <= 99; ++i)
		{
			const btScalar theta = btScalar(i) * SIMD_PI / 100;
			b.setWorldTransform(btTransform(poseA.getRotation() * btQuaternion(btVector3(0, 0, 1), theta), btVector3(0, 0, 0)));
			btTransform f = btTransform::getIdentity();
			btQuaternionHingeConstraint joint(a, b, f, f, refA);
			EXPECT_NEAR(joint.getHingeAngle(), stockFormula(a.getWorldTransform(), f, b.getWorldTransform(), f, refA),
						kAngleTol)
				<< theta;
			EXPECT_NEAR(joint.getHingeAngle(), (refA ? 1 : -1) * theta, kAngleTol) << theta;
		}
}

TEST(HingeAngle, EqualsStockThroughAllFourConstructors)
{
	// The same arguments give the same frames and so the same angle as a real btHingeConstraint.
	btBoxShape shape(btVector3(1, 1, 1));
	btRigidBody a(1, nullptr, &shape, btVector3(1, 1, 1)), b(1, nullptr, &shape, btVector3(1, 1, 1));
	a.setWorldTransform(btTransform(expRotation(btVector3(btScalar(0.2), btScalar(0.5), btScalar(0.1))), btVector3(0, 0, 0)));
	const btVector3 axisA = btVector3(btScalar(0.3), btScalar(-0.2), 1).normalized();
	const btVector3 axisB = btVector3(btScalar(-0.1), btScalar(0.4), 1).normalized();
	const btTransform frameA(expRotation(btVector3(btScalar(0.3), 0, btScalar(0.2))), btVector3(0, 1, 0));
	const btTransform frameB(expRotation(btVector3(0, btScalar(0.1), btScalar(0.9))), btVector3(0, -1, 0));
	double worstStock = 0;
	for (bool refA : {false, true})
		for (int i = 0; i < 12; ++i)
		{
			b.setWorldTransform(btTransform(expRotation(btVector3(btScalar(0.1 * i), btScalar(0.05), btScalar(0.5 * i))),
											btVector3(0, 0, 0)));
			btHingeConstraint s1(a, b, btVector3(0, 1, 0), btVector3(0, -1, 0), axisA, axisB, refA);
			btQuaternionHingeConstraint q1(a, b, btVector3(0, 1, 0), btVector3(0, -1, 0), axisA, axisB, refA);
			btHingeConstraint s2(b, btVector3(0, 1, 0), axisA, refA);
			btQuaternionHingeConstraint q2(b, btVector3(0, 1, 0), axisA, refA);
			btHingeConstraint s3(a, b, frameA, frameB, refA);
			btQuaternionHingeConstraint q3(a, b, frameA, frameB, refA);
			btHingeConstraint s4(b, frameA, refA);
			btQuaternionHingeConstraint q4(b, frameA, refA);
			// Off the hinge the two formulas differ (stock projects B's y axis, Q11 takes the twist): compare where
			// both are well defined, by the frames the constructors chose.
			for (auto pair : {std::make_pair(&s1, &q1), std::make_pair(&s2, &q2), std::make_pair(&s3, &q3),
							  std::make_pair(&s4, &q4)})
			{
				const btHingeConstraint& s = *pair.first;
				const btQuaternionHingeConstraint& q = *pair.second;
				// Same column directions (stock's first constructor leaves its x and y columns unnormalized when the
				// axis is not orthogonal to A's x axis; ours are the normalized columns, which is a rotation).
				for (int c = 0; c < 3; ++c)
				{
					EXPECT_NEAR((s.getAFrame().getBasis().getColumn(c).normalized() - q.getAFrame().getBasis().getColumn(c)).length(), 0, kFrameTol);
					EXPECT_NEAR((s.getBFrame().getBasis().getColumn(c).normalized() - q.getBFrame().getBasis().getColumn(c)).length(), 0, kFrameTol);
				}
				EXPECT_NEAR((s.getAFrame().getOrigin() - q.getAFrame().getOrigin()).length(), 0, kFrameTol);
				EXPECT_NEAR((s.getBFrame().getOrigin() - q.getBFrame().getOrigin()).length(), 0, kFrameTol);
			}
			// And with the joint's dynamic body placed on the hinge at θ, both report the same angle, for every form.
			for (auto pair : {std::make_pair(&s1, &q1), std::make_pair(&s2, &q2), std::make_pair(&s3, &q3),
							  std::make_pair(&s4, &q4)})
				for (int k = -8; k <= 8; ++k)
				{
					btQuaternionHingeConstraint& q = *pair.second;
					const btScalar theta = btScalar(k) * SIMD_PI / 8 + btScalar(0.01 * i);
					const btQuaternionHingeConstraint& frames = q;  // read the frames without a non-const reference
					qh_test::placeOnHinge(q.getRigidBodyA(), frames.getAFrame(), q.getRigidBodyB(), frames.getBFrame(), theta);
					const double difference = std::remainder(double(q.getHingeAngle()) - pair.first->getHingeAngle(), 2 * M_PI);
					EXPECT_NEAR(difference, 0, kStockAngleTol) << "θ " << theta << " refA " << refA;
					worstStock = std::max(worstStock, std::fabs(difference));
					EXPECT_NEAR(std::remainder(double(q.getHingeAngle()) - (refA ? 1 : -1) * double(theta), 2 * M_PI), 0,
								kStockAngleTol);
				}
		}
	std::printf(
		"[ figures  ] getHingeAngle vs btHingeConstraint, 4 forms x 2 reference frames x 17 angles x 12 poses: "
		"worst %.3g rad\n",
		worstStock);
}

TEST(HingeAngle, MultiTurnAngleCountsTenTurnsEachWay)
{
	// A velocity motor spins a wheel ten turns each way; the multi-turn angle follows the motor's integral.
	for (double direction : {1.0, -1.0})
	{
		qh_test::World world(qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, 0));
		btRigidBody* base = world.addBox(0, btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)), btTransform::getIdentity());
		btRigidBody* wheel = world.addBox(1, btVector3(btScalar(0.5), btScalar(0.5), btScalar(0.1)), btTransform::getIdentity());
		btTransform f = btTransform::getIdentity();
		auto* hinge = world.add(new btQuaternionHingeConstraint(*base, *wheel, f, f));
		const btScalar speed = btScalar(direction * 4 * SIMD_PI);  // 2 turns per second
		hinge->enableAngularMotor(true, speed, 1000);
		hinge->getMultiTurnAngle();  // start tracking
		world.step(300);             // 5 s: 10 turns
		const double expected = double(speed) * 5;
		std::printf("[ figures  ] multi-turn angle after 10 turns: %.4f rad (motor integral %.4f)\n",
					double(hinge->getMultiTurnAngle()), expected);
		EXPECT_NEAR(hinge->getMultiTurnAngle(), expected, kTurnsRelTol * std::fabs(expected));
		EXPECT_NEAR(quathinge::wrapAngle(hinge->getMultiTurnAngle()), hinge->getHingeAngle(), kWrapTol);
	}
}

TEST(HingeAngle, SetMultiTurnAngleAcceptsOnlyWholeTurns)
{
	// Declaring the pose to be k turns away is accepted; any other angle is refused.
	btBoxShape shape(btVector3(1, 1, 1));
	btRigidBody a(0, nullptr, &shape, btVector3(0, 0, 0)), b(1, nullptr, &shape, btVector3(1, 1, 1));
	b.setWorldTransform(btTransform(btQuaternion(btVector3(0, 0, 1), btScalar(0.7)), btVector3(0, 0, 0)));
	btTransform f = btTransform::getIdentity();
	btQuaternionHingeConstraint joint(a, b, f, f, true);
	const btScalar raw = joint.getHingeAngle();
	joint.setMultiTurnAngle(raw + 4 * SIMD_PI);
	EXPECT_NEAR(joint.getMultiTurnAngle(), raw + 4 * SIMD_PI, kWrapTol);
	EXPECT_REFUSED(joint.setMultiTurnAngle(raw + 1), "angle");
	EXPECT_NEAR(joint.getMultiTurnAngle(), raw + 4 * SIMD_PI, kWrapTol);  // unchanged after the refusal
}

TEST(HingeAngle, ReadingFramesThroughANonConstJointKeepsTheTurnCount)
{
	// getAFrame() on a non-const joint hands out a reference (as stock); only a real edit restarts the turn count.
	qh_test::World world(qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, 0));
	btRigidBody* base = world.addBox(0, btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)), btTransform::getIdentity());
	btRigidBody* wheel = world.addBox(1, btVector3(btScalar(0.5), btScalar(0.5), btScalar(0.1)), btTransform::getIdentity());
	auto* hinge = world.add(new btQuaternionHingeConstraint(*base, *wheel, btTransform::getIdentity(), btTransform::getIdentity(), true));
	hinge->enableAngularMotor(true, 6, 1000);
	hinge->getMultiTurnAngle();
	for (int i = 0; i < 120; ++i)
	{
		world.step();
		const btTransform frame = hinge->getAFrame();  // non-const overload, read only
		(void)frame;
	}
	const double kMotorLagRad = 0.05;                             // rad: the motor reaching 6 rad/s from rest in its first steps
	EXPECT_NEAR(hinge->getMultiTurnAngle(), 12.0, kMotorLagRad);  // 2 s at 6 rad/s, not wrapped
}
