// Drives: the servo reaches and holds a multi-turn target within its speed; the spring is implicit Euler, step for
// step; friction stops a spinning body in the time its torque predicts.
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/World.h"

#include <gtest/gtest.h>

#include <cmath>

namespace
{
struct Wheel
{
	qh_test::World world{qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, 0)};
	btRigidBody* base;
	btRigidBody* wheel;
	btQuaternionHingeConstraint* hinge;
	Wheel()
	{
		base = world.addBox(0, btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)), btTransform::getIdentity());
		base->setCollisionFlags(base->getCollisionFlags() | btCollisionObject::CF_NO_CONTACT_RESPONSE);
		wheel = world.addBox(2, btVector3(btScalar(0.5), btScalar(0.3), btScalar(0.05)), btTransform::getIdentity());
		wheel->setDamping(0, 0);
		hinge = world.add(new btQuaternionHingeConstraint(*base, *wheel, btTransform::getIdentity(),
														  btTransform::getIdentity(), true));
	}
	double inertiaZ() const { return 1.0 / double(wheel->getInvInertiaDiagLocal().z()); }
};
}  // namespace

TEST(Drives, ServoReachesAMultiTurnTargetAndHoldsIt)
{
	// Target 4π (two turns) at most 3 rad/s: reached after ≈ 4π/3 s, never faster than 3 rad/s, then held.
	Wheel w;
	w.hinge->setServoTarget(4 * SIMD_PI, 3, 100);
	double fastest = 0;
	for (int i = 0; i < 300; ++i)
	{
		w.world.step();
		fastest = std::max(fastest, std::fabs(double(w.wheel->getAngularVelocity().z())));
	}
	std::printf("[ figures  ] servo to 4π: final %.5f rad, fastest %.4f rad/s\n", double(w.hinge->getMultiTurnAngle()), fastest);
	const double kHoldTol = 1e-3;   // rad: at the target (float round-off of 12.6 rad is 1e-6)
	const double kSpeedTol = 1e-3;  // rad/s: over the speed limit
	EXPECT_NEAR(w.hinge->getMultiTurnAngle(), 4 * M_PI, kHoldTol);
	EXPECT_LT(fastest, 3 + kSpeedTol);
	w.wheel->applyTorqueImpulse(btVector3(0, 0, btScalar(0.5)));  // a knock: it returns
	w.world.step(60);
	EXPECT_NEAR(w.hinge->getMultiTurnAngle(), 4 * M_PI, kHoldTol);
}

TEST(Drives, SpringIsImplicitEulerStepByStep)
{
	// One body on a world hinge, no gravity: the joint's spring must reproduce, step by step, the implicit Euler
	// update θₙ₊₁ = θₙ + h vₙ₊₁, vₙ₊₁ = (vₙ − h ω² (θₙ − rest)) / (1 + 2ζωh + h²ω²), ω = 2πf.
	// Tolerance: 0.1° is the bound; the joint claims exact agreement up to round-off (1e-4 rad in float).
	const double kStepTol = qh_test::kDouble ? 1e-9 : 1e-4;  // rad
	Wheel w;
	const double f = 2, zeta = 0.1, rest = 0.5, h = 1.0 / 60;
	w.hinge->setSpring(btScalar(rest), btScalar(f), btScalar(zeta));
	const double omega = 2 * M_PI * f;
	double theta = 0, v = 0, worst = 0;
	for (int i = 0; i < 240; ++i)
	{
		v = (v - h * omega * omega * (theta - rest)) / (1 + 2 * zeta * omega * h + h * h * omega * omega);
		theta += h * v;
		w.world.step(1, btScalar(h), 10);
		worst = std::max(worst, std::fabs(double(w.hinge->getMultiTurnAngle()) - theta));
	}
	std::printf("[ figures  ] spring vs implicit Euler over 240 steps: worst %.3g rad (%.3g deg)\n", worst, worst * qh_test::kDeg);
	EXPECT_LT(worst, kStepTol);
	EXPECT_LT(worst * qh_test::kDeg, 0.1);
}

TEST(Drives, FrictionStopsASpinningBodyInThePredictedTime)
{
	// Coulomb friction torque T on inertia I spinning at ω₀ stops it after I ω₀ / T (within 5%).
	Wheel w;
	const double torque = 0.2, omega0 = 4;
	const double kStoppedRadPerSec = 1e-3;  // rad/s: counted as stopped
	const double kTimeRelTol = 0.05;        // dimensionless: 5%, as specified
	w.hinge->setMaxFrictionTorque(btScalar(torque));
	w.wheel->setAngularVelocity(btVector3(0, 0, btScalar(omega0)));
	const double expected = w.inertiaZ() * omega0 / torque;
	double stopped = -1;
	for (int i = 1; i <= 600 && stopped < 0; ++i)
	{
		w.world.step();
		if (std::fabs(double(w.wheel->getAngularVelocity().z())) < kStoppedRadPerSec) stopped = i / 60.0;
	}
	std::printf("[ figures  ] friction stop: %.4f s (predicted %.4f s)\n", stopped, expected);
	EXPECT_NEAR(stopped, expected, kTimeRelTol * expected);
}

TEST(Drives, VelocityMotorReachesItsSpeedWithinItsImpulse)
{
	// btHingeConstraint's motor: the wheel reaches the target velocity, accelerating at most maxImpulse per step.
	Wheel w;
	w.hinge->enableAngularMotor(true, 2, btScalar(0.01));
	w.world.step(1);
	const double dv = double(w.wheel->getAngularVelocity().z());
	const double kVelocityTol = 1e-4;  // rad/s: float round-off of one impulse / inertia
	EXPECT_NEAR(dv, 0.01 / w.inertiaZ(), kVelocityTol);
	w.world.step(600);
	const double kTargetTol = 1e-3;  // rad/s: at its target speed
	EXPECT_NEAR(w.wheel->getAngularVelocity().z(), 2, kTargetTol);
}
