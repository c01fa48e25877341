// projectPointConstraints: the stabilizer also projects the pivots of Bullet's btPoint2PointConstraint and
// btConeTwistConstraint, so a body mixing them with quaternion hinges holds together at every joint; off (the
// default) they are not seen.
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/StabilizerScene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

using namespace qh_test;

namespace
{
const btScalar kLink = btScalar(0.5);  // m, link length

// Largest pivot separation (m) over the scene's point constraints (their world pivots).
double pointSeparation(const std::vector<btTypedConstraint*>& points)
{
	double worst = 0;
	for (const btTypedConstraint* c : points)
	{
		btVector3 inA, inB;
		if (c->getConstraintType() == POINT2POINT_CONSTRAINT_TYPE)
		{
			inA = static_cast<const btPoint2PointConstraint*>(c)->getPivotInA();
			inB = static_cast<const btPoint2PointConstraint*>(c)->getPivotInB();
		}
		else
		{
			inA = static_cast<const btConeTwistConstraint*>(c)->getAFrame().getOrigin();
			inB = static_cast<const btConeTwistConstraint*>(c)->getBFrame().getOrigin();
		}
		const btVector3 a = c->getRigidBodyA().getCenterOfMassTransform() * inA;
		const btVector3 b = c->getRigidBodyB().getCenterOfMassTransform() * inB;
		worst = std::max(worst, double((b - a).length()));
	}
	return worst;
}

// A 6-link chain released horizontally at 10 m, hung from the world by a quaternion hinge; its joints alternate:
// hinge (z), point-to-point, hinge (y), cone twist, hinge (z), point-to-point. The last link is `lastMass` kg.
struct MixedChain
{
	StabilizerScene scene;
	std::vector<btTypedConstraint*> points;
	explicit MixedChain(btScalar lastMass = 1)
	{
		std::vector<btRigidBody*> links;
		for (int i = 0; i < 6; ++i)
			links.push_back(scene.box(btVector3(kLink / 2, btScalar(0.05), btScalar(0.05)), i == 5 ? lastMass : 1,
									  btVector3(kLink * (btScalar(i) + btScalar(0.5)), 10, 0)));
		const btVector3 left(-kLink / 2, 0, 0), right(kLink / 2, 0, 0);
		scene.hingeToWorld(*links[0], left, btVector3(0, 0, 1));
		for (int i = 1; i < 6; ++i)
		{
			btRigidBody& a = *links[size_t(i - 1)];
			btRigidBody& b = *links[size_t(i)];
			if (i % 2 == 0)
			{
				const btVector3 axis = i % 4 == 0 ? btVector3(0, 0, 1) : btVector3(0, 1, 0);
				scene.hinge(a, b, right, left, axis, axis);
				continue;
			}
			btTypedConstraint* c;
			if (i == 3)
			{
				btTransform fa = btTransform::getIdentity(), fb = btTransform::getIdentity();
				fa.setOrigin(right);
				fb.setOrigin(left);
				auto* cone = new btConeTwistConstraint(a, b, fa, fb);
				cone->setLimit(btScalar(0.8), btScalar(0.8), btScalar(0.5));
				c = cone;
			}
			else
				c = new btPoint2PointConstraint(a, b, right, left);
			scene.addConstraint(c);
			points.push_back(c);
		}
	}
	// Steps 2 s; the largest hinge and point separations seen after any step (m).
	void run(double& hingeWorst, double& pointWorst, int steps = 120)
	{
		hingeWorst = pointWorst = 0;
		for (int i = 0; i < steps; ++i)
		{
			scene.world().stepSimulation(kTimeStep, 0);
			double separation, misalignment;
			scene.jointErrors(separation, misalignment);
			hingeWorst = std::max(hingeWorst, separation);
			pointWorst = std::max(pointWorst, pointSeparation(points));
		}
	}
};
}  // namespace

TEST(StabilizerPoints, MixedChainHoldsAtEveryJointWithTheOptionAndOnlyAtItsHingesWithout)
{
	MixedChain on, off;
	btQuaternionHingeStabilizerSettings settings = qh_test::hingesOnly();
	settings.projectPointConstraints = true;
	// (the 6-dof hinge is projected as a hinge by default, projectDofHinges: tests/test_stabilizer_stock.cpp; the
	// stabilizer without the option here sees the quaternion hinges alone)
	btQuaternionHingeStabilizerSettings quaternionOnly = qh_test::hingesOnly();
	quaternionOnly.projectDofHinges = false;
	btQuaternionHingeStabilizer withPoints(settings), hingesOnly(quaternionOnly);
	on.scene.addAction(&withPoints);
	off.scene.addAction(&hingesOnly);
	double onHinge, onPoint, offHinge, offPoint;
	on.run(onHinge, onPoint);
	off.run(offHinge, offPoint);
	std::printf(
		"[ figures  ] mixed chain, largest separation (m): option on hinges %.2e points %.2e; off hinges %.2e "
		"points %.2e\n",
		onHinge, onPoint, offHinge, offPoint);
	EXPECT_EQ(withPoints.getLastStats().joints, 6);
	EXPECT_EQ(withPoints.getLastStats().islands, 1);
	EXPECT_EQ(hingesOnly.getLastStats().joints, 3);
	EXPECT_EQ(hingesOnly.getLastStats().islands, 3);  // the point constraints no longer connect the hinges
	EXPECT_LE(onHinge, kSeparationTolerance);
	EXPECT_LE(onPoint, kSeparationTolerance);
	EXPECT_LE(offHinge, kSeparationTolerance);
	EXPECT_GT(offPoint, 100 * kSeparationTolerance);  // the solver alone leaves the point constraints apart
	ASSERT_TRUE(on.scene.allFinite());
}

