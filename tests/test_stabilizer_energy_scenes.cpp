// The report's conservative scenes with the stabilizer's defaults (keepEnergyAndMomentum, docs/ENERGY.md): energy drift
// against stock's on the same scene (the reference: Bullet's own hinge), 10 s at 60 and 240 Hz, 10 iterations; a
// robot arm released from rest falls as without the restoration.
#ifdef QUATHINGE_HAVE_SCENES
#include "JointKinds.h"
#include "SceneSpec.h"
#include "Simulation.h"

#include "quathinge/btQuaternionHingeStabilizer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

using namespace quathinge::scenes;

namespace
{
Metrics run(const std::string& name, Kind kind, double dt = 1.0 / 60)
{
	RunSettings settings;
	settings.dt = dt;
	settings.duration = 10;
	settings.reference = false;
	return runScene(makeScene(name, 1), kind, settings);
}
}  // namespace

namespace
{
// Energy drift (max |E − E₀| over the scene's energy scale, Metrics::energyDrift) at most stock's and at most
// driftTol, joints within separationTol (m), on the conservative scenes at step dt (s); `heldToStock` (if any) only to
// stock's.
void expectConservativeScenesHeld(double dt, double driftTol, double separationTol, const char* heldToStock = "")
{
	for (const char* name : {"pendulum", "double_pendulum", "four_bar", "pendulum5", "chain10", "chain30", "rotor100"})
	{
		const Metrics stock = run(name, Kind::Stock, dt), stab = run(name, Kind::QuaternionStabilized, dt);
		std::printf("[ figures  ] %s at %.0f Hz: energy drift %.3g (stock %.3g), max separation %.3g m\n", name, 1 / dt,
					stab.energyDrift, stock.energyDrift, stab.maxSeparation);
		EXPECT_FALSE(stab.blewUp) << name;
		EXPECT_LE(stab.energyDrift, stock.energyDrift) << name;
		if (std::string(name) != heldToStock)
		{
			EXPECT_LE(stab.energyDrift, driftTol) << name;
		}
		EXPECT_LE(stab.maxSeparation, separationTol) << name;
	}
}
}  // namespace

TEST(StabilizerEnergyScenes, ConservativeScenesDriftLessThanStock)
{
	const double kDriftTol = 0.05;       // of the energy scale
	const double kSeparationTol = 1e-5;  // m
	expectConservativeScenesHeld(1.0 / 60, kDriftTol, kSeparationTol);
}

TEST(StabilizerEnergyScenes, ConservativeScenesDriftLessThanStockAt240Hz)
{
	const double kDriftTol = 0.02;       // of the energy scale
	const double kSeparationTol = 1e-5;  // m
#ifdef BT_USE_DOUBLE_PRECISION
	// chain10 in double: 0.030, lost in Bullet's own step, by its implicit gyroscopic force
	// (BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY, on by default) while the chain's end whips round; 0.0020 without that
	// flag, 0.015 in float (docs/ENERGY.md)
	expectConservativeScenesHeld(1.0 / 240, kDriftTol, kSeparationTol, "chain10");
#else
	expectConservativeScenesHeld(1.0 / 240, kDriftTol, kSeparationTol);
#endif
}

TEST(StabilizerEnergyScenes, LoadedChainsStayBoundedWithoutGain)
{
	// 1:100 to 1:10000 loads: no blow-up, energy drift at most stock's, no gain above the start beyond kGainTol of the
	// energy scale (the solver's leftover sags the load; its lift and its kinetic energy are taken out: Q16).
	const double kGainTol = 0.2;         // of the energy scale
	const double kSeparationTol = 1e-5;  // m
	for (const char* name : {"heavy100", "heavy1000", "heavy10000"})
	{
		const Metrics stock = run(name, Kind::Stock), stab = run(name, Kind::QuaternionStabilized);
		std::printf("[ figures  ] %s: energy drift %.3g (stock %.3g), largest gain %.3g, max separation %.3g m\n", name,
					stab.energyDrift, stock.energyDrift, stab.maxEnergyGain, stab.maxSeparation);
		EXPECT_FALSE(stab.blewUp) << name;
		EXPECT_LE(stab.energyDrift, stock.energyDrift) << name;
		EXPECT_LE(stab.maxEnergyGain, kGainTol) << name;
		EXPECT_LE(stab.maxSeparation, kSeparationTol) << name;
	}
}

