// A btConeTwistConstraint's swing and twist limits as limit rows of the projection (plugin/stabilizer/ConeTwistRows.h;
// docs/MATH.md, "Cone-twist limits"): their gradients are the exact derivatives of their variables (finite
// differences), the variables mean what Bullet's cone twist reads (isPastSwingLimit, getTwistAngle), and which limits
// become rows follows Bullet's own rules. The ragdolls that use them: tests/test_stabilizer_ragdoll_demo.cpp.
#ifdef QUATHINGE_HAVE_STABILIZER
#include "ConeTwistRows.h"
#include "support/RandomPoses.h"
#include "support/RowDerivatives.h"
#include "support/World.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

using namespace qh_test;
namespace qs = quathinge::stabilizer;

namespace
{

// A cone twist between frames random in the bodies, spans 0.2–1.4 rad (swing) and 0–1.4 rad (twist), and the bodies
// placed so that frame B is turned from frame A by up to `reach` rad.
struct ConeCase
{
	std::unique_ptr<btConeTwistConstraint> cone;
	btTransform tA, tB;
	ConeCase(RandomPoses& p, double reach)
	{
		const btTransform fa(p.unit(), p.vec(0.3)), fb(p.unit(), p.vec(0.3));
		cone.reset(new btConeTwistConstraint(p.a, p.b, fa, fb));
		cone->setLimit(btScalar(0.8 + 0.6 * p.number()), btScalar(0.8 + 0.6 * p.number()), btScalar(0.7 + 0.7 * p.number()));
		tA = btTransform(p.unit(), p.vec(2));
		const btTransform frameAWorld = tA * fa;
		const btTransform frameBWorld(expRotation(p.vec(reach / std::sqrt(3.0))) * frameAWorld.getRotation(),
									  frameAWorld.getOrigin() + p.vec(0.1));
		tB = frameBWorld * fb.inverse();
	}
};
}  // namespace

TEST(StabilizerConeLimits, GradientsAreTheDerivativeOfTheVariables)
{
	// The swing variable θ − L and the twist τ under small turns of either body (support/RowDerivatives.h: the step
	// and the tolerance), against their gradients (d/dt = g · (ω_B − ω_A): −g on ω_A's columns, g on ω_B's, nothing
	// linear). Seeded random frames, spans and relative turns up to 2.5 rad; where the swing is within 0.05 rad of 0
	// or of a half turn (no direction), or the twist within 0.05 rad of a half turn (where it wraps), there is no
	// derivative to take. The swing variable's third derivative is large on a narrow ellipse (spans 0.2 and 1.4 rad:
	// the bound turns by (1.4/0.2)³ over a turn of the direction, which moves by the step over sin θ), so float takes
	// a step of 1e-3 rad, not ε^⅓ ≈ 5e-3: its truncation error, ~h²/6 · 10⁴ at θ = 0.35 rad, is 0.03 at the default
	// (measured: up to 1%), 2e-3 at this step, with rounding ε/h ≈ 1e-4.
	const btScalar kSwingStep = kDouble ? rowDerivativeStep() : btScalar(1e-3);
	RandomPoses p(31);
	int checked = 0;
	for (int n = 0; n < 200; ++n)
	{
		ConeCase k(p, 2.5);
		const qs::ConeLimits limits = qs::coneLimits(*k.cone);
		ASSERT_TRUE(limits.swing && limits.twist);
		btVector3 gs, gt;
		qs::coneSwingVariable(*k.cone, limits, k.tA, k.tB, gs);
		const double twist = double(qs::coneTwistVariable(*k.cone, k.tA, k.tB, gt));
		const btVector3 xA = (k.tA.getBasis() * k.cone->getAFrame().getBasis()).getColumn(0);
		const btVector3 xB = (k.tB.getBasis() * k.cone->getBFrame().getBasis()).getColumn(0);
		const double swing = std::atan2(double(xA.cross(xB).length()), double(xA.dot(xB)));
		if (swing < 0.05 || swing > M_PI - 0.05 || std::fabs(twist) > M_PI - 0.05) continue;
		auto values = [&](const btTransform& ta, const btTransform& tb, double* out) {
			btVector3 unused;
			out[0] = double(qs::coneSwingVariable(*k.cone, limits, ta, tb, unused));
			out[1] = double(qs::coneTwistVariable(*k.cone, ta, tb, unused));
		};
		auto derivative = [&](int r, int column) {
			const btVector3& g = r == 0 ? gs : gt;
			if (column >= 3 && column < 6) return -double(g[column - 3]);
			if (column >= 9) return double(g[column - 9]);
			return 0.0;
		};
		expectRowDerivatives(values, derivative, k.tA, k.tB, 2, "configuration " + std::to_string(n), kSwingStep);
		++checked;
	}
	EXPECT_GT(checked, 150);
}

