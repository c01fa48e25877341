// Issue 16: where the bare quaternion hinge separates more than stock in a free run, is it the rows or the trajectory?
// MatchedStates (demos/scenes/MatchedStates.h) steps both kinds from the same states. On Gazebo's inertia-ratio world
// the free runs part after 1.5 s: the quaternion hinge keeps the links in plane and keeps more of the energy, and at
// 2.47 s the light link whips at 32 rad/s, where its elbow separates most (1.8e-3 m at 50 iterations, 2.1× stock's
// largest). Stock's rows stepped from those same states separate as much; and Bullet's reduced-coordinate btMultiBody,
// which has no joint error to drift, makes the same whip at the same time: that motion is the scene's, stock's run
// misses it (docs/ROW_BASIS.md, "Matched states").
#ifdef QUATHINGE_HAVE_SCENES
#include "JointKinds.h"
#include "MatchedStates.h"
#include "SceneSpec.h"
#include "Simulation.h"
#include "SolverRowBasis.h"

#include "quathinge/btQuaternionHingeConstraint.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace quathinge::scenes;

namespace
{
// The bound of issue 16: the quaternion rows within this factor of stock's.
const double kBound = 1.2;

double separationRatio(const MatchedRun& run, bool stockLeads)
{
	const JointErrorStats& stock = stockLeads ? run.leader : run.follower;
	const JointErrorStats& quaternion = stockLeads ? run.follower : run.leader;
	return quaternion.maxSeparation / stock.maxSeparation;
}

struct Whip
{
	double rate = 0;  // rad/s: the light link's largest angular speed over the run
	double time = 0;  // s: when
};

Whip lightLinkWhip(const SceneSpec& scene, Kind kind, int iterations)
{
	Simulation sim(scene, kind);
	Whip whip;
	const int steps = int(std::lround(scene.duration / scene.dt));
	for (int i = 1; i <= steps; ++i)
	{
		sim.step(scene.dt, iterations);
		const double rate = double(sim.bodies[0]->getAngularVelocity().length());  // bodies[0]: the thin link
		if (rate > whip.rate) whip = {rate, i * scene.dt};
	}
	return whip;
}
}  // namespace

TEST(MatchedStates, OnGazebosWorldTheRowsSeparateAsStocksFromTheSameStates)
{
	const SceneSpec scene = makeScene("inertia_ratio");
	for (int iterations : {50, 100})
		for (bool stockLeads : {true, false})
		{
			const MatchedRun run = stockLeads
									   ? runMatched(scene, Kind::Stock, Kind::Quaternion, scene.dt, iterations, -1)
									   : runMatched(scene, Kind::Quaternion, Kind::Stock, scene.dt, iterations, -1);
			ASSERT_TRUE(run.skipped.empty()) << run.skipped;
			ASSERT_FALSE(run.blewUp);
			ASSERT_EQ(run.steps, 3000);
			const double ratio = separationRatio(run, stockLeads);
			std::printf(
				"[ figures  ] inertia_ratio %d iterations, on %s's states: max separation quaternion / stock "
				"%.3f\n",
				iterations, stockLeads ? "stock" : "the quaternion hinge", ratio);
			EXPECT_LE(ratio, kBound) << iterations << " iterations, " << (stockLeads ? "stock" : "quaternion")
									 << " leading";
		}
}

#ifdef QUATHINGE_HAVE_URDF  // the URDF 5-link pendulum (urdfdom is optional)
TEST(MatchedStates, TheComparisonSeesRowsThatAreWorse)
{
	// The measure can fail: world-axis point rows on the URDF 5-link pendulum separate 12.5× stock's in a free run at
	// 10 iterations (docs/ROW_BASIS.md), and from stock's own states still 1.5×. (A matched step inherits the
	// leader's error, so it shows a difference that builds over many steps only in part.)
	const SceneSpec scene = makeScene("pendulum5");
	ASSERT_TRUE(scene.unavailable.empty()) << scene.unavailable;  // the model is the project's own
	const double dt = sceneStep(scene);
	auto world = [](btDiscreteDynamicsWorld& w) {
		for (int i = 0; i < w.getNumConstraints(); ++i)
			if (btQuaternionHingeConstraint* q = btQuaternionHingeConstraint::upcast(w.getConstraint(i)))
				quathinge::SolverRowBasisAccess::set(*q, quathinge::RowBasis::World, false);
	};
	const MatchedRun worse = runMatched(scene, Kind::Stock, Kind::Quaternion, dt, 10, -1, world);
	const MatchedRun asIs = runMatched(scene, Kind::Stock, Kind::Quaternion, dt, 10, -1);
	ASSERT_TRUE(worse.skipped.empty()) << worse.skipped;
	std::printf("[ figures  ] pendulum5 10 iterations, on stock's states: world rows %.3f, default rows %.3f × stock\n",
				separationRatio(worse, true), separationRatio(asIs, true));
	EXPECT_GT(separationRatio(worse, true), kBound);
	EXPECT_LE(separationRatio(asIs, true), kBound);
}
#endif

TEST(MatchedStates, TheGazeboWhipIsTheScenesMotion)
{
	// Bullet's btMultiBody (reduced coordinates: no joint error) as the reference: the quaternion hinge's run whips
	// within 10% of its rate and 10 ms of its time; the figures of stock's run are printed, not asserted.
	const SceneSpec scene = makeScene("inertia_ratio");
	const Whip reference = lightLinkWhip(scene, Kind::MultiBody, 50);
	const Whip quaternion = lightLinkWhip(scene, Kind::Quaternion, 50);
	const Whip stock = lightLinkWhip(scene, Kind::Stock, 50);
	std::printf(
		"[ figures  ] inertia_ratio 50 iterations, the light link's largest rate: multibody %.1f rad/s at "
		"%.3f s, quaternion %.1f at %.3f s, stock %.1f at %.3f s\n",
		reference.rate, reference.time, quaternion.rate, quaternion.time, stock.rate, stock.time);
	EXPECT_NEAR(quaternion.rate, reference.rate, 0.1 * reference.rate);  // rad/s
	EXPECT_NEAR(quaternion.time, reference.time, 0.010);                 // s
}
#endif
