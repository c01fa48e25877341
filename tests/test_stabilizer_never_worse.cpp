// The stabilizer with its defaults never makes a constraint worse: in every scene of the demo's library (the robots
// included) and each maximal-coordinate kind Bullet apps build (stock hinges, 6-dofs as Bullet's URDF importer builds
// them, quaternion hinges), after each call no joint is further apart (pivots, axes, past a limit) and no contact
// deeper than before that call. Each step: Bullet's step, the errors measured, the stabilizer's projection
// (stabilize), the errors measured again.
#if defined(QUATHINGE_HAVE_STABILIZER) && defined(QUATHINGE_HAVE_SCENES)
#include "JointKinds.h"
#include "SceneSpec.h"
#include "support/SceneRuns.h"
#include "Simulation.h"
#include "quathinge/btQuaternionHingeStabilizer.h"

#include <btBulletDynamicsCommon.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

using namespace quathinge::scenes;

namespace
{
const double kWorseSeparation = 1e-6;  // m: a joint's pivots or a slider's line, past what they were before the call
// … plus what the precision cannot resolve there: a body's position is stored in btScalar, so a pivot at |x| moves in
// steps of one unit in the last place of |x| (float: 2^-18 m = 3.8e-6 m from 32 to 64 m from the origin, where
// chain100's far links are; double: 7e-15 m), and two pivots' distance changes by such a step however small the
// projection's move. Without it chain100 (float) measures 3.81e-6 m, one such step, in all three kinds (printed).
double resolution(const btVector3& a, const btVector3& b)
{
	btScalar largest = 0;
	for (int k = 0; k < 3; ++k) largest = std::max({largest, btFabs(a[k]), btFabs(b[k])});
	return double(std::nextafter(largest, btScalar(SIMD_INFINITY)) - largest);
}

// The pivots of a measured joint or slider in world, now.
double pivotResolution(const MeasuredJoint& j)
{
	return resolution(j.a->getCenterOfMassTransform() * j.frameA.getOrigin(), j.b->getCenterOfMassTransform() * j.frameB.getOrigin());
}
const double kWorseAngle = 1e-5;  // rad: a joint's axes or its angle past a stop
const double kWorseDepth = 1e-6;  // m: a contact point's penetration

// Every measured error of the world now, in a fixed order (the manifolds' points are not changed by the projection):
// per joint its pivot separation (m), axis misalignment (rad) and how far its angle is past a stop (rad); per slider
// its distance from the slide line and how far past its limits (m); per contact point its penetration (m, ≥ 0) at the bodies' current poses.
struct Errors
{
	std::vector<double> separation, angle, depth;
	std::vector<double> resolution;  // m, per separation: resolution() of its pivots
};

Errors measure(Simulation& sim)
{
	Errors e;
	for (MeasuredJoint& j : sim.joints)
	{
		const JointError je = measureJointError(j);
		e.separation.push_back(je.separation);
		e.resolution.push_back(pivotResolution(j));
		e.angle.push_back(je.misalignmentDeg * M_PI / 180);
		if (j.hasLimit)
		{
			trackTheta(j);  // the continuous angle from the frames
			e.angle.push_back(std::max({0.0, j.lower - j.theta, j.theta - j.upper}));
		}
	}
	for (const MeasuredJoint& s : sim.sliders)
	{
		e.separation.push_back(measureSliderSeparation(s));
		e.resolution.push_back(pivotResolution(s));
		if (!s.hasLimit) continue;
		e.separation.push_back(measureSliderPastLimits(s));
		e.resolution.push_back(pivotResolution(s));
	}
	btDispatcher& d = *sim.world().getDispatcher();
	for (int m = 0; m < d.getNumManifolds(); ++m)
	{
		const btPersistentManifold* manifold = d.getManifoldByIndexInternal(m);
		const btTransform& ta = manifold->getBody0()->getWorldTransform();
		const btTransform& tb = manifold->getBody1()->getWorldTransform();
		for (int p = 0; p < manifold->getNumContacts(); ++p)
		{
			const btManifoldPoint& point = manifold->getContactPoint(p);
			const double distance = double(point.m_normalWorldOnB.dot(ta * point.m_localPointA - tb * point.m_localPointB));
			e.depth.push_back(std::max(0.0, -distance));
		}
	}
	return e;
}

// The largest amount by which an entry of `after` exceeds its entry of `before` (less `unresolved[i]`, if given).
double worsening(const std::vector<double>& before, const std::vector<double>& after,
				 const std::vector<double>* unresolved = nullptr)
{
	double worst = 0;
	for (size_t i = 0; i < std::min(before.size(), after.size()); ++i)
		worst = std::max(worst, after[i] - before[i] - (unresolved ? (*unresolved)[i] : 0.0));
	return worst;
}
}  // namespace

TEST(StabilizerNeverWorse, NoConstraintOfAnyLibrarySceneIsFurtherFromSatisfiedAfterACall)
{
	const double dt = 1.0 / 60;
	const int steps = 60;  // 1 s: the starts (flipped, separated), the first contacts, the swings
	int worlds = 0;
	for (const SceneSpec& scene : qh_test::availableScenes())
	{
		const std::string& name = scene.name;
		for (Kind kind : {Kind::Stock, Kind::Generic6Dof2, Kind::Quaternion})
		{
			Simulation sim(scene, kind);
			btQuaternionHingeStabilizer stabilizer;                // the defaults
			double separation = 0, angle = 0, depth = 0, raw = 0;  // raw: the separations' without the resolution
			int skipped = 0;
			for (int s = 0; s < steps; ++s)
			{
				sim.step(dt, 10);
				const Errors before = measure(sim);
				const btQuaternionHingeStabilizerStats& stats = stabilizer.stabilize(&sim.world(), btScalar(dt));
				skipped = std::max(skipped, stats.skippedByOption + stats.skippedUnexpressible + stats.skippedFaulted);
				const Errors after = measure(sim);
				separation = std::max(separation, worsening(before.separation, after.separation, &after.resolution));
				raw = std::max(raw, worsening(before.separation, after.separation));
				angle = std::max(angle, worsening(before.angle, after.angle));
				depth = std::max(depth, worsening(before.depth, after.depth));
			}
			++worlds;
			std::printf(
				"[ measured ] %-16s %-10s worst worsening in a call: %.2e m (%.2e m with the unresolved step), "
				"%.2e rad, contacts %.2e m\n",
				name.c_str(), kindName(kind).c_str(), separation, raw, angle, depth);
			EXPECT_LE(separation, kWorseSeparation) << name << " " << kindName(kind);
			EXPECT_LE(angle, kWorseAngle) << name << " " << kindName(kind);
			EXPECT_LE(depth, kWorseDepth) << name << " " << kindName(kind);
			EXPECT_EQ(skipped, 0) << name << " " << kindName(kind) << ": every joint of the listed kinds projected";
		}
	}
	EXPECT_GT(worlds, 0);
}
#endif
