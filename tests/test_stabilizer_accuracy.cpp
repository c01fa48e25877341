// btQuaternionHingeStabilizer (docs/MATH.md Q13, Q14): how closely the projection puts bodies back on their joints:
// chains, sub-steps, heavy loads, initial error, velocities, and the projected pose Bullet shows.
// One line of intent opens each test; scenes and named tolerances: support/StabilizerScene.h. Built when
// QuatHinge::Stabilizer is (QUATHINGE_HAVE_STABILIZER).
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/StabilizerScene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <vector>

using namespace qh_test;

TEST(Stabilizer, TenLinkChainStaysOnItsJoints)
{
	// A 10-link chain released horizontally keeps every pivot together and every axis aligned (the brief's target),
	// where the rows alone drift by centimetres.
	const int steps = 300;  // 5 s
	double separationWithout, misalignmentWithout;
	{
		StabilizerScene scene;
		scene.chain(10);
		runAndMeasure(scene, steps, separationWithout, misalignmentWithout);
	}
	StabilizerScene scene;
	scene.chain(10);
	btQuaternionHingeStabilizer stabilizer;
	scene.addAction(&stabilizer);
	double separation, misalignment;
	runAndMeasure(scene, steps, separation, misalignment);
	std::cout << "[ figures  ] 10-link chain, 60 Hz, 10 iterations, 5 s: max separation " << separationWithout
			  << " m -> " << separation << " m, max misalignment " << misalignmentWithout << " deg -> "
			  << misalignment << " deg" << std::endl;
	EXPECT_LE(separation, kSeparationTolerance);
	EXPECT_LE(misalignment, kMisalignmentToleranceDeg);
	EXPECT_GT(separationWithout, 100 * kSeparationTolerance);  // the scene is one where drift exists
}

TEST(Stabilizer, SubStepsAreProjectedToo)
{
	// With fixed sub-steps (Bullet calls the action after every internal step) the result is as tight.
	StabilizerScene scene;
	scene.chain(10);
	btQuaternionHingeStabilizer stabilizer;
	scene.addAction(&stabilizer);
	double separation = 0, misalignment = 0;
	for (int i = 0; i < 60; ++i)
	{
		scene.world().stepSimulation(btScalar(1) / 30, 4, btScalar(1) / 120);  // 4 internal steps per call
		double s, m;
		scene.jointErrors(s, m);
		separation = std::max(separation, s);
		misalignment = std::max(misalignment, m);
	}
	EXPECT_LE(separation, kSeparationTolerance);
	EXPECT_LE(misalignment, kMisalignmentToleranceDeg);
}

TEST(Stabilizer, HeavyLoadOnLightChainStaysBounded)
{
	// A 1000 kg load on a chain of 1 kg links (1:1000, where the rows alone blow up) stays bounded and together.
	double separationWithout, misalignmentWithout;
	{
		StabilizerScene scene;
		scene.chain(10, 1000);
		runAndMeasure(scene, 300, separationWithout, misalignmentWithout);
	}
	StabilizerScene scene;
	std::vector<btRigidBody*> links = scene.chain(10, 1000);
	btQuaternionHingeStabilizer stabilizer;
	scene.addAction(&stabilizer);
	double separation, misalignment;
	runAndMeasure(scene, 300, separation, misalignment);
	ASSERT_TRUE(scene.allFinite());
	// m: the chain is 5 m long and hangs from (0, 10, 0); bounded means it stays within reach of its anchor.
	const btScalar reach = btScalar(5 + 0.5);
	for (btRigidBody* link : links)
		EXPECT_LE((link->getCenterOfMassPosition() - btVector3(0, 10, 0)).length(), reach);
	std::cout << "[ figures  ] 1:1000 chain (10 links), 5 s: max separation " << separationWithout << " m -> "
			  << separation << " m, max misalignment " << misalignmentWithout << " deg -> " << misalignment << " deg"
			  << std::endl;
	EXPECT_LE(separation, kHeavySeparationTolerance);
}

