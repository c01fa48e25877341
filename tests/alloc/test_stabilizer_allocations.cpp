// Issue 15, "no per-step heap allocation (measure it)": once an island is built, btQuaternionHingeStabilizer::stabilize
// allocates nothing. Counted here: every global operator new (std containers, std::unordered_map) and every Bullet
// allocation (btAlignedAlloc, which the stabilizer's own arrays use: plugin/stabilizer/BulletAllocator.h), while
// stabilize() runs and only then. Not counted: Eigen's std::malloc, which only the closed-loop path's SparseLDLT
// (Eigen's SimplicialLDLT) reaches; four_bar is run for the rest of its path.
//
// Its own executable: replacing the global operator new would change every other test's allocations.
#include "SceneSpec.h"
#include "Simulation.h"

#include "quathinge/btQuaternionHingeStabilizer.h"

#include <LinearMath/btAlignedAllocator.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <string>

namespace
{
std::atomic<long> g_allocations{0};
thread_local bool t_counting = false;

void* countedMalloc(std::size_t size)
{
	if (t_counting) ++g_allocations;
	return std::malloc(size ? size : 1);
}
void countedFree(void* p) { std::free(p); }
void* bulletAlloc(size_t size) { return countedMalloc(size); }
void bulletFree(void* p) { countedFree(p); }

// Bullet's allocator goes through these from the first allocation on (set before main, so that nothing allocated by the
// default is freed by ours: both are std::malloc/std::free anyway).
const bool g_bulletHooked = [] {
	btAlignedAllocSetCustom(bulletAlloc, bulletFree);
	return true;
}();

// Counts the allocations made by f.
template <class F>
long allocationsIn(F&& f)
{
	const long before = g_allocations.load();
	t_counting = true;
	f();
	t_counting = false;
	return g_allocations.load() - before;
}
}  // namespace

void* operator new(std::size_t size)
{
	void* p = countedMalloc(size);
#if defined(__cpp_exceptions)
	if (!p) throw std::bad_alloc();
#else
	if (!p) std::abort();
#endif
	return p;
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return countedMalloc(size); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return countedMalloc(size); }
void operator delete(void* p) noexcept { countedFree(p); }
void operator delete[](void* p) noexcept { countedFree(p); }
void operator delete(void* p, std::size_t) noexcept { countedFree(p); }
void operator delete[](void* p, std::size_t) noexcept { countedFree(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { countedFree(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { countedFree(p); }

using namespace quathinge::scenes;

namespace
{
// The bare quaternion hinges' world of a scene, stabilized by hand after each step so that only stabilize() is counted.
// Returns the limit rows projected over the steps (to show that a scene exercised them). builtOnce: the islands are
// built in the first call alone (false where contact rows come and go: a contact that appears or leaves rebuilds its
// island, and only the steps that did not rebuild are counted then).
int expectNoAllocationPerStep(const std::string& name, int steps,
							  const btQuaternionHingeStabilizerSettings& settings = btQuaternionHingeStabilizerSettings(),
							  bool builtOnce = true)
{
	EXPECT_TRUE(g_bulletHooked);
	const SceneSpec scene = makeScene(name, 1);
	EXPECT_TRUE(scene.unavailable.empty()) << scene.unavailable;
	if (!scene.unavailable.empty()) return 0;
	Simulation sim(scene, Kind::Quaternion);
	btQuaternionHingeStabilizer stabilizer;
	stabilizer.setSettings(settings);
	const double dt = sceneStep(scene);
	long afterBuild = 0;
	int rebuilds = 0, projected = 0, factorizations = 0, limitRows = 0;
	for (int i = 0; i < steps; ++i)
	{
		sim.step(dt, 10);
		const long n = allocationsIn([&] { stabilizer.stabilize(&sim.world(), btScalar(dt)); });
		const btQuaternionHingeStabilizerStats& stats = stabilizer.getLastStats();
		if (stats.structureRebuilt) ++rebuilds;
		else
		{
			afterBuild += n;
			EXPECT_EQ(n, 0) << name << ": step " << i << " allocated " << n << " times";
		}
		projected += stats.islands - stats.restingIslands;
		factorizations += stats.factorizations;
		limitRows += stats.activeLimitRows;
	}
	EXPECT_EQ(afterBuild, 0) << name;
	// the counted steps did the work: the islands were built once, then projected with factorizations
	if (builtOnce) EXPECT_EQ(rebuilds, 1) << name;
	else EXPECT_LT(rebuilds, steps / 2) << name;
	EXPECT_GT(projected, steps / 2) << name;
	EXPECT_GT(factorizations, steps / 2) << name;
	EXPECT_TRUE(sim.finiteAndBounded()) << name;
	return limitRows;
}
}  // namespace

// The counter counts: a step that builds the islands allocates.
TEST(StabilizerAllocations, BuildingTheIslandsIsCounted)
{
	const SceneSpec scene = makeScene("chain10", 1);
	Simulation sim(scene, Kind::Quaternion);
	btQuaternionHingeStabilizer stabilizer;
	sim.step(1.0 / 60, 10);
	const long n = allocationsIn([&] { stabilizer.stabilize(&sim.world(), btScalar(1) / 60); });
	EXPECT_TRUE(stabilizer.getLastStats().structureRebuilt);
	EXPECT_GT(n, 0);
}

// 5-row blocks (no limits), a swinging chain.
TEST(StabilizerAllocations, SwingingChain) { expectNoAllocationPerStep("chain10", 120); }
// 6-row blocks with limit rows entering and leaving the system, contacts with the ground (the contact weighting's
// lookups), a tumbling landing.
// Joints only (contacts left to Bullet's solver): the islands are built once.
TEST(StabilizerAllocations, RagdollOnTheGround)
{
	btQuaternionHingeStabilizerSettings jointsOnly;
	jointsOnly.projectContacts = false;
	EXPECT_GT(expectNoAllocationPerStep("ragdoll", 180, jointsOnly), 0);
}
// The defaults, contact rows included: a step that keeps its contacts allocates nothing.
TEST(StabilizerAllocations, RagdollOnTheGroundWithContactRows)
{
	EXPECT_GT(expectNoAllocationPerStep("ragdoll", 180, btQuaternionHingeStabilizerSettings(), false), 0);
}
// A closed loop (the general sparse path; Eigen's own std::malloc is not counted, see above).
TEST(StabilizerAllocations, FourBarLinkage) { expectNoAllocationPerStep("four_bar", 120); }
#ifdef QUATHINGE_HAVE_URDF
// A robot from URDF, its stops reached as it falls (registered when built with urdfdom).
TEST(StabilizerAllocations, KukaArm) { EXPECT_GT(expectNoAllocationPerStep("kuka_iiwa", 180), 0); }
#endif