TEST(StabilizerPoints, HeavyLoadOnAMixedChainHolds)
{
	// 1:100 at the end: the projection's metric and its step control serve point rows as they serve a hinge's.
	MixedChain chain(100);
	btQuaternionHingeStabilizerSettings settings;
	settings.projectPointConstraints = true;
	btQuaternionHingeStabilizer stabilizer(settings);
	chain.scene.addAction(&stabilizer);
	double hinge, point;
	chain.run(hinge, point);
	std::printf("[ figures  ] mixed chain 1:100, largest separation (m): hinges %.2e points %.2e\n", hinge, point);
	EXPECT_LE(hinge, kHeavySeparationTolerance);
	EXPECT_LE(point, kHeavySeparationTolerance);
	EXPECT_EQ(stabilizer.getLastStats().numericalIssues, 0);
}

TEST(StabilizerPoints, AngularOnlyConeTwistAndFilteredPointsAreLeftOut)
{
	MixedChain chain;
	static_cast<btConeTwistConstraint*>(chain.points[1])->setAngularOnly(true);  // no pivot to hold
	struct NoPointToPoint : btQuaternionHingeStabilizerFilter
	{
		bool needsStabilization(const btTypedConstraint& c) const override
		{
			return c.getConstraintType() != POINT2POINT_CONSTRAINT_TYPE;
		}
	} filter;
	btQuaternionHingeStabilizerSettings settings;
	settings.projectPointConstraints = true;
	btQuaternionHingeStabilizer stabilizer(settings);
	stabilizer.setFilter(&filter);
	chain.scene.addAction(&stabilizer);
	chain.scene.world().stepSimulation(kTimeStep, 0);
	EXPECT_EQ(stabilizer.getLastStats().joints, 3);          // the three hinges
	EXPECT_EQ(stabilizer.getLastStats().filteredJoints, 2);  // the two point-to-points
	// switched off again through setSettings: only the hinges, nothing filtered
	settings.projectPointConstraints = false;
	stabilizer.setSettings(settings);
	stabilizer.setFilter(nullptr);
	chain.scene.world().stepSimulation(kTimeStep, 0);
	EXPECT_TRUE(stabilizer.getLastStats().structureRebuilt);
	EXPECT_EQ(stabilizer.getLastStats().joints, 3);
	EXPECT_EQ(stabilizer.getLastStats().filteredJoints, 0);
}