TEST(Stabilizer, InitialErrorIsRemovedByStabilize)
{
	// A scene assembled off its joints (10 cm, 20°) is put back on them by one stabilize() call (Newton, Q13).
	StabilizerScene scene;
	std::vector<btRigidBody*> links = scene.chain(4);
	btTransform t = links[2]->getCenterOfMassTransform();
	t.setOrigin(t.getOrigin() + btVector3(0.05, 0.08, -0.03));
	t.setRotation(btQuaternion(btVector3(1, 1, 0).normalized(), btScalar(20 / kRadToDeg)) * t.getRotation());
	links[2]->setCenterOfMassTransform(t);
	btQuaternionHingeStabilizer stabilizer;
	const btQuaternionHingeStabilizerStats& stats = stabilizer.stabilize(&scene.world());
	EXPECT_GT(stats.residualBefore, btScalar(0.05));
	EXPECT_LE(stats.residualAfter, kResidualTolerance);
	EXPECT_LE(stats.iterations, stabilizer.getSettings().maxIterations);
	double separation, misalignment;
	scene.jointErrors(separation, misalignment);
	EXPECT_LE(separation, kSeparationTolerance);
	EXPECT_LE(misalignment, kMisalignmentToleranceDeg);
}

TEST(Stabilizer, VelocitiesAreProjectedOntoTheJoints)
{
	// After a step the bodies' velocities satisfy J v = 0 at the projected positions (Q14), to rounding.
	StabilizerScene scene;
	scene.chain(10);
	btQuaternionHingeStabilizer stabilizer;
	scene.addAction(&stabilizer);
	for (int i = 0; i < 60; ++i) scene.world().stepSimulation(kTimeStep, 0);
	const btQuaternionHingeStabilizerStats& stats = stabilizer.getLastStats();
	EXPECT_GT(stats.velocityResidualBefore, stats.velocityResidualAfter);
	// m/s: J v is ≤ tolerance / time step by design (a drift below the position tolerance over the next step).
	EXPECT_LE(stats.velocityResidualAfter, kResidualTolerance / kTimeStep);
}

TEST(Stabilizer, ProjectedPoseReachesInterpolationAndMotionState)
{
	// A moved body's interpolation transform is its projected transform, and so is what its motion state shows.
	StabilizerScene scene;
	std::vector<btRigidBody*> links = scene.chain(5);
	btQuaternionHingeStabilizer stabilizer;
	scene.addAction(&stabilizer);
	// A variable step: Bullet hands the motion state the interpolation transform itself (with fixed sub-steps it
	// would be interpolated over the left-over time, from that same transform).
	for (int i = 0; i < 30; ++i) scene.world().stepSimulation(kTimeStep, 0);
	for (btRigidBody* link : links)
	{
		EXPECT_TRUE(sameTransform(link->getInterpolationWorldTransform(), link->getCenterOfMassTransform()));
		btTransform shown;
		link->getMotionState()->getWorldTransform(shown);
		// Bullet passes the pose through a quaternion on the way (integrateTransform over a zero time): equal to
		// rounding, 8ε relative (m for the origin at ~10 m, and per basis entry).
		const btTransform& pose = link->getCenterOfMassTransform();
		EXPECT_LE((shown.getOrigin() - pose.getOrigin()).length(), 8 * SIMD_EPSILON * pose.getOrigin().length());
		for (int r = 0; r < 3; ++r)
			EXPECT_LE((shown.getBasis()[r] - pose.getBasis()[r]).length(), 8 * SIMD_EPSILON);
	}
	double separation, misalignment;
	scene.jointErrors(separation, misalignment);
	EXPECT_LE(separation, kSeparationTolerance);
}

