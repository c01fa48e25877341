// btQuaternionHingeStabilizer (docs/MATH.md Q13, Q14): what it takes into its islands and how it solves them:
// redundant rows, block and sparse factorizations, static, kinematic and sleeping bodies, disabled and broken
// joints, mixed islands, contacts, angular-only hinges and the row structure the assembly relies on.
// One line of intent opens each test; scenes and named tolerances: support/StabilizerScene.h. Built when
// QuatHinge::Stabilizer is (QUATHINGE_HAVE_STABILIZER).
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/StabilizerScene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <new>
#include <iostream>
#include <vector>

using namespace qh_test;

TEST(Stabilizer, GroundedFourBarWithRedundantRowsStaysFinite)
{
	// A planar four-bar (3 redundant rows: K is singular) is regularized: no NaN, and its joints stay closed.
	StabilizerScene scene;
	const btScalar half = btScalar(0.25), thin = btScalar(0.03);
	btRigidBody* crank = scene.box(btVector3(thin, half, thin), 1, btVector3(0, half, 0));
	btRigidBody* coupler = scene.box(btVector3(2 * half, thin, thin), 1, btVector3(2 * half, 2 * half, 0));
	btRigidBody* rocker = scene.box(btVector3(thin, half, thin), 1, btVector3(4 * half, half, 0));
	const btVector3 z(0, 0, 1);
	scene.hingeToWorld(*crank, btVector3(0, -half, 0), z);
	scene.hinge(*crank, *coupler, btVector3(0, half, 0), btVector3(-2 * half, 0, 0), z, z);
	scene.hinge(*coupler, *rocker, btVector3(2 * half, 0, 0), btVector3(0, half, 0), z, z);
	scene.hingeToWorld(*rocker, btVector3(0, -half, 0), z);
	crank->setAngularVelocity(btVector3(0, 0, 3));
	btQuaternionHingeStabilizer stabilizer;
	scene.addAction(&stabilizer);
	btScalar worstResidual = 0;
	for (int i = 0; i < 180; ++i)
	{
		scene.world().stepSimulation(kTimeStep, 0);
		worstResidual = std::max(worstResidual, stabilizer.getLastStats().residualAfter);
		EXPECT_EQ(stabilizer.getLastStats().numericalIssues, 0);
	}
	ASSERT_TRUE(scene.allFinite());
	EXPECT_LE(worstResidual, kResidualTolerance);
	double separation, misalignment;
	scene.jointErrors(separation, misalignment);
	EXPECT_LE(separation, kSeparationTolerance);
}

namespace
{
// Four free bodies hinged in a ring (a cycle of movable bodies: no numbering along a tree of bodies is fill-free),
// in zero gravity; the first body spins.
std::vector<btRigidBody*> floatingRing(StabilizerScene& scene)
{
	scene.world().setGravity(btVector3(0, 0, 0));
	const btScalar half = btScalar(0.25), thin = btScalar(0.03);
	btRigidBody* left = scene.box(btVector3(thin, half, thin), 1, btVector3(0, half, 0));
	btRigidBody* top = scene.box(btVector3(half, thin, thin), 1, btVector3(half, 2 * half, 0));
	btRigidBody* right = scene.box(btVector3(thin, half, thin), 1, btVector3(2 * half, half, 0));
	btRigidBody* bottom = scene.box(btVector3(half, thin, thin), 1, btVector3(half, 0, 0));
	const btVector3 z(0, 0, 1);
	scene.hinge(*left, *top, btVector3(0, half, 0), btVector3(-half, 0, 0), z, z);
	scene.hinge(*top, *right, btVector3(half, 0, 0), btVector3(0, half, 0), z, z);
	scene.hinge(*right, *bottom, btVector3(0, -half, 0), btVector3(half, 0, 0), z, z);
	scene.hinge(*bottom, *left, btVector3(-half, 0, 0), btVector3(0, -half, 0), z, z);
	return {left, top, right, bottom};
}
}  // namespace