namespace
{
// Allowed to sleep with Bullet's defaults (0.8 m/s, 1 rad/s for 2 s), up to `seconds` at 60 Hz, 10 iterations.
struct Settling
{
	double sleepTime = -1;          // s until every body is asleep; −1 if not within the run
	int touchingSteps = 0;          // steps in which the scene had contact points (the ragdoll on the ground)
	int restoredWhileTouching = 0;  // … of which steps in which keepEnergyAndMomentum scaled its velocities
};

// `scene` as `kind` (Quaternion: no stabilizer; QuaternionStabilized: keepEnergyAndMomentum as `keep`).
Settling settle(SceneSpec scene, Kind kind, bool keep, double seconds)
{
	scene.allowSleep = true;
	Simulation sim(scene, kind);
	if (btQuaternionHingeStabilizer* stabilizer = sim.stabilizer())
	{
		btQuaternionHingeStabilizerSettings settings = stabilizer->getSettings();
		settings.keepEnergyAndMomentum = keep;
		stabilizer->setSettings(settings);
	}
	Settling s;
	const double dt = 1.0 / 60;
	for (int step = 1; step <= int(seconds / dt); ++step)
	{
		sim.step(dt, 10);
		bool touching = false;
		btDispatcher& dispatcher = *sim.world().getDispatcher();
		for (int m = 0; m < dispatcher.getNumManifolds() && !touching; ++m)
			touching = dispatcher.getManifoldByIndexInternal(m)->getNumContacts() > 0;
		if (touching)
		{
			++s.touchingSteps;
			if (sim.stabilizer() && sim.stabilizer()->getLastStats().energyRestoredIslands > 0) ++s.restoredWhileTouching;
		}
		bool asleep = true;
		for (const btRigidBody* b : sim.bodies) asleep = asleep && !b->isActive();
		if (asleep)
		{
			s.sleepTime = step * dt;
			break;
		}
	}
	return s;
}

// How many of `drops` fell asleep, and the median time of those that did (s; −1 if none).
struct SleepCount
{
	int asleep = 0;
	double medianTime = -1;
};
SleepCount countAsleep(const std::vector<Settling>& drops)
{
	std::vector<double> times;
	for (const Settling& d : drops)
		if (d.sleepTime > 0) times.push_back(d.sleepTime);
	SleepCount c;
	c.asleep = int(times.size());
	if (!times.empty())
	{
		std::sort(times.begin(), times.end());
		c.medianTime = times[times.size() / 2];
	}
	return c;
}
}  // namespace

TEST(StabilizerEnergyScenes, RestingBodiesStillFallAsleep)
{
	// Keeping the energy must not keep bodies awake. The restoration does not act on an island touching anything
	// outside it, so a ragdoll on the ground settles with the projection's own damping: checked in every step of
	// kDrops drops (the ragdoll scene's seeds 1..kDrops: different spins), in which no velocity may be scaled while the
	// ragdoll touches the ground. Whether a drop ends asleep within kSeconds is chaotic (a last tumble, a limb resting
	// on a stop: it changes with the compiler and the platform), so the outcome is counted over the drops, with the
	// restoration, without it and without a stabilizer, and printed; kMinAsleep of them must sleep with the defaults.
	// 50 chains hanging at rest (not chaotic: they reach the rest cache's fixed point) fall asleep either way.
	const int kDrops = 12;
	// drops of kDrops asleep within kSeconds with the defaults: a guard against keeping resting bodies awake wholesale,
	// not a target (docs/ENERGY.md, "Limitation": without a stabilizer more drops sleep)
	const int kMinAsleep = 6;
	const double kSeconds = 15;  // s of simulation at most
	std::vector<Settling> bare, off, on;
	for (int seed = 1; seed <= kDrops; ++seed)
	{
		bare.push_back(settle(ragdollScene(unsigned(seed)), Kind::Quaternion, false, kSeconds));
		off.push_back(settle(ragdollScene(unsigned(seed)), Kind::QuaternionStabilized, false, kSeconds));
		on.push_back(settle(ragdollScene(unsigned(seed)), Kind::QuaternionStabilized, true, kSeconds));
		EXPECT_GT(on.back().touchingSteps, 0) << "seed " << seed;
		EXPECT_EQ(on.back().restoredWhileTouching, 0) << "seed " << seed;
	}
	const SleepCount bareCount = countAsleep(bare), offCount = countAsleep(off), onCount = countAsleep(on);
	const Settling chainsOff = settle(restScene(50, 10, true), Kind::QuaternionStabilized, false, kSeconds),
				   chainsOn = settle(restScene(50, 10, true), Kind::QuaternionStabilized, true, kSeconds);
	std::printf(
		"[ figures  ] ragdoll drops asleep within %.0f s: %d of %d with keepEnergyAndMomentum (median %.3g s), "
		"%d without it (median %.3g s), %d without a stabilizer (median %.3g s); 50 chains at rest asleep "
		"after %.3g s (without the restoration %.3g s)\n",
		kSeconds, onCount.asleep, kDrops, onCount.medianTime, offCount.asleep, offCount.medianTime,
		bareCount.asleep, bareCount.medianTime, chainsOn.sleepTime, chainsOff.sleepTime);
	EXPECT_GE(onCount.asleep, kMinAsleep);
	if (chainsOff.sleepTime > 0)
	{
		EXPECT_GT(chainsOn.sleepTime, 0);
	}
}

