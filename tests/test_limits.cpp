// Limits act on the multi-turn angle: ranges across ±π and wider than a turn hold and never flip; a hard hit is
// stopped; a motor driven into a stop is held by it; low > high is refused.
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/World.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace
{
// A wheel on a world hinge about z (no gravity torque about z): the joint under test and its body.
struct Wheel
{
	qh_test::World world{qh_test::SolverKind::SequentialImpulse, btVector3(0, -10, 0)};
	btRigidBody* base;
	btRigidBody* wheel;
	btQuaternionHingeConstraint* hinge;
	explicit Wheel(btScalar startAngle = 0)
	{
		base = world.addBox(0, btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)), btTransform::getIdentity());
		base->setCollisionFlags(base->getCollisionFlags() | btCollisionObject::CF_NO_CONTACT_RESPONSE);
		// useReferenceFrameA: getHingeAngle = +θ, the rotation of the wheel about +z
		wheel = world.addBox(1, btVector3(btScalar(0.5), btScalar(0.05), btScalar(0.05)),
							 btTransform(btQuaternion(btVector3(0, 0, 1), startAngle)));
		hinge = world.add(new btQuaternionHingeConstraint(*base, *wheel, btTransform::getIdentity(),
														  btTransform::getIdentity(), true));
	}
};
// Tolerance on staying inside a limit (rad): the stop is approached speculatively, so a crossing is at most the
// solver's residual; 0.02 rad (about 1°) leaves room for float and 10 iterations.
const double kLimitTol = 0.02;
}  // namespace

TEST(Limits, RangeAcrossPiHoldsWithoutFlipping)
{
	// [2.5, 3.8] straddles π; a wheel starting at 3.0 spun both ways stays inside and never jumps by 2π.
	Wheel w(3.0);
	w.hinge->setLimit(btScalar(2.5), btScalar(3.8));
	double lo = 1e9, hi = -1e9;
	for (double spin : {8.0, -8.0})
	{
		w.wheel->setAngularVelocity(btVector3(0, 0, btScalar(spin)));
		for (int i = 0; i < 60; ++i)
		{
			w.world.step();
			const double a = w.hinge->getMultiTurnAngle();
			lo = std::min(lo, a);
			hi = std::max(hi, a);
		}
	}
	std::printf("[ figures  ] limit [2.5, 3.8]: angle stayed in [%.4f, %.4f] rad\n", lo, hi);
	EXPECT_GT(lo, 2.5 - kLimitTol);
	EXPECT_LT(hi, 3.8 + kLimitTol);
	EXPECT_LT(hi, 2.5 + 2 * M_PI);  // never wrapped
}

TEST(Limits, RangeWiderThanATurnStopsAfterOneAndAHalfTurns)
{
	// [−3π, 3π] with a velocity motor: the wheel turns 1.5 turns and stops at the stop, each way.
	for (double direction : {1.0, -1.0})
	{
		Wheel w;
		w.hinge->setLimit(-3 * SIMD_PI, 3 * SIMD_PI);
		w.hinge->enableAngularMotor(true, btScalar(direction * 6), 50);
		w.world.step(300);
		const double a = w.hinge->getMultiTurnAngle();
		std::printf("[ figures  ] limit ±3π with motor %+g rad/s: stopped at %.4f rad\n", direction * 6, a);
		EXPECT_NEAR(a, direction * 3 * M_PI, kLimitTol);
		EXPECT_EQ(w.hinge->getSolveLimit(), 1);
		EXPECT_EQ(w.hinge->getLimitSign(), direction > 0 ? -1 : 1);  // stock: +1 at the lower stop, −1 at the upper
	}
}

TEST(Limits, HitAtTwentyRadiansPerSecondIsStopped)
{
	// A wheel at 20 rad/s into the stop at 1 rad: the overshoot is reported and bounded.
	Wheel w;
	w.hinge->setLimit(-1, 1);
	w.wheel->setAngularVelocity(btVector3(0, 0, 20));
	double peak = 0;
	for (int i = 0; i < 60; ++i)
	{
		w.world.step();
		peak = std::max(peak, double(w.hinge->getMultiTurnAngle()));
	}
	std::printf("[ figures  ] 20 rad/s into a stop at 1 rad: overshoot %.3f deg\n", (peak - 1) * qh_test::kDeg);
	EXPECT_LT(peak - 1, kLimitTol);
}

TEST(Limits, MotorDrivenIntoTheStopIsHeld)
{
	// A motor pushing toward +∞ stops at the upper limit; its impulse saturates.
	Wheel w;
	w.hinge->setLimit(btScalar(-0.5), btScalar(0.5));
	w.hinge->enableAngularMotor(true, 5, 2);
	w.world.step(120);
	EXPECT_NEAR(w.hinge->getMultiTurnAngle(), 0.5, kLimitTol);
	EXPECT_NEAR(w.wheel->getAngularVelocity().z(), 0, 0.05);
}

TEST(Limits, LowAboveHighIsRefusedAndRemoveLimitFrees)
{
	// setLimit(low > high) throws (stock would silently free the joint); removeLimit frees it.
	Wheel w;
	w.hinge->setLimit(-1, 1);
	EXPECT_THROW(w.hinge->setLimit(2, 1), std::invalid_argument);
	EXPECT_TRUE(w.hinge->hasLimit());
	EXPECT_EQ(w.hinge->getLowerLimit(), -1);
	w.hinge->removeLimit();
	EXPECT_FALSE(w.hinge->hasLimit());
	w.hinge->getMultiTurnAngle();  // without a limit the multi-turn angle is tracked from its first read on
	w.wheel->setAngularVelocity(btVector3(0, 0, 10));
	w.world.step(60);
	EXPECT_GT(w.hinge->getMultiTurnAngle(), 5.0);  // free: it spun past where the stop was
}

TEST(Limits, SolveLimitAndSignAsStock)
{
	// Free inside the range (no row beyond the speculative margin), +1 at the lower stop, −1 at the upper.
	Wheel w;
	w.hinge->setLimit(-1, 1, 1.0);  // softness 1: no speculative margin
	btTypedConstraint::btConstraintInfo1 info;
	w.hinge->getInfo1(&info);
	EXPECT_EQ(w.hinge->getSolveLimit(), 0);
	EXPECT_EQ(w.hinge->getLimitSign(), 0);
	w.wheel->setWorldTransform(btTransform(btQuaternion(btVector3(0, 0, 1), btScalar(-1.2))));
	w.hinge->getInfo1(&info);
	EXPECT_EQ(w.hinge->getSolveLimit(), 1);
	EXPECT_EQ(w.hinge->getLimitSign(), 1);
}
