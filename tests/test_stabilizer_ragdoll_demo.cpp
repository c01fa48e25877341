// Bullet's RagdollDemo ragdolls (tests/support/RagdollDemo.h: hinges and cone twists, the ground a static
// btCollisionObject as the demo makes it, or a static btRigidBody) with the stabilizer's defaults, nothing else set:
// every joint held from t = 0.5 s (the demo's frames start up to 0.1 m apart), and the ragdolls resting no deeper in
// the ground than without the stabilizer. One ragdoll and a pile of 20, 60 Hz, 10 iterations.
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/RagdollDemo.h"
#include "support/StabilizerScene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

using namespace qh_test;

namespace
{
const double kLimitPastTolerance = 1e-3;  // rad: how far past a hinge's or cone twist's limits a joint may be (issue 38)

struct RagdollFigures
{
	double hinge = 0;      // m: the largest hinge pivot separation from t = 0.5 s
	double cone = 0;       // m: the largest cone-twist pivot separation from t = 0.5 s
	double hingePast = 0;  // rad: the farthest a hinge is past its limits from t = 0.5 s
	double conePast = 0;   // rad: … a cone twist past its swing or twist span
	double restDepth = 0;  // m: the mean over the last second of each step's deepest ground penetration
	int skipped = 0;       // joints of Bullet's kinds the stabilizer left out (all reasons), the most in any step
	int contactRows = 0;   // contact rows projected, summed over the run
};

// `count` ragdolls: one standing at the origin, or a pile of columns of five, each 1.8 m above the one below, turned
// and spun differently; 4 s at 60 Hz.
RagdollFigures run(RagdollGround ground, int count, bool stabilized,
				   const btQuaternionHingeStabilizerSettings& settings = btQuaternionHingeStabilizerSettings())
{
	RagdollDemoWorld w(ground);
	for (int i = 0; i < count; ++i)
	{
		const int column = i / 5, level = i % 5;
		const btVector3 at(btScalar(0.4 * (column % 2) - 0.2), btScalar(0.2 + 1.8 * level), btScalar(0.4 * (column / 2) - 0.2));
		w.addRagdoll(at, btScalar(0.9 * i), btScalar(std::sin(1.7 * i + 0.3)));
	}
	btQuaternionHingeStabilizer stabilizer(settings);  // the defaults unless said
	if (stabilized) w.world().addAction(&stabilizer);
	RagdollFigures f;
	const int steps = 240, from = 30, lastSecond = 60;
	for (int s = 0; s < steps; ++s)
	{
		w.world().stepSimulation(kTimeStep, 0, kTimeStep);
		if (stabilized)
		{
			const btQuaternionHingeStabilizerStats& st = stabilizer.getLastStats();
			f.skipped = std::max(f.skipped, st.skippedByOption + st.skippedUnexpressible + st.skippedFaulted);
			f.contactRows += st.contactRows;
		}
		if (s + 1 >= from)
		{
			double hinge = 0, cone = 0;
			w.jointSeparations(hinge, cone);
			f.hinge = std::max(f.hinge, hinge);
			f.cone = std::max(f.cone, cone);
			w.limitsPast(hinge, cone);
			f.hingePast = std::max(f.hingePast, hinge);
			f.conePast = std::max(f.conePast, cone);
		}
		if (s >= steps - lastSecond) f.restDepth += w.groundPenetration() / lastSecond;
	}
	if (stabilized) w.world().removeAction(&stabilizer);
	return f;
}

// Without and with the stabilizer's defaults; returns both (bare, held) for checkConeLimits.
std::pair<RagdollFigures, RagdollFigures> check(RagdollGround ground, int count)
{
	const RagdollFigures bare = run(ground, count, false), held = run(ground, count, true);
	const char* groundName = ground == RagdollGround::CollisionObject ? "btCollisionObject" : "btRigidBody";
	std::printf(
		"[ measured ] %d ragdoll(s) on a %s ground, without -> with the stabilizer (defaults): hinges %.2e -> "
		"%.2e m, cone twists %.2e -> %.2e m, resting ground penetration %.2e -> %.2e m, contact rows %d; past the "
		"limits: hinges %.2e -> %.2e rad, cone twists %.2e -> %.2e rad\n",
		count, groundName, bare.hinge, held.hinge, bare.cone, held.cone, bare.restDepth, held.restDepth,
		held.contactRows, bare.hingePast, held.hingePast, bare.conePast, held.conePast);
	EXPECT_LE(held.hinge, kSeparationTolerance);
	EXPECT_LE(held.cone, kSeparationTolerance);
	EXPECT_LE(held.hingePast, kLimitPastTolerance);
	EXPECT_LE(held.restDepth, bare.restDepth);
	EXPECT_GT(held.contactRows, 0);
	EXPECT_EQ(held.skipped, 0);
	return {bare, held};
}

// With projectConeTwistLimits the cone twists' swing and twist limits are rows of the projection too: every hinge and
// cone twist then stays within its limits to kLimitPastTolerance (with the defaults the cone twists go further past
// than without the stabilizer: the projection moves their bodies to close the hinges and does not see those limits).
// The pile's landings take up to 15 Newton iterations in double (measured), so maxIterations is 20 here. `bare` and
// `defaults`: the same world's runs without the stabilizer and with its defaults (check, on the btCollisionObject ground).
void checkConeLimits(int count, const RagdollFigures& bare, const RagdollFigures& defaults)
{
	btQuaternionHingeStabilizerSettings settings;
	settings.projectConeTwistLimits = true;
	settings.maxIterations = 20;
	const RagdollFigures held = run(RagdollGround::CollisionObject, count, true, settings);
	std::printf(
		"[ measured ] %d ragdoll(s), projectConeTwistLimits: joints %.2e m (hinges), %.2e m (cone twists); past the limits: "
		"hinges %.2e rad, cone twists %.2e rad (without the stabilizer %.2e rad, with its defaults %.2e rad); resting "
		"ground penetration %.2e m (without %.2e m)\n",
		count, held.hinge, held.cone, held.hingePast, held.conePast, bare.conePast, defaults.conePast, held.restDepth,
		bare.restDepth);
	EXPECT_LE(held.hinge, kSeparationTolerance);
	EXPECT_LE(held.cone, kSeparationTolerance);
	EXPECT_LE(held.hingePast, kLimitPastTolerance);
	EXPECT_LE(held.conePast, kLimitPastTolerance);
	EXPECT_GT(bare.conePast, 100 * kLimitPastTolerance);  // Bullet's soft limits alone
	EXPECT_LE(held.restDepth, bare.restDepth);
	EXPECT_EQ(held.skipped, 0);
}
}  // namespace

// On the btCollisionObject ground (RagdollDemo's), each world also runs with projectConeTwistLimits.
TEST(StabilizerRagdollDemo, OneRagdollOnACollisionObjectGround)
{
	const auto figures = check(RagdollGround::CollisionObject, 1);
	checkConeLimits(1, figures.first, figures.second);
}
TEST(StabilizerRagdollDemo, OneRagdollOnARigidBodyGround) { check(RagdollGround::StaticBody, 1); }
TEST(StabilizerRagdollDemo, APileOfTwentyOnACollisionObjectGround)
{
	const auto figures = check(RagdollGround::CollisionObject, 20);
	checkConeLimits(20, figures.first, figures.second);
}
TEST(StabilizerRagdollDemo, APileOfTwentyOnARigidBodyGround)
{
#ifdef QUATHINGE_SANITIZED_TESTS
	// the same projection and contact code as the pile on the btCollisionObject ground above, which the sanitizer build
	// runs (the normal builds run both, with the same figures); under ASan + UBSan each pile takes over two minutes
	GTEST_SKIP() << "the sanitizer build runs the pile on the btCollisionObject ground only";
#endif
	check(RagdollGround::StaticBody, 20);
}
#endif
