// Bullet's RagdollDemo ragdolls (tests/support/RagdollDemo.h: hinges and cone twists, the ground a static
// btCollisionObject as the demo makes it, or a static btRigidBody) with the stabilizer's defaults, nothing else set:
// every joint held from t = 0.5 s (the demo's frames start up to 0.1 m apart), hinges and cone twists within their
// limits, no call sinking a part into the ground, and the ragdolls resting no deeper in it than without the
// stabilizer. One ragdoll, a pile of 20 and a crowd of 100, 60 Hz, 10 iterations.
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/RagdollDemo.h"
#include "support/StabilizerScene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

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
	double deepest = 0;    // m: the deepest ground penetration over the run (the landings)
	// m: the most one stabilizer call sank a part into the ground, by the part's own deepest point, over the run
	// (from t = 0: the first calls close the demo's joints, up to 0.1 m apart, and its limits)
	double callSink = 0;
	int skipped = 0;      // joints of Bullet's kinds the stabilizer left out (all reasons), the most in any step
	int contactRows = 0;  // contact rows projected, summed over the run
};

// How the ragdolls stand: a pile (columns of five, each 1.8 m above the one below, the columns 0.4 m apart; one
// ragdoll is the first column's lowest) or a crowd (all on the ground, rows of ten 0.8 m apart: each falls onto its
// neighbours).
enum class Layout
{
	Pile,
	Crowd
};

// `count` ragdolls as `layout` places them, turned and spun differently; 4 s at 60 Hz.
RagdollFigures run(RagdollGround ground, int count, bool stabilized,
				   const btQuaternionHingeStabilizerSettings& settings = btQuaternionHingeStabilizerSettings(),
				   Layout layout = Layout::Pile)
{
	RagdollDemoWorld w(ground);
	for (int i = 0; i < count; ++i)
	{
		btVector3 at;
		if (layout == Layout::Pile)
		{
			const int column = i / 5, level = i % 5;
			at = btVector3(btScalar(0.4 * (column % 2) - 0.2), btScalar(0.2 + 1.8 * level), btScalar(0.4 * (column / 2) - 0.2));
		}
		else
		{
			at = btVector3(btScalar(0.8 * (i % 10)), btScalar(0.2), btScalar(0.8 * (i / 10)));
		}
		w.addRagdoll(at, btScalar(0.9 * i), btScalar(std::sin(1.7 * i + 0.3)));
	}
	btQuaternionHingeStabilizer stabilizer(settings);  // the defaults unless said
	RagdollGroundProbe beforeCall(w), afterCall(w);
	if (stabilized)
	{
		w.world().addAction(&beforeCall);  // actions run in the order they were added
		w.world().addAction(&stabilizer);
		w.world().addAction(&afterCall);
	}
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
			f.callSink = std::max(f.callSink, std::max(afterCall.deepeningSince(beforeCall, true),
													   afterCall.deepeningSince(beforeCall, false)));
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
		const double depth = w.groundPenetration();
		f.deepest = std::max(f.deepest, depth);
		if (s >= steps - lastSecond) f.restDepth += depth / lastSecond;
	}
	if (stabilized)
	{
		w.world().removeAction(&afterCall);
		w.world().removeAction(&stabilizer);
		w.world().removeAction(&beforeCall);
	}
	return f;
}

const double kCallSink = 1e-5;  // m: how much deeper one call may leave a part in the ground (float's rounding there)

