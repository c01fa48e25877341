// Limits act on the multi-turn angle: ranges across ±π and wider than a turn hold and never flip; a hard hit is
// stopped; a motor driven into a stop is held by it; low > high is refused.
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/World.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

namespace
{
// A solver that records, after each solve, every joint row's accumulated impulse and bounds (the rows' own view of
// what the solver did: which row saturated, which held).
struct RowRecord
{
	btScalar impulse, lower, upper;
};
struct RecordingSolver : btSequentialImpulseConstraintSolver
{
	std::vector<RowRecord> rows;
	btScalar solveGroupCacheFriendlyFinish(btCollisionObject** bodies, int numBodies,
										   const btContactSolverInfo& info) override
	{
		rows.clear();
		for (int i = 0; i < m_tmpSolverNonContactConstraintPool.size(); ++i)
		{
			const btSolverConstraint& c = m_tmpSolverNonContactConstraintPool[i];
			rows.push_back({btScalar(c.m_appliedImpulse), c.m_lowerLimit, c.m_upperLimit});
		}
		return btSequentialImpulseConstraintSolver::solveGroupCacheFriendlyFinish(bodies, numBodies, info);
	}
};

// A wheel on a world hinge about z (no gravity torque about z): the joint under test and its body.
struct Wheel
{
	qh_test::World world;
	btRigidBody* base;
	btRigidBody* wheel;
	btQuaternionHingeConstraint* hinge;
	explicit Wheel(btScalar startAngle = 0, std::unique_ptr<btConstraintSolver> solver = nullptr)
		: world(solver ? std::move(solver) : std::unique_ptr<btConstraintSolver>(new btSequentialImpulseConstraintSolver),
				btVector3(0, -10, 0))
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
// A wheel held at a stop: residual angular velocity (rad/s), a few steps' worth of the solver's leftover.
const double kHeldVelocityTol = 0.05;
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
	std::printf("[ figures  ] 20 rad/s into a stop at 1 rad: overshoot %.3g deg\n", (peak - 1) * qh_test::kDeg);
	EXPECT_LT(peak - 1, kLimitTol);
}

TEST(Limits, MotorDrivenIntoTheStopIsHeld)
{
	// A motor pushing toward +∞ stops at the upper limit and stays there; its row saturates at +maxImpulse while the
	// limit row takes the opposite impulse.
	const btScalar kMaxImpulse = 2;                             // N·m·s per step
	const double kImpulseTol = qh_test::kDouble ? 1e-9 : 1e-4;  // N·m·s: converged, up to round-off
	auto* recorder = new RecordingSolver;
	Wheel w(0, std::unique_ptr<btConstraintSolver>(recorder));
	w.hinge->setLimit(btScalar(-0.5), btScalar(0.5));
	w.hinge->enableAngularMotor(true, 5, kMaxImpulse);
	double lowest = 1e9;
	for (int i = 0; i < 120; ++i)
	{
		w.world.step();
		if (i >= 60) lowest = std::min(lowest, double(w.hinge->getMultiTurnAngle()));  // after it arrived
	}
	EXPECT_NEAR(w.hinge->getMultiTurnAngle(), 0.5, kLimitTol);
	EXPECT_GT(lowest, 0.5 - kLimitTol);  // stayed at the stop, no chatter away from it
	EXPECT_NEAR(w.wheel->getAngularVelocity().z(), 0, kHeldVelocityTol);
	EXPECT_EQ(w.hinge->getLimitSign(), -1);
	// rows of the last solve: 5 bilateral, the motor (bounds ±kMaxImpulse), the upper stop (bounds (−∞, 0])
	ASSERT_EQ(recorder->rows.size(), 7u);
	const RowRecord& motor = recorder->rows[5];
	const RowRecord& stop = recorder->rows[6];
	EXPECT_EQ(motor.upper, kMaxImpulse);
	EXPECT_EQ(motor.lower, -kMaxImpulse);
	EXPECT_EQ(stop.upper, 0);
	std::printf("[ figures  ] motor into the stop: motor impulse %.6g (bound %g), stop impulse %.6g N·m·s\n",
				double(motor.impulse), double(kMaxImpulse), double(stop.impulse));
	EXPECT_NEAR(motor.impulse, kMaxImpulse, kImpulseTol);  // saturated
	EXPECT_NEAR(stop.impulse, -kMaxImpulse, kImpulseTol);  // the stop holds it
}

TEST(Limits, LowAboveHighFreesAsStockAndRemoveLimitFrees)
{
	// setLimit(low > high) frees the joint, as stock (btAngularLimit's negative half range never acts), keeping the
	// values it was given; removeLimit frees it as well.
	for (bool viaRemove : {false, true})
	{
		Wheel w;
		w.hinge->setLimit(-1, 1);
		EXPECT_TRUE(w.hinge->hasLimit());
		if (viaRemove) w.hinge->removeLimit();
		else w.hinge->setLimit(2, 1);
		EXPECT_FALSE(w.hinge->hasLimit());
		EXPECT_EQ(w.hinge->getLowerLimit(), viaRemove ? -1 : 2);
		EXPECT_EQ(w.hinge->getUpperLimit(), 1);
		w.hinge->getMultiTurnAngle();  // without a limit the multi-turn angle is tracked from its first read on
		w.wheel->setAngularVelocity(btVector3(0, 0, 10));
		w.world.step(60);
		EXPECT_GT(w.hinge->getMultiTurnAngle(), 5.0);  // free: it spun past where the stop was
	}
}

TEST(Limits, SolveLimitAndSignAsStock)
{
	// Free inside the range (softness 1: no speculative margin), +1 at or past the lower stop, −1 at or past the upper.
	Wheel w;
	w.hinge->setLimit(-1, 1, 1.0);
	btTypedConstraint::btConstraintInfo1 info;
	const struct
	{
		double angle;
		int solve;
		int sign;
	} cases[] = {{0.0, 0, 0}, {0.9, 0, 0}, {-0.9, 0, 0}, {-1.2, 1, 1}, {1.2, 1, -1}, {0.0, 0, 0}};
	for (const auto& c : cases)
	{
		w.wheel->setCenterOfMassTransform(btTransform(btQuaternion(btVector3(0, 0, 1), btScalar(c.angle))));
		w.hinge->getInfo1(&info);
		EXPECT_EQ(w.hinge->getSolveLimit(), c.solve) << c.angle;
		EXPECT_EQ(w.hinge->getLimitSign(), c.sign) << c.angle;
		EXPECT_EQ(info.m_numConstraintRows, 5 + c.solve) << c.angle;
	}
	w.hinge->removeLimit();
	w.wheel->setCenterOfMassTransform(btTransform(btQuaternion(btVector3(0, 0, 1), btScalar(1.2))));
	w.hinge->getInfo1(&info);
	EXPECT_EQ(w.hinge->getSolveLimit(), 0);
	EXPECT_EQ(w.hinge->getLimitSign(), 0);
}