TEST(StabilizerPoints, PointToPointChainAloneIsProjected)
{
	// No quaternion hinge at all: five point-to-point links hung from the world, held to tolerance.
	StabilizerScene scene;
	std::vector<btTypedConstraint*> points;
	btRigidBody* previous = nullptr;
	for (int i = 0; i < 5; ++i)
	{
		btRigidBody* link = scene.box(btVector3(kLink / 2, btScalar(0.05), btScalar(0.05)), 1,
									  btVector3(kLink * (btScalar(i) + btScalar(0.5)), 10, 0));
		btTypedConstraint* c = previous ? new btPoint2PointConstraint(*previous, *link, btVector3(kLink / 2, 0, 0),
																	  btVector3(-kLink / 2, 0, 0))
										: new btPoint2PointConstraint(*link, btVector3(-kLink / 2, 0, 0));
		scene.addConstraint(c);
		points.push_back(c);
		previous = link;
	}
	btQuaternionHingeStabilizerSettings settings;
	settings.projectPointConstraints = true;
	btQuaternionHingeStabilizer stabilizer(settings);
	scene.addAction(&stabilizer);
	double worst = 0;
	for (int i = 0; i < 120; ++i)
	{
		scene.world().stepSimulation(kTimeStep, 0);
		worst = std::max(worst, pointSeparation(points));
	}
	EXPECT_EQ(stabilizer.getLastStats().joints, 5);
	EXPECT_LE(worst, kSeparationTolerance);
}
TEST(StabilizerPoints, HangingMixedChainAtRestIsReplayedAndAMovedPivotIsProjectedAgain)
{
	// Straight down from the world: hinge, point-to-point, hinge, point-to-point; at rest after a few steps, every
	// step is a replay of the last projection (its inputs, the point constraints' pivots included, unchanged to the
	// bit). A point-to-point's pivot moved by 1 mm, nothing else, is a changed input: projected again, and held.
	StabilizerScene scene;
	std::vector<btTypedConstraint*> points;
	btRigidBody* previous = nullptr;
	const btVector3 top(0, btScalar(0.25), 0), bottom(0, btScalar(-0.25), 0);
	for (int i = 0; i < 4; ++i)
	{
		btRigidBody* link = scene.box(btVector3(btScalar(0.05), btScalar(0.25), btScalar(0.05)), 1,
									  btVector3(0, btScalar(-0.25 - 0.5 * i), 0));
		if (!previous)
			scene.hingeToWorld(*link, top, btVector3(0, 0, 1));
		else if (i % 2 == 0)
			scene.hinge(*previous, *link, bottom, top, btVector3(0, 0, 1), btVector3(0, 0, 1));
		else
		{
			btTypedConstraint* c = new btPoint2PointConstraint(*previous, *link, bottom, top);
			scene.addConstraint(c);
			points.push_back(c);
		}
		previous = link;
	}
	btQuaternionHingeStabilizerSettings settings;
	settings.projectPointConstraints = true;
	btQuaternionHingeStabilizer stabilizer(settings);
	scene.addAction(&stabilizer);
	for (int i = 0; i < 60; ++i) scene.world().stepSimulation(kTimeStep, 0, kTimeStep);
	EXPECT_EQ(stabilizer.getLastStats().joints, 4);
	EXPECT_EQ(stabilizer.getLastStats().restingIslands, 1);
	EXPECT_EQ(stabilizer.getLastStats().factorizations, 0);
	EXPECT_LE(pointSeparation(points), kSeparationTolerance);
	// The pivot alone: the bodies put back as they were, the projection called directly (no solver step between).
	const std::vector<btTransform> poses = scene.poses();
	auto putBack = [&] { scene.setPoses(poses); };
	stabilizer.stabilize(&scene.world(), kTimeStep);  // keeps these inputs
	putBack();
	stabilizer.stabilize(&scene.world(), kTimeStep);
	EXPECT_EQ(stabilizer.getLastStats().restingIslands, 1);  // the control: nothing changed
	putBack();
	static_cast<btPoint2PointConstraint*>(points[0])->setPivotB(top + btVector3(btScalar(1e-3), 0, 0));
	stabilizer.stabilize(&scene.world(), kTimeStep);
	EXPECT_EQ(stabilizer.getLastStats().restingIslands, 0);
	EXPECT_GT(stabilizer.getLastStats().factorizations, 0);
	EXPECT_LE(pointSeparation(points), kSeparationTolerance);
}

namespace
{
// A 6-dof's pivot separation (m): |p_B − p_A| with A's pivot frame A's origin moved by the locked linear values
// along frame A's axes (the constraint's own reading of its locked axes, measured here independently of PointRows.h).
double dofSeparation(btGeneric6DofSpring2Constraint& dof)
{
	btVector3 low;
	dof.getLinearLowerLimit(low);
	const btVector3 a = dof.getRigidBodyA().getCenterOfMassTransform() * (dof.getFrameOffsetA() * low);
	const btVector3 b = dof.getRigidBodyB().getCenterOfMassTransform() * dof.getFrameOffsetB().getOrigin();
	return double((b - a).length());
}
}  // namespace