// Without and with the stabilizer's defaults (every joint, the cone twists' limits and the contacts projected);
// returns both (bare, held) for checkWithoutConeLimits.
std::pair<RagdollFigures, RagdollFigures> check(RagdollGround ground, int count, Layout layout = Layout::Pile,
												double jointTolerance = kSeparationTolerance)
{
	const btQuaternionHingeStabilizerSettings defaults;
	const RagdollFigures bare = run(ground, count, false, defaults, layout),
						 held = run(ground, count, true, defaults, layout);
	const char* groundName = ground == RagdollGround::CollisionObject ? "btCollisionObject" : "btRigidBody";
	std::printf(
		"[ measured ] %d ragdoll(s) (%s) on a %s ground, without -> with the stabilizer (defaults): hinges %.2e -> "
		"%.2e m, cone twists %.2e -> %.2e m, resting ground penetration %.2e -> %.2e m, deepest %.2e -> %.2e m, "
		"contact rows %d, deepest sink of a part by a call %.2e m; past the limits: hinges %.2e -> %.2e rad, cone "
		"twists %.2e -> %.2e rad\n",
		count, layout == Layout::Pile ? "pile" : "crowd", groundName, bare.hinge, held.hinge, bare.cone, held.cone, bare.restDepth, held.restDepth, bare.deepest,
		held.deepest, held.contactRows, held.callSink, bare.hingePast, held.hingePast, bare.conePast, held.conePast);
	EXPECT_LE(held.hinge, jointTolerance);
	EXPECT_LE(held.cone, jointTolerance);
	EXPECT_LE(held.hingePast, kLimitPastTolerance);
	EXPECT_LE(held.conePast, kLimitPastTolerance);
	EXPECT_GT(bare.conePast, 100 * kLimitPastTolerance);  // Bullet's soft limits alone: the scene asks the question
	EXPECT_LE(held.restDepth, bare.restDepth);
	EXPECT_LE(held.callSink, kCallSink);
	EXPECT_GT(held.contactRows, 0);
	EXPECT_EQ(held.skipped, 0);
	return {bare, held};
}

// projectConeTwistLimits off (the default before 0.2.0's last change): the cone twists' limits are Bullet's alone, and
// the projection, which moves their bodies to close the joints without seeing those limits, leaves them further past
// than Bullet alone does. `bare` and `held`: the same world's runs without the stabilizer and with its defaults.
void checkWithoutConeLimits(int count, const RagdollFigures& bare, const RagdollFigures& held)
{
	btQuaternionHingeStabilizerSettings settings;
	settings.projectConeTwistLimits = false;
	const RagdollFigures off = run(RagdollGround::CollisionObject, count, true, settings);
	std::printf(
		"[ measured ] %d ragdoll(s), projectConeTwistLimits off: joints %.2e m (hinges), %.2e m (cone twists); cone "
		"twists past their limits %.2e rad (without the stabilizer %.2e rad, with its defaults %.2e rad); resting "
		"ground penetration %.2e m, deepest %.2e m, deepest sink by a call %.2e m\n",
		count, off.hinge, off.cone, off.conePast, bare.conePast, held.conePast, off.restDepth, off.deepest, off.callSink);
	EXPECT_LE(off.hinge, kSeparationTolerance);
	EXPECT_LE(off.cone, kSeparationTolerance);
	EXPECT_GT(off.conePast, bare.conePast);
	EXPECT_LE(off.restDepth, bare.restDepth);
	EXPECT_LE(off.callSink, kCallSink);
}
}  // namespace

// On the btCollisionObject ground (RagdollDemo's), each world also runs with projectConeTwistLimits off.
TEST(StabilizerRagdollDemo, OneRagdollOnACollisionObjectGround)
{
	const auto figures = check(RagdollGround::CollisionObject, 1);
	checkWithoutConeLimits(1, figures.first, figures.second);
}
TEST(StabilizerRagdollDemo, OneRagdollOnARigidBodyGround) { check(RagdollGround::StaticBody, 1); }
TEST(StabilizerRagdollDemo, APileOfTwentyOnACollisionObjectGround)
{
#ifdef QUATHINGE_SANITIZED_TESTS
	// Under ASan + UBSan the pile's islands (loops through the contacts between the ragdolls: the block LDLᵀ's Eigen
	// products and the checks of their temporaries) take five minutes or more of CI's sanitizer stage. That build runs
	// the same projection, contact rows, loops and calls done again on StabilizerMixed's four ragdolls and
	// StabilizerContacts.APartSwungIntoAGroundItHadNoContactWithIsHeld, and the option off on the one ragdoll above;
	// every other build runs the pile.
	GTEST_SKIP() << "the sanitizer build runs this code on four ragdolls (StabilizerMixed) and the one above";
#endif
	const auto figures = check(RagdollGround::CollisionObject, 20);
	checkWithoutConeLimits(20, figures.first, figures.second);
}
TEST(StabilizerRagdollDemo, APileOfTwentyOnARigidBodyGround)
{
#ifdef QUATHINGE_SANITIZED_TESTS
	// the same projection and contact code as the pile on the btCollisionObject ground above, which the sanitizer build
	// leaves out too (the normal builds run both, with the same figures)
	GTEST_SKIP() << "the sanitizer build runs this code on four ragdolls (StabilizerMixed)";
#endif
	check(RagdollGround::StaticBody, 20);
}
namespace
{
// A crowd's joints are held to issue 38's 1e-5 m in both precisions (float: 2.3e-6 m hinges, 6.4e-6 m cone twists on
// the btCollisionObject ground). In double three calls of the 240 end at Newton's iteration cap (17 to 20 iterations,
// after a switch to the stiff metric) where Bullet's step opened a joint 0.1 to 0.18 m in the falling crowd: up to
// 4.7e-9 m, against the pile's 8e-11 m.
const double kCrowdJointTolerance = 1e-5;  // m
}  // namespace

