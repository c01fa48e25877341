// The scene library: every scene runs with every joint kind (CI-sized), the metrics measure what they claim on
// hand-computed cases, and the pendulum keeps the exact period.
#ifdef QUATHINGE_HAVE_SCENES
#include "JointKinds.h"
#include "SceneSpec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>

using namespace quathinge::scenes;

namespace
{
std::string modelsDir()
{
	const char* dir = std::getenv("QUATHINGE_MODELS_DIR");
	return dir ? dir : "../shared/models";
}

// Two static boxes joined by a hinge whose child frame is turned by `twist`: nothing moves, so the metrics must
// return exactly the built-in error.
SceneSpec frozen(const btQuaternion& twist)
{
	SceneSpec s;
	s.name = "frozen";
	BodySpec a;
	a.mass = 0;
	BodySpec b = a;
	b.pose.setOrigin(btVector3(1, 0, 0));
	s.bodies = {a, b};
	JointSpec j;
	j.parent = 0;
	j.child = 1;
	j.pivot = btVector3(btScalar(0.5), 0, 0);
	j.axis = btVector3(0, 0, 1);
	j.childFrameTwist = twist;
	s.joints = {j};
	s.reference = Reference::None;
	s.duration = 0.1;
	return s;
}
}  // namespace

TEST(Scenes, EverySceneRunsWithEveryKind)
{
	// A quarter second of every scene × kind: it runs (or says why not) and nothing blows up where stock survives.
	RunSettings settings;
	settings.duration = 0.25;
	settings.reference = false;
	for (const std::string& name : sceneNames())
	{
		const SceneSpec scene = makeScene(name, 1, modelsDir());
		if (!scene.unavailable.empty())
		{
			std::printf("[ skipped  ] %s: %s\n", name.c_str(), scene.unavailable.c_str());
			continue;
		}
		for (Kind kind : allKinds())
		{
			const Metrics m = runScene(scene, kind, settings);
			if (kind == Kind::MultiBody && (!isTree(scene) || !scene.bulletFile.empty() || name.rfind("flipped", 0) == 0))
			{
				// reduced coordinates cannot express a loop, a file of stock hinges or a misaligned start: said, not run
				EXPECT_FALSE(m.skipped.empty()) << name;
				continue;
			}
			EXPECT_TRUE(m.skipped.empty()) << name << " " << kindName(kind) << ": " << m.skipped;
			EXPECT_EQ(m.steps, 15) << name << " " << kindName(kind);
			EXPECT_TRUE(std::isfinite(m.maxSeparation)) << name << " " << kindName(kind);
			if (kind != Kind::MultiBody)  // multibody joints are coordinates, not rows
			{
				EXPECT_GT(m.rowsPerStep, 0) << name << " " << kindName(kind);
			}
			if (kind == Kind::QuaternionStabilized && !m.blewUp)
			{
				EXPECT_LT(m.maxSeparation, 1e-4) << name;  // m: the stabilizer holds every scene together
			}
		}
	}
}

TEST(Scenes, MetricsMeasureHandComputedErrors)
{
	// A frozen joint turned 30° about x: misalignment exactly 30°, separation 0; about z by 0.5 rad with a
	// limit [−0.2, 0.2]: limit violation exactly 0.3 rad.
	const double kAngleTol = 1e-4;  // degrees / rad, float round-off of a rotation matrix
	RunSettings settings;
	settings.reference = false;
	Metrics m = runScene(frozen(btQuaternion(btVector3(1, 0, 0), btScalar(M_PI / 6))), Kind::Quaternion, settings);
	EXPECT_NEAR(m.maxMisalignmentDeg, 30.0, kAngleTol);
	EXPECT_NEAR(m.rmsMisalignmentDeg, 30.0, kAngleTol);
	EXPECT_NEAR(m.maxSeparation, 0.0, 1e-6);
	EXPECT_LT(m.recoveryTime, 0);  // never below 1°
	SceneSpec limited = frozen(btQuaternion(btVector3(0, 0, 1), btScalar(0.5)));
	limited.joints[0].hasLimit = true;
	limited.joints[0].lower = btScalar(-0.2);
	limited.joints[0].upper = btScalar(0.2);
	m = runScene(limited, Kind::Stock, settings);
	EXPECT_NEAR(m.limitViolation, 0.3, kAngleTol);
	EXPECT_NEAR(m.finalTheta, 0.5, kAngleTol);
	EXPECT_NEAR(m.maxMisalignmentDeg, 0.0, 1e-3);
	EXPECT_FALSE(isTree([] {
		SceneSpec loop = makeScene("four_bar");
		return loop;
	}()));
	EXPECT_TRUE(isTree(makeScene("chain10")));
}

TEST(Scenes, PendulumPeriodWithinHalfAPercentAt240Hz)
{
	// The physical pendulum released at 90°: its measured period is within 0.5% of the elliptic-integral value.
	const double kPeriodTol = 0.005;  // relative
	RunSettings settings;
	settings.dt = 1.0 / 240;
	const SceneSpec scene = makeScene("pendulum");
	for (Kind kind : {Kind::Stock, Kind::Quaternion})
	{
		const Metrics m = runScene(scene, kind, settings);
		std::printf("[ figures  ] pendulum at 240 Hz, %s: period error %.3g (exact %.4f s)\n", kindName(kind).c_str(),
					m.trajectoryError, scene.exactPeriod);
		EXPECT_GE(m.trajectoryError, 0);
		EXPECT_LT(m.trajectoryError, kPeriodTol);
	}
}
#endif