TEST(StabilizerConeLimits, VariablesMeanWhatBulletReads)
{
	// At the same transforms Bullet's cone twist reads itself (calcAngleInfo2): past its swing limit exactly where the
	// swing variable is positive (elliptical cones: which span bounds which direction), and its twist angle is |τ|.
	// Configurations within 1e-4 rad of the swing bound are not judged (rounding decides there).
	RandomPoses p(32);
	int judged = 0, past = 0;
	// rad: Bullet reads the twist as 2 acos(w) (getAngle), which near 0 resolves only to about √ε
	const double tolerance = 4 * std::sqrt(double(SIMD_EPSILON));
	for (int n = 0; n < 300; ++n)
	{
		ConeCase k(p, 2.0);
		const qs::ConeLimits limits = qs::coneLimits(*k.cone);
		btVector3 g;
		const double swing = double(qs::coneSwingVariable(*k.cone, limits, k.tA, k.tB, g));
		const double twist = double(qs::coneTwistVariable(*k.cone, k.tA, k.tB, g));
		k.cone->calcAngleInfo2(k.tA, k.tB, btMatrix3x3::getIdentity(), btMatrix3x3::getIdentity());
		EXPECT_NEAR(std::fabs(twist), double(k.cone->getTwistAngle()), tolerance) << "configuration " << n;
		if (std::fabs(swing) < 1e-4) continue;
		EXPECT_EQ(swing > 0, k.cone->isPastSwingLimit()) << "configuration " << n << ", swing variable " << swing;
		++judged;
		if (swing > 0) ++past;
	}
	EXPECT_GT(judged, 250);
	EXPECT_GT(past, 50);  // both sides of the bound were seen
	EXPECT_GT(judged - past, 50);
}

TEST(StabilizerConeLimits, RowsFollowBulletsRulesForWhichLimitsAct)
{
	// Bullet's cone twist acts on no limit while its motor is on; on the swing as a cone only with both spans at its
	// fix threshold or more (else it is a hinge or weld of its own kind); on the twist for a span of 0 or more. A
	// span of π or more never binds.
	RandomPoses p(33);
	btConeTwistConstraint cone(p.a, p.b, btTransform::getIdentity(), btTransform::getIdentity());
	cone.setLimit(btScalar(0.5), btScalar(0.7), btScalar(0.3));
	qs::ConeLimits k = qs::coneLimits(cone);
	EXPECT_TRUE(k.swing && k.twist);
	cone.setLimit(btScalar(0.5), btScalar(0.01), btScalar(-1));  // under the fix threshold (0.05); no twist limit
	k = qs::coneLimits(cone);
	EXPECT_FALSE(k.swing || k.twist);
	cone.setLimit(SIMD_PI, SIMD_PI, SIMD_PI);
	k = qs::coneLimits(cone);
	EXPECT_FALSE(k.swing || k.twist);
	cone.setLimit(btScalar(0.5), btScalar(0.7), 0);  // a twist locked at 0 (RagdollDemo's hips and shoulders)
	k = qs::coneLimits(cone);
	EXPECT_TRUE(k.swing && k.twist);
	cone.enableMotor(true);
	k = qs::coneLimits(cone);
	EXPECT_FALSE(k.swing || k.twist);
}
#endif
