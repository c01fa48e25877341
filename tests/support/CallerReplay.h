// Real callers as tests (issue 17, item 6): one caller's calls, replayed on btHingeConstraint and on
// btQuaternionHingeConstraint, each in a scene of its own built by the same code. The replay is a generic lambda taking
// a null pointer whose pointee type is the hinge class (`using Hinge = qh_test::HingeOf<decltype(tag)>;`); it returns
// what the caller reads back and how the scene moved, and replayOnBoth returns that for both classes.
#ifndef QUATHINGE_TESTS_CALLER_REPLAY_H
#define QUATHINGE_TESTS_CALLER_REPLAY_H

#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/Refusal.h"
#include "support/World.h"

#include "BulletDynamics/ConstraintSolver/btHingeConstraint.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <type_traits>
#include <vector>

namespace qh_test
{
/// Same motion (rad, at every step) for the caller-pattern tests: both classes hold the same joint with differently
/// formed rows; over a few seconds their residuals differ by round-off-sized amounts that the dynamics amplify near
/// stops and motors.
const double kSameMotionTol = 0.01;

/// The hinge class a replay runs on, from its tag.
template <class Tag>
using HingeOf = typename std::remove_pointer<typename std::decay<Tag>::type>::type;

/// What a replay reports: what the caller read back (in the order it read it) and the motion.
struct CallerRun
{
	std::vector<double> reads;   // getter values the caller uses, in order
	std::vector<double> angles;  // getHingeAngle() after every step (rad)
	double maxSeparation = 0;    // largest distance between the world pivots over the steps (m)
	bool finite = true;          // every body's state stayed finite
	std::vector<double> extra;   // values that differ by design or exist on one class only (not compared)
};

template <class Result>
struct Replayed
{
	Result stock;
	Result quat;
};

/// Runs `replay` on both classes. Every call a caller makes is one stock accepts, so it must be accepted here too:
/// nothing thrown (with exceptions) and nothing reported through the error callback (without them).
template <class Replay>
auto replayOnBoth(Replay&& replay) -> Replayed<decltype(replay(static_cast<btHingeConstraint*>(nullptr)))>
{
	Replayed<decltype(replay(static_cast<btHingeConstraint*>(nullptr)))> r{};
	EXPECT_TRUE(accepted([&] { r.stock = replay(static_cast<btHingeConstraint*>(nullptr)); })) << "btHingeConstraint";
	EXPECT_TRUE(accepted([&] { r.quat = replay(static_cast<btQuaternionHingeConstraint*>(nullptr)); }))
		<< "btQuaternionHingeConstraint";
	return r;
}

/// Steps `world` `steps` times (dt, iterations as World::step), calling `beforeStep(i)` first when given, and records
/// the hinge's angle, the pivot separation and finiteness into `run`.
template <class Hinge>
void record(CallerRun& run, World& world, Hinge& hinge, int steps, const std::function<void(int)>& beforeStep = {},
			btScalar dt = btScalar(1) / 60, int iterations = 10)
{
	for (int i = 0; i < steps; ++i)
	{
		if (beforeStep) beforeStep(i);
		world.step(1, dt, iterations);
		run.angles.push_back(double(hinge.getHingeAngle()));
		const double sep = separation(hinge.getRigidBodyA(), hinge.getAFrame(), hinge.getRigidBodyB(), hinge.getBFrame());
		if (sep > run.maxSeparation) run.maxSeparation = sep;
		run.finite = run.finite && finiteState(hinge.getRigidBodyA()) && finiteState(hinge.getRigidBodyB());
	}
}

/// a − b wrapped into (−π, π] (rad).
inline double angleDiff(double a, double b) { return std::remainder(a - b, 2 * 3.14159265358979323846); }

/// The last angle of a trace continued across ±π (rad): how far the joint turned in all.
double unwrapped(const std::vector<double>& angles);

/// Largest |angleDiff| between two angle traces of the same length (rad).
double maxAngleDiff(const std::vector<double>& a, const std::vector<double>& b);

/// Expects both runs finite, the same reads (within `readTol`, exact when 0) and the same angle trace within
/// `angleTol` (rad); prints the figures under `name`.
void expectSameRun(const char* name, const CallerRun& stock, const CallerRun& quat, double angleTol,
				   double readTol = 0);
}  // namespace qh_test

#endif