TEST(StabilizerRagdollDemo, ACrowdOfAHundredOnACollisionObjectGround)
{
#ifdef QUATHINGE_SANITIZED_TESTS
	// the same projection and contact code as the pile of twenty, which the sanitizer build leaves out too
	GTEST_SKIP() << "the sanitizer build runs this code on four ragdolls (StabilizerMixed)";
#endif
	check(RagdollGround::CollisionObject, 100, Layout::Crowd, kCrowdJointTolerance);
}
TEST(StabilizerRagdollDemo, ACrowdOfAHundredOnARigidBodyGround)
{
#ifdef QUATHINGE_SANITIZED_TESTS
	GTEST_SKIP() << "the sanitizer build runs this code on four ragdolls (StabilizerMixed)";
#endif
	check(RagdollGround::StaticBody, 100, Layout::Crowd, kCrowdJointTolerance);
}
TEST(StabilizerRagdollDemo, OneHangingByItsHeadFromAPoint)
{
	// A ragdoll hung by its head from a fixed point (a btPoint2PointConstraint to the world, 2 m above the ground),
	// spun, swinging for 4 s: with the defaults every joint, the hanging point's included, holds from t = 0.5 s and
	// every hinge and cone twist stays within its limits; without the stabilizer they part and go past.
	for (bool stabilized : {false, true})
	{
		RagdollDemoWorld w(RagdollGround::CollisionObject);
		w.addRagdoll(btVector3(0, 1, 0), btScalar(0.3), btScalar(2));
		std::vector<double> depths;
		std::vector<const btCollisionObject*> parts;
		w.partPenetrations(depths, &parts);
		ASSERT_GE(parts.size(), size_t(3));
		// RagdollDemo's parts: pelvis, spine, head, …
		btRigidBody& head = *const_cast<btRigidBody*>(btRigidBody::upcast(parts[2]));
		const btVector3 top(0, btScalar(0.1), 0);  // on the head's axis, above its centre
		btPoint2PointConstraint hang(head, top);   // to the world where that point is now
		w.world().addConstraint(&hang, true);
		btQuaternionHingeStabilizer stabilizer;
		if (stabilized) w.world().addAction(&stabilizer);
		double hinge = 0, cone = 0, point = 0, hingePast = 0, conePast = 0;
		for (int s = 0; s < 240; ++s)
		{
			w.world().stepSimulation(kTimeStep, 0, kTimeStep);
			if (s + 1 < 30) continue;
			double h = 0, c = 0;
			w.jointSeparations(h, c);
			hinge = std::max(hinge, h);
			cone = std::max(cone, c);
			point = std::max(point, double((head.getCenterOfMassTransform() * hang.getPivotInA() - hang.getPivotInB()).length()));
			w.limitsPast(h, c);
			hingePast = std::max(hingePast, h);
			conePast = std::max(conePast, c);
		}
		if (stabilized) w.world().removeAction(&stabilizer);
		w.world().removeConstraint(&hang);
		std::printf(
			"[ measured ] a ragdoll hanging by its head, %s: hinges %.2e m, cone twists %.2e m, the hanging point "
			"%.2e m; past the limits: hinges %.2e rad, cone twists %.2e rad\n",
			stabilized ? "defaults" : "no stabilizer", hinge, cone, point, hingePast, conePast);
		if (!stabilized)
		{
			EXPECT_GT(std::max(hinge, cone), 10 * kSeparationTolerance);  // the scene asks the question
			continue;
		}
		EXPECT_LE(hinge, kSeparationTolerance);
		EXPECT_LE(cone, kSeparationTolerance);
		EXPECT_LE(point, kSeparationTolerance);
		EXPECT_LE(hingePast, kLimitPastTolerance);
		EXPECT_LE(conePast, kLimitPastTolerance);
	}
}
#endif
