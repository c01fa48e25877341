// The stabilizer's containers allocate through Bullet's allocator (plugin/stabilizer/BulletAllocator.h), so an app
// that routes Bullet's memory through btAlignedAllocSetCustom (an engine's own allocator) routes the stabilizer's
// too. Engines also count on a steady world not allocating every step: a call that rebuilt no island
// (getLastStats().structureRebuilt false) reuses what the calls before it sized, so it allocates only where a step
// is the largest yet (more contacts than before). Counted here with a custom allocator around each call, on a
// swinging chain and on RagdollDemo's ragdolls falling onto the ground and resting there (contact rows, slots,
// limits). Not counted: Eigen's sparse factorization (SparseLDLT, for islands with loops) allocates through Eigen.
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/RagdollDemo.h"
#include "support/StabilizerScene.h"

#include <LinearMath/btAlignedAllocator.h>
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdio>
#include <cstdlib>

using namespace qh_test;

namespace
{
long gAllocations = 0;  // btAlignedAlloc's calls of the allocation function since the counter was installed
void* countingAlloc(std::size_t size)
{
	++gAllocations;
	return std::malloc(size);
}
void countingFree(void* p) { std::free(p); }

// Installs the counting allocator for a scope: Bullet's default allocates with malloc and frees with free, as it does,
// so memory allocated before or after is freed correctly either way.
struct CountingAllocator
{
	CountingAllocator() { btAlignedAllocSetCustom(countingAlloc, countingFree); }
	~CountingAllocator() { btAlignedAllocSetCustom(nullptr, nullptr); }
};

// Allocations by the calls that rebuilt nothing (after the warm-up) and by the others.
struct Counts
{
	long steady = 0;      // allocations in calls that rebuilt nothing, after the warm-up
	int steadyCalls = 0;  // such calls
	long rebuilding = 0;  // allocations in calls that rebuilt the islands, or in the warm-up
	int rebuildingCalls = 0;
	Counts operator-(const Counts& o) const
	{
		return {steady - o.steady, steadyCalls - o.steadyCalls, rebuilding - o.rebuilding, rebuildingCalls - o.rebuildingCalls};
	}
};

// The stabilizer as the world's action, counting the allocations of each call.
struct CountedStabilizer : btActionInterface
{
	btQuaternionHingeStabilizer stabilizer;
	Counts counts;
	int steps = 0;
	int warmUpSteps = 0;  // calls counted as warm-up
	void updateAction(btCollisionWorld* world, btScalar timeStep) override
	{
		const long before = gAllocations;
		stabilizer.updateAction(world, timeStep);
		const long n = gAllocations - before;
		if (steps < warmUpSteps || stabilizer.getLastStats().structureRebuilt)
		{
			counts.rebuilding += n;
			++counts.rebuildingCalls;
		}
		else
		{
			counts.steady += n;
			++counts.steadyCalls;
		}
		++steps;
	}
	void debugDraw(btIDebugDraw*) override {}
};
}  // namespace

// A 10-link chain swinging for 10 s, its links' collisions filtered out (as apps do for a ragdoll's own parts): after
// the first call, which builds the islands, nothing changes its size. (With its links colliding, the first touch, at
// 2.9 s, grows the contact scan's scratch once: the ragdolls below.)
TEST(StabilizerAllocations, ASwingingChainAllocatesNothingAfterItsFirstStep)
{
	CountingAllocator counting;
	CountedStabilizer counted;  // outlives the scene, which removes it from its world
	StabilizerScene scene;
	for (btRigidBody* link : scene.chain(10)) link->getBroadphaseHandle()->m_collisionFilterMask = 0;
	counted.warmUpSteps = 1;  // the first call builds the islands and sizes everything
	scene.addAction(&counted);
	for (int s = 0; s < 600; ++s) scene.world().stepSimulation(btScalar(1) / 60, 1, btScalar(1) / 60);
	const Counts& c = counted.counts;
	std::printf("chain10: %ld allocations in %d calls that rebuilt nothing, %ld in the others\n", c.steady, c.steadyCalls,
				c.rebuilding);
	EXPECT_GT(c.rebuilding, 0);  // the counter sees the stabilizer's containers
	EXPECT_GT(c.steadyCalls, 500);
	EXPECT_EQ(c.steady, 0);
}

// Four RagdollDemo ragdolls (hinges, cone twists, their limits, contacts with each other and with RagdollDemo's
// btCollisionObject ground) falling for 4 s, then 4 s on the ground: the calls of the second stretch that rebuild
// nothing allocate nothing. (The islands are rebuilt when the contacts join or split them: those calls allocate, 400
// to 600 times each here, which the test prints.)
TEST(StabilizerAllocations, RagdollsOnTheGroundAllocateNothingOnceLanded)
{
	CountingAllocator counting;
	RagdollDemoWorld w(RagdollGround::CollisionObject);
	for (int i = 0; i < 4; ++i)
		w.addRagdoll(btVector3(btScalar(0.8 * i - 1.2), btScalar(0.2 + 0.9 * i), 0), btScalar(0.7 * i), btScalar(i % 2 ? 0.5 : -0.5));
	CountedStabilizer counted;
	w.world().addAction(&counted);
	for (int s = 0; s < 240; ++s) w.world().stepSimulation(btScalar(1) / 60, 1, btScalar(1) / 60);
	const Counts falling = counted.counts;
	for (int s = 0; s < 240; ++s) w.world().stepSimulation(btScalar(1) / 60, 1, btScalar(1) / 60);
	w.world().removeAction(&counted);
	const Counts landed = counted.counts - falling;
	std::printf(
		"ragdolls, first 4 s: %ld allocations in %d calls that rebuilt nothing, %ld in %d that rebuilt; next 4 s: "
		"%ld in %d, %ld in %d\n",
		falling.steady, falling.steadyCalls, falling.rebuilding, falling.rebuildingCalls, landed.steady,
		landed.steadyCalls, landed.rebuilding, landed.rebuildingCalls);
	EXPECT_GT(falling.rebuilding, 0);  // the counter sees the stabilizer's containers
	EXPECT_GT(landed.steadyCalls, 0);
	EXPECT_EQ(landed.steady, 0);
}
#endif