TEST(Stabilizer, FloatingClosedLoopUsesTheFillReducingOrder)
{
	// The ring is solved by the block LDLᵀ in a fill-reducing order with its fill (not the general sparse LDLᵀ), stays
	// finite and closed.
	StabilizerScene scene;
	const std::vector<btRigidBody*> ring = floatingRing(scene);
	ring[0]->setAngularVelocity(btVector3(0, 0, 4));
	ring[1]->setLinearVelocity(btVector3(0.5, 0, 0.2));
	btQuaternionHingeStabilizer stabilizer;
	scene.addAction(&stabilizer);
	for (int i = 0; i < 120; ++i)
	{
		scene.world().stepSimulation(kTimeStep, 0);
		EXPECT_LE(stabilizer.getLastStats().residualAfter, kResidualTolerance);
		EXPECT_EQ(stabilizer.getLastStats().numericalIssues, 0);
	}
	EXPECT_EQ(stabilizer.getLastStats().loopIslands, 1);
	EXPECT_EQ(stabilizer.getLastStats().sparseIslands, 0);
	ASSERT_TRUE(scene.allFinite());
}

TEST(Stabilizer, BothFactorizationsGiveTheSameProjection)
{
	// The block LDLᵀ and the general sparse LDLᵀ project the same perturbed chain (tree-ordered) and the same
	// perturbed ring (a closed loop: fill-reducing order) to the same place.
	for (bool loop : {false, true})
	{
		std::vector<btTransform> results[2];
		for (int solver = 0; solver < 2; ++solver)
		{
			StabilizerScene scene;
			std::vector<btRigidBody*> links = loop ? floatingRing(scene) : scene.chain(6);
			for (size_t i = 0; i < links.size(); ++i)
			{
				btTransform t = links[i]->getCenterOfMassTransform();
				t.setOrigin(t.getOrigin() + btVector3(0.01f * btScalar(i), -0.02f, 0.005f));
				t.setRotation(btQuaternion(btVector3(0, 1, 1).normalized(), btScalar(0.05) * btScalar(i)) * t.getRotation());
				links[i]->setCenterOfMassTransform(t);
			}
			btQuaternionHingeStabilizerSettings settings;
			settings.solver = solver == 0 ? BT_QHSTAB_SOLVER_AUTO : BT_QHSTAB_SOLVER_SPARSE_LDLT;
			btQuaternionHingeStabilizer stabilizer(settings);
			const btQuaternionHingeStabilizerStats& stats = stabilizer.stabilize(&scene.world());
			EXPECT_EQ(stats.sparseIslands, solver);
			EXPECT_EQ(stats.loopIslands, loop && solver == 0 ? 1 : 0);
			EXPECT_LE(stats.residualAfter, kResidualTolerance);
			for (btRigidBody* link : links) results[solver].push_back(link->getCenterOfMassTransform());
		}
		// m: both solve the same systems in double; they differ by the order of rounding only, amplified by the float
		// positions' resolution (~1e-6 m here).
		const btScalar agreement = btScalar(1e-5);
		for (size_t i = 0; i < results[0].size(); ++i)
		{
			EXPECT_LE((results[0][i].getOrigin() - results[1][i].getOrigin()).length(), agreement)
				<< (loop ? "ring" : "chain") << " link " << i;
			// rad: the same for the turns (the quaternions' difference, twice the angle between them for small angles)
			EXPECT_LE((results[0][i].getRotation() - results[1][i].getRotation()).length(), agreement)
				<< (loop ? "ring" : "chain") << " link " << i;
		}
	}
}

