// btQuaternionHingeStabilizer's settings and statistics: bad settings are refused, the position and velocity
// projections can be turned off, and every counter of the statistics reports what the step did.
// One line of intent opens each test; scenes and named tolerances: support/StabilizerScene.h. Built when
// QuatHinge::Stabilizer is (QUATHINGE_HAVE_STABILIZER).
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/StabilizerScene.h"

#include "support/Refusal.h"
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

using namespace qh_test;

TEST(Stabilizer, InvalidSettingsAreRefused)
{
	// Every setting is checked: an out-of-range value is refused (thrown, or reported without exceptions) and nothing
	// changes.
	btQuaternionHingeStabilizerSettings bad;
	bad.positionTolerance = 0;
	EXPECT_REFUSED(btQuaternionHingeStabilizer{bad}, "positionTolerance");
	btQuaternionHingeStabilizer stabilizer;
	bad = btQuaternionHingeStabilizerSettings();
	bad.maxIterations = 0;
	EXPECT_REFUSED(stabilizer.setSettings(bad), "maxIterations");
	bad = btQuaternionHingeStabilizerSettings();
	bad.regularization = -1;
	EXPECT_REFUSED(stabilizer.setSettings(bad), "regularization");
	bad = btQuaternionHingeStabilizerSettings();
	bad.minimumProgress = 0;
	EXPECT_REFUSED(stabilizer.setSettings(bad), "minimumProgress");
	for (btScalar weight : {btScalar(0.5), btScalar(2e6), btScalar(NAN)})
	{
		bad = btQuaternionHingeStabilizerSettings();
		bad.positionRotationWeight = weight;
		EXPECT_REFUSED(stabilizer.setSettings(bad), "positionRotationWeight") << weight;
	}
	EXPECT_EQ(stabilizer.getSettings().maxIterations, btQuaternionHingeStabilizerSettings().maxIterations);
	StabilizerScene scene;
	EXPECT_REFUSED(stabilizer.stabilize(&scene.world(), 0), "timeStep");
}

TEST(Stabilizer, PositionOrVelocityProjectionCanBeTurnedOff)
{
	// With the position part off, positions are left to the solver and only velocities are projected (and back).
	StabilizerScene scene;
	scene.chain(10);
	btQuaternionHingeStabilizerSettings settings;
	settings.projectPositions = false;
	btQuaternionHingeStabilizer stabilizer(settings);
	scene.addAction(&stabilizer);
	for (int i = 0; i < 30; ++i) scene.world().stepSimulation(kTimeStep, 0);
	EXPECT_EQ(stabilizer.getLastStats().iterations, 0);
	EXPECT_EQ(stabilizer.getLastStats().residualAfter, stabilizer.getLastStats().residualBefore);
	EXPECT_LT(stabilizer.getLastStats().velocityResidualAfter, stabilizer.getLastStats().velocityResidualBefore);
	settings.projectPositions = true;
	settings.projectVelocities = false;
	stabilizer.setSettings(settings);
	scene.world().stepSimulation(kTimeStep, 0);
	EXPECT_GE(stabilizer.getLastStats().iterations, 1);
	EXPECT_EQ(stabilizer.getLastStats().velocityResidualAfter, 0);
}

TEST(Stabilizer, StatisticsAreFilled)
{
	// Every counter of the statistics reports what the step did.
	StabilizerScene scene;
	scene.chain(10);
	scene.chain(4, 1, 20);
	btQuaternionHingeStabilizer stabilizer;
	scene.addAction(&stabilizer);
	scene.world().stepSimulation(kTimeStep, 0);
	const btQuaternionHingeStabilizerStats first = stabilizer.getLastStats();
	EXPECT_TRUE(first.structureRebuilt);
	for (int i = 0; i < 20; ++i) scene.world().stepSimulation(kTimeStep, 0);
	const btQuaternionHingeStabilizerStats& s = stabilizer.getLastStats();
	EXPECT_FALSE(s.structureRebuilt);  // nothing changed: the islands and their analysis are reused
	EXPECT_EQ(s.islands, 2);
	EXPECT_EQ(s.sparseIslands, 0);
	EXPECT_EQ(s.joints, 14);
	EXPECT_EQ(s.bodies, 14);
	EXPECT_EQ(s.rows, 14 * 5);
	EXPECT_GE(s.iterations, 1);
	EXPECT_GE(s.totalIterations, s.iterations);
	EXPECT_GE(s.factorizations, 1);
	EXPECT_GE(s.solves, s.totalIterations);
	EXPECT_GT(s.residualBefore, s.residualAfter);
	EXPECT_LE(s.residualAfter, kResidualTolerance);
	EXPECT_GT(s.velocityResidualBefore, s.velocityResidualAfter);
	EXPECT_GT(s.timeMicroseconds, 0);
	EXPECT_EQ(s.numericalIssues, 0);
	EXPECT_EQ(s.activeLimitRows, 0);
}

#endif  // QUATHINGE_HAVE_STABILIZER