TEST(StabilizerPoints, SixDofWithItsLinearAxesLockedIsAPointConstraint)
{
	// A 5-link chain released horizontally: hinge to the world, then a 6-dof ball (linear axes locked at a 2 cm offset
	// along frame A's x, angles free), a hinge, a 6-dof hinge (linear axes locked at 0, its x and y angles locked, z
	// free), and a weld (btFixedConstraint) to a last small box. With the option the two 6-dofs' pivots are projected
	// as point constraints and hold; the weld is not one (its orientation is locked too), nor is anything without it.
	const btVector3 left(-kLink / 2, 0, 0), right(kLink / 2, 0, 0);
	const btScalar offset = btScalar(0.02);
	auto build = [&](StabilizerScene& scene, std::vector<btGeneric6DofSpring2Constraint*>& dofs) {
		std::vector<btRigidBody*> links;
		btScalar x = 0;
		for (int i = 0; i < 4; ++i)
		{
			links.push_back(scene.box(btVector3(kLink / 2, btScalar(0.05), btScalar(0.05)), 1,
									  btVector3(x + kLink / 2, 10, 0)));
			x += kLink + (i == 0 ? offset : 0);  // the ball holds its links 2 cm apart along x
		}
		scene.hingeToWorld(*links[0], left, btVector3(0, 0, 1));
		btTransform fa = btTransform::getIdentity(), fb = btTransform::getIdentity();
		fa.setOrigin(right);
		fb.setOrigin(left);
		auto* ball = new btGeneric6DofSpring2Constraint(*links[0], *links[1], fa, fb);
		ball->setLinearLowerLimit(btVector3(offset, 0, 0));
		ball->setLinearUpperLimit(btVector3(offset, 0, 0));
		ball->setAngularLowerLimit(btVector3(1, 1, 1));  // lower > upper: free
		ball->setAngularUpperLimit(btVector3(-1, -1, -1));
		scene.addConstraint(ball);
		scene.hinge(*links[1], *links[2], right, left, btVector3(0, 1, 0), btVector3(0, 1, 0));
		auto* dofHinge = new btGeneric6DofSpring2Constraint(*links[2], *links[3], fa, fb);
		dofHinge->setLinearLowerLimit(btVector3(0, 0, 0));
		dofHinge->setLinearUpperLimit(btVector3(0, 0, 0));
		dofHinge->setAngularLowerLimit(btVector3(0, 0, 1));
		dofHinge->setAngularUpperLimit(btVector3(0, 0, -1));
		scene.addConstraint(dofHinge);
		btRigidBody* tool = scene.box(btVector3(btScalar(0.05), btScalar(0.05), btScalar(0.05)), btScalar(0.1),
									  btVector3(x + btScalar(0.05), 10, 0));
		btTransform ta = btTransform::getIdentity(), tb = btTransform::getIdentity();
		ta.setOrigin(right);
		tb.setOrigin(btVector3(btScalar(-0.05), 0, 0));
		scene.addConstraint(new btFixedConstraint(*links[3], *tool, ta, tb));
		dofs = {ball, dofHinge};
	};
	StabilizerScene on, off;
	std::vector<btGeneric6DofSpring2Constraint*> dofsOn, dofsOff;
	build(on, dofsOn);
	build(off, dofsOff);
	btQuaternionHingeStabilizerSettings settings = qh_test::hingesOnly();
	settings.projectPointConstraints = true;
	// (the 6-dof hinge is projected as a hinge by default, projectDofHinges: tests/test_stabilizer_stock.cpp; the
	// stabilizer without the option here sees the quaternion hinges alone)
	btQuaternionHingeStabilizerSettings quaternionOnly = qh_test::hingesOnly();
	quaternionOnly.projectDofHinges = false;
	btQuaternionHingeStabilizer withPoints(settings), hingesOnly(quaternionOnly);
	on.addAction(&withPoints);
	off.addAction(&hingesOnly);
	double worstOn = 0, worstOff = 0, hingeOn = 0;
	for (int i = 0; i < 120; ++i)
	{
		on.world().stepSimulation(kTimeStep, 0);
		off.world().stepSimulation(kTimeStep, 0);
		for (btGeneric6DofSpring2Constraint* d : dofsOn) worstOn = std::max(worstOn, dofSeparation(*d));
		for (btGeneric6DofSpring2Constraint* d : dofsOff) worstOff = std::max(worstOff, dofSeparation(*d));
		double separation, misalignment;
		on.jointErrors(separation, misalignment);
		hingeOn = std::max(hingeOn, separation);
	}
	std::printf("[ figures  ] 6-dof points, largest separation (m): option on %.2e (hinges %.2e); off %.2e\n", worstOn,
				hingeOn, worstOff);
	EXPECT_EQ(withPoints.getLastStats().joints, 4);            // two hinges, two 6-dofs; not the weld
	EXPECT_EQ(withPoints.getLastStats().pointConstraints, 1);  // the ball; the 6-dof hinge is a hinge
	EXPECT_EQ(withPoints.getLastStats().dofHinges, 1);
	EXPECT_EQ(withPoints.getLastStats().islands, 1);
	EXPECT_EQ(hingesOnly.getLastStats().joints, 2);
	EXPECT_LE(worstOn, kSeparationTolerance);
	EXPECT_LE(hingeOn, kSeparationTolerance);
	EXPECT_GT(worstOff, 100 * kSeparationTolerance);  // the solver alone leaves them apart
	ASSERT_TRUE(on.allFinite());
	// unlocking a linear axis makes the ball a slider: no longer a point constraint (the islands are rebuilt)
	dofsOn[0]->setLinearLowerLimit(btVector3(offset, 0, -1));
	dofsOn[0]->setLinearUpperLimit(btVector3(offset, 0, 1));
	on.world().stepSimulation(kTimeStep, 0);
	EXPECT_TRUE(withPoints.getLastStats().structureRebuilt);
	EXPECT_EQ(withPoints.getLastStats().joints, 3);
}
#endif  // QUATHINGE_HAVE_STABILIZER