#ifdef QUATHINGE_HAVE_URDF  // kuka_iiwa.urdf (urdfdom is optional)
TEST(StabilizerEnergyScenes, AnArmReleasedFromRestIsNotHeldBack)
{
	// The KUKA arm from URDF starts at rest, upright, and falls under gravity. Bullet's solver leaves the arm a sag
	// each step that the position correction lifts back (0.021 J a step, against a kinetic energy of 1e-8 J at the
	// start); a restoration that charges that lift to the kinetic energy scales the velocities down by the cap every
	// step and holds the arm back (0.28 m from the common reference after 1.15 s). The arm's bodies with the
	// restoration stay within kPathTol (RMS over bodies, the largest over the run) of the same arm with the
	// projection alone and of the bare quaternion hinges (no stabilizer), each a run without the restoration.
	const double kPathTol = 0.03;  // m
	const double kSeconds = 1.15;  // s: the peers' horizon for this scene (docs/PEERS.md)
	const SceneSpec scene = makeScene("kuka_iiwa");
	ASSERT_TRUE(scene.unavailable.empty()) << scene.unavailable;
	Simulation on(scene, Kind::QuaternionStabilized), off(scene, Kind::QuaternionStabilized), bare(scene, Kind::Quaternion);
	btQuaternionHingeStabilizerSettings settings = off.stabilizer()->getSettings();
	settings.keepEnergyAndMomentum = false;
	off.stabilizer()->setSettings(settings);
	ASSERT_TRUE(on.stabilizer()->getSettings().keepEnergyAndMomentum);
	double fromOff = 0, fromBare = 0, travelled = 0;  // m
	std::vector<btVector3> start;
	for (const btRigidBody* b : on.bodies) start.push_back(b->getCenterOfMassPosition());
	const double dt = 1.0 / 60;
	for (int step = 1; step <= int(std::lround(kSeconds / dt)); ++step)
	{
		for (Simulation* sim : {&on, &off, &bare}) sim->step(dt, 30);
		double sumOff = 0, sumBare = 0, sumTravel = 0;
		for (size_t i = 0; i < on.bodies.size(); ++i)
		{
			const btVector3 x = on.bodies[i]->getCenterOfMassPosition();
			sumOff += double((x - off.bodies[i]->getCenterOfMassPosition()).length2());
			sumBare += double((x - bare.bodies[i]->getCenterOfMassPosition()).length2());
			sumTravel += double((x - start[i]).length2());
		}
		const double n = double(on.bodies.size());
		fromOff = std::max(fromOff, std::sqrt(sumOff / n));
		fromBare = std::max(fromBare, std::sqrt(sumBare / n));
		travelled = std::max(travelled, std::sqrt(sumTravel / n));
	}
	std::printf(
		"[ figures  ] kuka_iiwa over %.3g s: fell %.3g m (RMS); apart from the projection alone %.3g m, from the "
		"bare hinges %.3g m\n",
		kSeconds, travelled, fromOff, fromBare);
	EXPECT_GT(travelled, 5 * kPathTol);  // it falls: the bound below is not met by standing still
	EXPECT_LE(fromOff, kPathTol);
	EXPECT_LE(fromBare, kPathTol);
}
#endif  // QUATHINGE_HAVE_URDF

TEST(StabilizerEnergyScenes, StiffAndExtremeCasesStayBoundedOnTheirJoints)
{
	// With the energy restoration on: a 200-link chain released horizontally (100 m long), a 10-link chain under
	// 100 g, and the ragdoll scene with its ground contacts: no blow-up, no energy gain beyond kGainTol of the energy
	// scale (the conservative ones), joints held. (The 1:10000 load: LoadedChainsStayBoundedWithoutGain.)
	const double kGainTol = 0.2;         // of the energy scale
	const double kSeparationTol = 1e-5;  // m
	RunSettings settings;
	settings.dt = 1.0 / 60;
	settings.reference = false;
	struct Case
	{
		SceneSpec scene;
		double extent;  // m: the farthest a pivot gets from the origin
	};
	std::vector<Case> cases;
	cases.push_back({chainScene(200, 1), 100});
	SceneSpec heavyGravity = makeScene("chain10", 1);
	heavyGravity.name = "chain10 at 100 g";
	heavyGravity.gravity *= btScalar(100);
	cases.push_back({heavyGravity, 5});
	cases.push_back({makeScene("ragdoll", 1), 5});
	for (const Case& c : cases)
	{
		settings.duration = c.scene.duration;
		const Metrics stab = runScene(c.scene, Kind::QuaternionStabilized, settings);
		// m: the rounding floor of a pivot `extent` from the origin (4ε·extent; the stabilizer's own convergence test)
		const double floor = std::max(kSeparationTol, 4 * double(SIMD_EPSILON) * c.extent);
		std::printf(
			"[ figures  ] %s, %.3g s: max separation %.3g m (bound %.3g m), largest energy gain %.3g, energy drift "
			"%.3g\n",
			c.scene.name.c_str(), c.scene.duration, stab.maxSeparation, floor, stab.maxEnergyGain, stab.energyDrift);
		EXPECT_FALSE(stab.blewUp) << c.scene.name;
		EXPECT_LE(stab.maxSeparation, floor) << c.scene.name;
		if (c.scene.conservative)
		{
			EXPECT_LE(stab.maxEnergyGain, kGainTol) << c.scene.name;
		}
	}
}

#endif  // QUATHINGE_HAVE_SCENES