TEST(Stabilizer, RotationWeightHoldsATenThousandToOneLoad)
{
	// The demo's heavy10000: a planar chain of five 1 kg links 0.5 m long, hinged to the world, carrying a 10000 kg
	// cube (0.2 m), released horizontally. In the mass metric (weight 1) the cheapest first-order fix of a stretched
	// joint is to swing the light links, which the second-order terms undo: Newton falls short step after step and
	// the chain tears apart. With the default rotation weight the correction moves the links along instead.
	auto run = [](btScalar weight, double& separation, double& misalignment, StabilizerWork& work) {
		StabilizerScene scene;
		const btScalar length = btScalar(0.5);
		std::vector<btRigidBody*> links;
		for (int i = 0; i < 5; ++i)
		{
			btRigidBody* link = scene.box(btVector3(length / 2, btScalar(0.05), btScalar(0.05)), 1,
										  btVector3(length * (btScalar(i) + btScalar(0.5)), 0, 0));
			if (i == 0) scene.hingeToWorld(*link, btVector3(-length / 2, 0, 0), btVector3(0, 0, 1));
			else
				scene.hinge(*links.back(), *link, btVector3(length / 2, 0, 0), btVector3(-length / 2, 0, 0),
							btVector3(0, 0, 1), btVector3(0, 0, 1));
			links.push_back(link);
		}
		btRigidBody* load = scene.box(btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)), 10000,
									  btVector3(btScalar(2.6), 0, 0));
		scene.hinge(*links.back(), *load, btVector3(length / 2, 0, 0), btVector3(btScalar(-0.1), 0, 0),
					btVector3(0, 0, 1), btVector3(0, 0, 1));
		btQuaternionHingeStabilizerSettings settings;
		settings.positionRotationWeight = weight;
		btQuaternionHingeStabilizer stabilizer(settings);
		scene.addAction(&stabilizer);
		runAndMeasure(scene, 300, separation, misalignment, &stabilizer, &work);  // 5 s at 60 Hz
		return scene.allFinite();
	};
	double sepDefault, misDefault, sepMass, misMass;
	StabilizerWork workDefault, workMass;
	ASSERT_TRUE(run(btQuaternionHingeStabilizerSettings().positionRotationWeight, sepDefault, misDefault, workDefault));
	const bool massFinite = run(1, sepMass, misMass, workMass);
	std::cout << "[ figures  ] 1:10000 load on 5 links, 5 s: rotation weight 1: max separation " << sepMass
			  << " m, misalignment " << misMass << " deg, " << workMass.newtonPerStep
			  << " Newton iterations/step; default weight: " << sepDefault << " m, " << misDefault << " deg, "
			  << workDefault.newtonPerStep << std::endl;
	EXPECT_LE(sepDefault, kHeavySeparationTolerance);
	EXPECT_LE(misDefault, kMisalignmentToleranceDeg);
	// the weight is what holds it: the mass metric misses the tolerance by far (float: 8.6e-3 m with the energy
	// restoration, 7.9e-2 m with the projection's own damping; the chain swings differently)
	const double kMassMetricMiss = 20;  // times kHeavySeparationTolerance
	EXPECT_TRUE(!massFinite || sepMass > kMassMetricMiss * kHeavySeparationTolerance);
}

TEST(Stabilizer, RotationWeightKeepsNewtonShortOnALongChain)
{
	// A hanging 300-link chain: Newton iterations per step (the projection's cost) with the default rotation weight
	// against the mass metric; both end on the joints.
	auto run = [](btScalar weight, double& separation, StabilizerWork& work) {
		StabilizerScene scene;
		scene.chain(300);
		btQuaternionHingeStabilizerSettings settings;
		settings.positionRotationWeight = weight;
		btQuaternionHingeStabilizer stabilizer(settings);
		scene.addAction(&stabilizer);
		double misalignment;
		runAndMeasure(scene, 120, separation, misalignment, &stabilizer, &work);
		return scene.allFinite();
	};
	double sepDefault, sepMass;
	StabilizerWork workDefault, workMass;
	ASSERT_TRUE(run(btQuaternionHingeStabilizerSettings().positionRotationWeight, sepDefault, workDefault));
	ASSERT_TRUE(run(1, sepMass, workMass));
	std::cout << "[ figures  ] 300-link chain, 2 s: Newton iterations/step " << workMass.newtonPerStep
			  << " (weight 1) -> " << workDefault.newtonPerStep << " (default), factorizations/step "
			  << workMass.factorizationsPerStep << " -> " << workDefault.factorizationsPerStep << "; max separation "
			  << sepMass << " m -> " << sepDefault << " m" << std::endl;
	// m: the rounding floor of a pivot 150 m from the origin (4ε·150 m; the stabilizer's own convergence test)
	const double floor = std::max(kSeparationTolerance, 4 * double(SIMD_EPSILON) * 150);
	EXPECT_LE(sepDefault, floor);
	EXPECT_LE(sepMass, floor);
	EXPECT_LT(workDefault.newtonPerStep, workMass.newtonPerStep);
}

#endif  // QUATHINGE_HAVE_STABILIZER