TEST(Stabilizer, StaticAndKinematicBodiesAreNeverMoved)
{
	// Infinite-mass bodies keep their exact transforms: a static anchor and a kinematic body moved by the user.
	StabilizerScene scene;
	btRigidBody* anchor = scene.box(btVector3(0.1, 0.1, 0.1), 0, btVector3(0, 5, 0));
	btRigidBody* kinematic = scene.box(btVector3(0.1, 0.1, 0.1), 0, btVector3(3, 5, 0));
	kinematic->setCollisionFlags(kinematic->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
	kinematic->setActivationState(DISABLE_DEACTIVATION);
	btRigidBody* a = scene.box(btVector3(0.25, 0.05, 0.05), 1, btVector3(0.35, 5, 0));
	btRigidBody* b = scene.box(btVector3(0.25, 0.05, 0.05), 1, btVector3(3.35, 5, 0));
	const btVector3 z(0, 0, 1);
	scene.hinge(*anchor, *a, btVector3(0.1, 0, 0), btVector3(-0.25, 0, 0), z, z);
	scene.hinge(*kinematic, *b, btVector3(0.1, 0, 0), btVector3(-0.25, 0, 0), z, z);
	btQuaternionHingeStabilizer stabilizer;
	scene.addAction(&stabilizer);
	const btTransform anchorPose = anchor->getCenterOfMassTransform();
	for (int i = 0; i < 120; ++i)
	{
		// The kinematic body is driven through its motion state, as Bullet expects.
		const btTransform kinematicPose(btQuaternion(z, btScalar(0.02) * btScalar(i)),
										btVector3(3 + btScalar(0.01) * btScalar(i), 5, 0));
		kinematic->getMotionState()->setWorldTransform(kinematicPose);
		scene.world().stepSimulation(kTimeStep, 0);
		EXPECT_TRUE(sameTransform(kinematic->getCenterOfMassTransform(), kinematicPose)) << "step " << i;
		EXPECT_TRUE(sameTransform(anchor->getCenterOfMassTransform(), anchorPose)) << "step " << i;
	}
	EXPECT_EQ(stabilizer.getLastStats().islands, 2);  // static and kinematic bodies do not connect islands
	EXPECT_EQ(stabilizer.getLastStats().bodies, 2);
	double separation, misalignment;
	scene.jointErrors(separation, misalignment);
	EXPECT_LE(separation, kSeparationTolerance);
}

TEST(Stabilizer, SleepingIslandIsLeftAlone)
{
	// A sleeping island is not touched, even with an error in it; an active island beside it is projected.
	StabilizerScene scene;
	std::vector<btRigidBody*> sleeping = scene.chain(3, 1, 10);
	scene.chain(3, 1, 20);
	for (btRigidBody* link : sleeping) link->forceActivationState(ISLAND_SLEEPING);
	btTransform t = sleeping[1]->getCenterOfMassTransform();
	t.setOrigin(t.getOrigin() + btVector3(0, 0.01, 0));  // an error the stabilizer would remove if it looked
	sleeping[1]->setCenterOfMassTransform(t);
	std::vector<btTransform> before;
	for (btRigidBody* link : sleeping) before.push_back(link->getCenterOfMassTransform());
	btQuaternionHingeStabilizer stabilizer;
	scene.addAction(&stabilizer);
	for (int i = 0; i < 30; ++i)
	{
		scene.world().stepSimulation(kTimeStep, 0);
		for (size_t k = 0; k < sleeping.size(); ++k)
			EXPECT_TRUE(sameTransform(sleeping[k]->getCenterOfMassTransform(), before[k])) << "link " << k;
	}
	EXPECT_EQ(stabilizer.getLastStats().islands, 1);
	EXPECT_EQ(stabilizer.getLastStats().joints, 3);
}

TEST(Stabilizer, AChangeInOneIslandRebuildsThatIslandOnly)
{
	// two chains, two islands: a joint disabled in the second rebuilds its island and keeps the first as it is
	StabilizerScene scene;
	scene.chain(4, 1, 10);
	scene.chain(4, 1, 20);
	btQuaternionHingeStabilizer stabilizer;
	scene.addAction(&stabilizer);
	scene.world().stepSimulation(kTimeStep, 0);
	EXPECT_EQ(stabilizer.getLastStats().islands, 2);
	EXPECT_EQ(stabilizer.getLastStats().islandsBuilt, 2);
	scene.world().stepSimulation(kTimeStep, 0);
	EXPECT_FALSE(stabilizer.getLastStats().structureRebuilt);
	EXPECT_EQ(stabilizer.getLastStats().islandsBuilt, 0);
	scene.hinges()[7]->setEnabled(false);
	scene.world().stepSimulation(kTimeStep, 0);
	EXPECT_TRUE(stabilizer.getLastStats().structureRebuilt);
	EXPECT_EQ(stabilizer.getLastStats().islands, 2);
	EXPECT_EQ(stabilizer.getLastStats().islandsBuilt, 1);
	double separation = 0, misalignment = 0;
	scene.jointErrors(separation, misalignment);
	EXPECT_LE(separation, kSeparationTolerance);
}

TEST(Stabilizer, DisabledAndBrokenJointsAreSkipped)
{
	// A disabled joint and a joint broken by its impulse threshold are not projected: their bodies part.
	StabilizerScene scene;
	std::vector<btRigidBody*> links = scene.chain(4);
	btQuaternionHingeStabilizer stabilizer;
	scene.addAction(&stabilizer);
	scene.world().stepSimulation(kTimeStep, 0);
	EXPECT_EQ(stabilizer.getLastStats().joints, 4);

	btQuaternionHingeConstraint* last = scene.hinges()[3];
	last->setEnabled(false);
	scene.world().stepSimulation(kTimeStep, 0);
	EXPECT_TRUE(stabilizer.getLastStats().structureRebuilt);
	EXPECT_EQ(stabilizer.getLastStats().joints, 3);
	for (int i = 0; i < 30; ++i) scene.world().stepSimulation(kTimeStep, 0);
	// m: the freed last link fell away from the chain (half a second of free fall is over a metre).
	const btVector3 pa = (last->getRigidBodyA().getCenterOfMassTransform() * last->getAFrame()).getOrigin();
	const btVector3 pb = (last->getRigidBodyB().getCenterOfMassTransform() * last->getBFrame()).getOrigin();
	EXPECT_GT((pa - pb).length(), btScalar(0.1));

	scene.hinges()[2]->setBreakingImpulseThreshold(btScalar(1e-3));  // N·s: any load breaks it
	for (int i = 0; i < 5; ++i) scene.world().stepSimulation(kTimeStep, 0);
	EXPECT_FALSE(scene.hinges()[2]->isEnabled());
	EXPECT_EQ(stabilizer.getLastStats().joints, 2);
}

TEST(Stabilizer, OnlyQuaternionHingesAreProjectedInMixedIslands)
{
	// An island that also holds a point-to-point constraint: the hinges are projected, the other constraint is
	// left to Bullet's solver, and nothing breaks.
	StabilizerScene scene;
	std::vector<btRigidBody*> links = scene.chain(3);
	btRigidBody* bob = scene.box(btVector3(0.1, 0.1, 0.1), 1, btVector3(1.5 + 0.35, 10, 0));
	scene.addConstraint(new btPoint2PointConstraint(*links.back(), *bob, btVector3(0.25, 0, 0),
													btVector3(-0.1, 0, 0)));
	btQuaternionHingeStabilizer stabilizer(hingesOnly());  // projectPointConstraints off: the point constraint left out
	scene.addAction(&stabilizer);
	double separation, misalignment;
	runAndMeasure(scene, 120, separation, misalignment);
	EXPECT_EQ(stabilizer.getLastStats().joints, 3);
	EXPECT_EQ(stabilizer.getLastStats().bodies, 3);  // the bob is not one of the stabilizer's bodies
	ASSERT_TRUE(scene.allFinite());
	EXPECT_LE(separation, kSeparationTolerance);
}

TEST(Stabilizer, RagdollOnTheGroundSinksAtMostByItsCorrection)
{
	// The projection does not see contacts: a jointed body lying on the ground may be pushed into it, but never by
	// more than the correction applied (and the contact solver pushes it back out in the next step).
	double penetration[2] = {0, 0};  // m below the ground's surface, without and with the stabilizer
	btScalar largestCorrection = 0;
	for (int withStabilizer = 0; withStabilizer < 2; ++withStabilizer)
	{
		StabilizerScene scene;
		scene.box(btVector3(20, 0.5, 20), 0, btVector3(0, -0.5, 0));  // ground, surface at y = 0
		const btScalar half = btScalar(0.05);
		std::vector<btRigidBody*> limbs;
		for (int i = 0; i < 5; ++i)
			limbs.push_back(scene.box(btVector3(0.2, half, half), 1, btVector3(btScalar(0.45) * btScalar(i), half, 0)));
		for (int i = 1; i < 5; ++i)
			scene.hinge(*limbs[i - 1], *limbs[i], btVector3(0.225, 0, 0), btVector3(-0.225, 0, 0), btVector3(0, 0, 1),
						btVector3(0, 0, 1));
		btQuaternionHingeStabilizer stabilizer;
		if (withStabilizer) scene.addAction(&stabilizer);
		for (int step = 0; step < 180; ++step)
		{
			scene.world().stepSimulation(kTimeStep, 0);
			if (withStabilizer) largestCorrection = std::max(largestCorrection, stabilizer.getLastStats().residualBefore);
			for (btRigidBody* limb : limbs)
				for (int corner = 0; corner < 8; ++corner)
				{
					const btVector3 local((corner & 1) ? 0.2 : -0.2, (corner & 2) ? half : -half,
										  (corner & 4) ? half : -half);
					const btScalar y = (limb->getCenterOfMassTransform() * local).y();
					penetration[withStabilizer] = std::max(penetration[withStabilizer], double(-y));
				}
		}
	}
	std::cout << "[ figures  ] ragdoll on the ground, 3 s: max penetration " << penetration[0] << " m without, "
			  << penetration[1] << " m with the stabilizer (largest correction " << largestCorrection << " m)"
			  << std::endl;
	// m: Bullet's contact slop and the ground's own penetration allowance (collision margin 0.04 m) bound both;
	// the stabilizer may add at most the largest joint correction it made (residualBefore is ‖C‖∞ of that step).
	EXPECT_LE(penetration[1], penetration[0] + largestCorrection + 1e-3);
}

TEST(Stabilizer, PositionRowsHaveThePointStructureTheAssemblyUses)
{
	// The stabilizer's assembly relies on the linear part of every row being ±[I; 0] (C = p_B − p_A for the point
	// rows, Q7's zero linear part for the quaternion rows); this checks the joint's rows have it.
	StabilizerScene scene;
	std::vector<btRigidBody*> links = scene.chain(2);
	btTransform t = links[1]->getCenterOfMassTransform();
	t.setRotation(btQuaternion(btVector3(1, 2, 3).normalized(), btScalar(0.4)));
	btScalar c[5], jac[60];
	const int rows = scene.hinges()[1]->computePositionRows(links[0]->getCenterOfMassTransform(), t, c, jac);
	ASSERT_EQ(rows, 5);
	for (int r = 0; r < rows; ++r)
		for (int k = 0; k < 3; ++k)
		{
			const btScalar e = (r < 3 && r == k) ? btScalar(1) : btScalar(0);
			EXPECT_EQ(jac[12 * r + k], -e);
			EXPECT_EQ(jac[12 * r + 6 + k], e);
		}
}

TEST(Stabilizer, WorldWithoutQuaternionHingesIsANoOp)
{
	// A world with no quaternion hinge (only a stock hinge, stock hinges not asked for: projectStockHinges off;
	// tests/test_stabilizer_stock.cpp for them) is left exactly as the solver left it.
	StabilizerScene scene;
	btRigidBody* bar = scene.box(btVector3(0.5, 0.05, 0.05), 1, btVector3(0.5, 5, 0));
	scene.addConstraint(new btHingeConstraint(*bar, btVector3(-0.5, 0, 0), btVector3(0, 0, 1)));
	btQuaternionHingeStabilizerSettings settings;
	settings.projectStockHinges = false;
	btQuaternionHingeStabilizer stabilizer(settings);
	scene.addAction(&stabilizer);
	scene.world().stepSimulation(kTimeStep, 0);
	const btQuaternionHingeStabilizerStats& s = stabilizer.getLastStats();
	EXPECT_EQ(s.islands, 0);
	EXPECT_EQ(s.joints, 0);
	EXPECT_EQ(s.factorizations, 0);
	EXPECT_EQ(s.residualBefore, 0);
}

TEST(Stabilizer, AngularOnlyHingeKeepsItsAxesAligned)
{
	// An angular-only hinge has 2 rows: the stabilizer aligns the axes and leaves the pivots free.
	StabilizerScene scene;
	scene.world().setGravity(btVector3(0, 0, 0));
	btRigidBody* a = scene.box(btVector3(0.3, 0.1, 0.1), 1, btVector3(0, 0, 0));
	btRigidBody* b = scene.box(btVector3(0.3, 0.1, 0.1), 2, btVector3(1, 0, 0));
	btQuaternionHingeConstraint* h =
		scene.hinge(*a, *b, btVector3(0.5, 0, 0), btVector3(-0.5, 0, 0), btVector3(0, 0, 1), btVector3(0, 0, 1));
	h->setAngularOnly(true);
	a->setAngularVelocity(btVector3(1, 2, 3));
	b->setLinearVelocity(btVector3(0, 1, 0));
	btQuaternionHingeStabilizer stabilizer;
	scene.addAction(&stabilizer);
	double worstMisalignment = 0;
	for (int i = 0; i < 60; ++i)
	{
		scene.world().stepSimulation(kTimeStep, 0);
		const btVector3 za = a->getCenterOfMassTransform().getBasis() * h->getAFrame().getBasis().getColumn(2);
		const btVector3 zb = b->getCenterOfMassTransform().getBasis() * h->getBFrame().getBasis().getColumn(2);
		worstMisalignment =
			std::max(worstMisalignment, double(btAtan2(za.cross(zb).length(), za.dot(zb))) * kRadToDeg);
	}
	EXPECT_EQ(stabilizer.getLastStats().rows, 2);
	EXPECT_LE(worstMisalignment, kMisalignmentToleranceDeg);
	// m: b drifts away at 1 m/s: the pivots are not held together (1 s of drift minus any rotation).
	const btVector3 pa = (a->getCenterOfMassTransform() * h->getAFrame()).getOrigin();
	const btVector3 pb = (b->getCenterOfMassTransform() * h->getBFrame()).getOrigin();
	EXPECT_GT((pa - pb).length(), btScalar(0.5));
}

TEST(Stabilizer, AConstraintMadeAtAnOldOnesAddressIsSeenForWhatItIs)
{
	// The stabilizer keeps which of the world's constraints are quaternion hinges. A stock hinge removed, destroyed
	// and replaced by a quaternion hinge at the same address and index must be projected; and the other way round,
	// the stock hinge that takes a quaternion hinge's place must not be (stock hinges not asked for).
	StabilizerScene scene;
	btQuaternionHingeStabilizerSettings settings;
	settings.projectStockHinges = false;
	btQuaternionHingeStabilizer stabilizer(settings);
	btRigidBody* link = scene.box(btVector3(btScalar(0.05), btScalar(0.25), btScalar(0.05)), 1, btVector3(0, -1, 0));
	const btVector3 pivot(0, btScalar(0.25), 0), axis(0, 0, 1);
	alignas(16) static unsigned char storage[sizeof(btHingeConstraint) > sizeof(btQuaternionHingeConstraint)
												 ? sizeof(btHingeConstraint)
												 : sizeof(btQuaternionHingeConstraint)];
	btTypedConstraint* stock = new (storage) btHingeConstraint(*link, pivot, axis);
	scene.world().addConstraint(stock);
	EXPECT_EQ(stabilizer.stabilize(&scene.world(), kTimeStep).joints, 0);
	scene.world().removeConstraint(stock);
	stock->~btTypedConstraint();
	btQuaternionHingeConstraint* hinge = new (storage) btQuaternionHingeConstraint(*link, pivot, axis);
	ASSERT_EQ(static_cast<void*>(hinge), static_cast<void*>(storage));
	scene.world().addConstraint(hinge);
	link->setCenterOfMassTransform(btTransform(btQuaternion::getIdentity(), btVector3(btScalar(0.01), -1, 0)));
	const btQuaternionHingeStabilizerStats& stats = stabilizer.stabilize(&scene.world(), kTimeStep);
	EXPECT_EQ(stats.joints, 1);
	EXPECT_GT(stats.residualBefore, btScalar(0.009));  // m: the 1 cm the link was put off its pivot
	EXPECT_LE(stats.residualAfter, kResidualTolerance);
	scene.world().removeConstraint(hinge);
	hinge->~btQuaternionHingeConstraint();
	stock = new (storage) btHingeConstraint(*link, pivot, axis);
	scene.world().addConstraint(stock);
	EXPECT_EQ(stabilizer.stabilize(&scene.world(), kTimeStep).joints, 0);
	scene.world().removeConstraint(stock);
	stock->~btTypedConstraint();
}

#endif  // QUATHINGE_HAVE_STABILIZER
