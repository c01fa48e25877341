// Threads: the joint (and the stabilizer) keep no shared mutable state, so worlds stepped at once in several threads
// give exactly the results they give one at a time. Debian's Bullet 3.24 is not built BT_THREADSAFE (its task
// schedulers never run anything in parallel; see DebianBulletIsNotBuiltThreadSafe), so btDiscreteDynamicsWorldMt runs
// sequentially there: the joint is checked to work in that world (the Mt solver's own code paths) all the same.
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/World.h"
#ifdef QUATHINGE_HAVE_STABILIZER
#include "quathinge/btQuaternionHingeStabilizer.h"
#endif

#include "BulletCollision/CollisionDispatch/btCollisionDispatcherMt.h"
#include "BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolverMt.h"
#include "BulletDynamics/Dynamics/btDiscreteDynamicsWorldMt.h"
#include "LinearMath/btThreads.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <thread>
#include <vector>

namespace
{
const int kWorlds = 4;
const int kLinks = 8;
const int kSteps = 300;                      // at 60 Hz: 5 s
const btScalar kHalfLength = btScalar(0.2);  // m, half a link

// 64-bit FNV-1a over the raw bytes of every body's transform and velocities after every step.
struct Fnv1a
{
	std::uint64_t h = 0xcbf29ce484222325ULL;
	void add(const btScalar* v, int n)
	{
		const unsigned char* p = reinterpret_cast<const unsigned char*>(v);
		for (std::size_t i = 0; i < n * sizeof(btScalar); ++i)
		{
			h ^= p[i];
			h *= 0x100000001b3ULL;
		}
	}
	void add(const btRigidBody& b)
	{
		const btTransform& t = b.getCenterOfMassTransform();
		for (int r = 0; r < 3; ++r) add(t.getBasis()[r].m_floats, 3);
		add(t.getOrigin().m_floats, 3);
		add(b.getLinearVelocity().m_floats, 3);
		add(b.getAngularVelocity().m_floats, 3);
	}
};

// A chain of quaternion hinges hung from the world in any dynamics world; `variant` changes the axes, the limit and
// the drives so that no two worlds compute the same thing.
class Chain
{
public:
	Chain(btDiscreteDynamicsWorld& world, int variant) : m_world(world)
	{
		btVector3 inertia;
		m_shape.calculateLocalInertia(1, inertia);
		const btVector3 axes[] = {btVector3(0, 0, 1), btVector3(0, 1, 0), btVector3(0, 1, 1), btVector3(1, 0, 1)};
		// The first link hangs from a static body of this world, not from Bullet's one fixed body that one-body
		// constraints share (btTypedConstraint::getFixedBody(), a static): addConstraint adds each constraint to its
		// bodies' lists, so worlds built in threads at once raced on that body's list (ThreadSanitizer; once in a
		// few hundred runs, glibc's "unaligned tcache chunk detected" abort).
		m_anchor.setWorldTransform(btTransform::getIdentity());
		m_world.addRigidBody(&m_anchor, 1, 0);
		btRigidBody* parent = nullptr;
		for (int i = 0; i < kLinks; ++i)
		{
			m_bodies.emplace_back(new btRigidBody(1, nullptr, &m_shape, inertia));
			btRigidBody* body = m_bodies.back().get();
			body->setWorldTransform(btTransform(btQuaternion::getIdentity(), btVector3((2 * i + 1) * kHalfLength, 0, 0)));
			body->setActivationState(DISABLE_DEACTIVATION);
			m_world.addRigidBody(body, 1, 0);  // no contacts: the joints and the solver only
			const btVector3 axis = axes[(i + variant) % 4].normalized(), pivot(-kHalfLength, 0, 0);
			if (!parent)  // at the world's origin, on the same axis in both frames (the anchor is at the identity)
				m_joints.emplace_back(new btQuaternionHingeConstraint(m_anchor, *body, btVector3(0, 0, 0), pivot, axis, axis));
			else
				m_joints.emplace_back(new btQuaternionHingeConstraint(*parent, *body, btVector3(kHalfLength, 0, 0), pivot,
																	  axis, axis));
			btQuaternionHingeConstraint* joint = m_joints.back().get();
			if (i == 0) joint->setLimit(btScalar(-0.4 - 0.1 * variant), btScalar(0.6));
			if (i == 3) joint->enableAngularMotor(true, btScalar(1 + variant), btScalar(0.5));
			if (i == 5) joint->setServoTarget(btScalar(0.5 * variant), 2, 5);
			if (i == 6) joint->setMaxFrictionTorque(btScalar(0.05));
			m_world.addConstraint(joint, true);
			parent = body;
		}
	}
	~Chain()
	{
		for (auto& j : m_joints) m_world.removeConstraint(j.get());
		for (auto& b : m_bodies) m_world.removeRigidBody(b.get());
		m_world.removeRigidBody(&m_anchor);
	}
	Chain(const Chain&) = delete;
	Chain& operator=(const Chain&) = delete;

	std::uint64_t hashState() const
	{
		Fnv1a hash;
		for (auto& b : m_bodies) hash.add(*b);
		return hash.h;
	}
	double maxSeparation() const
	{
		double worst = 0;
		for (auto& j : m_joints)
			worst = std::max(worst, qh_test::separation(j->getRigidBodyA(), j->getAFrame(), j->getRigidBodyB(), j->getBFrame()));
		return worst;
	}
	const std::vector<std::unique_ptr<btRigidBody>>& bodies() const { return m_bodies; }

private:
	btDiscreteDynamicsWorld& m_world;
	btBoxShape m_shape{btVector3(kHalfLength, btScalar(0.04), btScalar(0.04))};
	btRigidBody m_anchor{0, nullptr, &m_shape};  // static
	std::vector<std::unique_ptr<btRigidBody>> m_bodies;
	std::vector<std::unique_ptr<btQuaternionHingeConstraint>> m_joints;
};

// World `variant` from construction to the end: the hash of its whole trajectory. Worlds 1 and 3 also run the
// post-stabilizer when it is built. `ready`/`go` line the threads up so that their steps overlap.
std::uint64_t runWorld(int variant, std::atomic<int>* ready = nullptr, const std::atomic<bool>* go = nullptr)
{
	qh_test::World world(qh_test::SolverKind::SequentialImpulse, btVector3(0, -10, btScalar(variant)));
	Chain chain(world.world(), variant);
#ifdef QUATHINGE_HAVE_STABILIZER
	btQuaternionHingeStabilizer stabilizer;
	if (variant % 2) world.world().addAction(&stabilizer);
#endif
	if (ready) ++*ready;
	if (go)
		while (!go->load()) std::this_thread::yield();
	Fnv1a hash;
	for (int s = 0; s < kSteps; ++s)
	{
		world.step(1);
		hash.h ^= chain.hashState();
		hash.h *= 0x100000001b3ULL;
	}
#ifdef QUATHINGE_HAVE_STABILIZER
	if (variant % 2) world.world().removeAction(&stabilizer);
#endif
	return hash.h;
}

double seconds(std::chrono::steady_clock::duration d) { return std::chrono::duration<double>(d).count(); }

// Restores the task scheduler in use when it goes out of scope.
struct SchedulerGuard
{
	btITaskScheduler* previous = btGetTaskScheduler();
	~SchedulerGuard() { btSetTaskScheduler(previous); }
};

}  // namespace

TEST(Threads, WorldsSteppedInParallelMatchWorldsSteppedOneAtATime)
{
	// Four worlds, each with its own chain (limit, motor, servo, friction; two with the stabilizer), built and stepped
	// in four threads at once, give bit for bit the trajectories they give one after the other.
	std::uint64_t alone[kWorlds], together[kWorlds];
	const auto t0 = std::chrono::steady_clock::now();
	for (int k = 0; k < kWorlds; ++k) alone[k] = runWorld(k);
	const auto t1 = std::chrono::steady_clock::now();
	std::atomic<int> ready{0};
	std::atomic<bool> go{false};
	std::vector<std::thread> threads;
	for (int k = 0; k < kWorlds; ++k) threads.emplace_back([&, k] { together[k] = runWorld(k, &ready, &go); });
	while (ready.load() < kWorlds) std::this_thread::yield();
	go = true;
	for (auto& t : threads) t.join();
	const auto t2 = std::chrono::steady_clock::now();
	std::printf("[ figures  ] %d worlds x %d steps: one at a time %.3f s, in %d threads %.3f s\n", kWorlds, kSteps,
				seconds(t1 - t0), kWorlds, seconds(t2 - t1));
	for (int k = 0; k < kWorlds; ++k)
	{
		std::printf("[ figures  ] world %d: alone 0x%016" PRIx64 ", in a thread 0x%016" PRIx64 "\n", k, alone[k],
					together[k]);
		EXPECT_EQ(alone[k], together[k]) << "world " << k << " differs when stepped in a thread beside the others";
	}
	for (int k = 1; k < kWorlds; ++k)
		EXPECT_NE(alone[k], alone[0]) << "the worlds must differ for the test to mean anything";
}

TEST(Threads, DebianBulletIsNotBuiltThreadSafe)
{
	// Documents the finding: Debian's Bullet 3.24 is built without BT_THREADSAFE — it has no default (pthreads),
	// OpenMP, TBB or PPL task scheduler, only the sequential one — so btDiscreteDynamicsWorldMt runs sequentially. If
	// this fails, Bullet became thread-safe: turn ChainInMultiThreadedWorldMatchesSingleThreadedWorld into a test with
	// a real multi-threaded scheduler.
	btITaskScheduler* created = btCreateDefaultTaskScheduler();
	EXPECT_EQ(created, nullptr) << "a default (multi-threaded) task scheduler exists";
	delete created;
	EXPECT_EQ(btGetOpenMPTaskScheduler(), nullptr);
	EXPECT_EQ(btGetTBBTaskScheduler(), nullptr);
	EXPECT_EQ(btGetPPLTaskScheduler(), nullptr);
	ASSERT_NE(btGetSequentialTaskScheduler(), nullptr);
	EXPECT_EQ(btGetSequentialTaskScheduler()->getMaxNumThreads(), 1);
	// Without installing anything: a BT_THREADSAFE Bullet numbers each thread that asks (1, 2, …); this one answers 0
	// on every thread.
	unsigned otherIndex = ~0u;
	std::thread other([&] { otherIndex = btGetCurrentThreadIndex(); });
	other.join();
	std::printf("[ figures  ] thread index of a second thread: %u (BT_THREADSAFE numbers it from 1)\n", otherIndex);
	EXPECT_EQ(otherIndex, 0u) << "a second thread has its own index: Bullet is BT_THREADSAFE";
}

TEST(Threads, ChainInMultiThreadedWorldMatchesSingleThreadedWorld)
{
	// btDiscreteDynamicsWorldMt with a pool of btSequentialImpulseConstraintSolverMt (with Debian's Bullet the only
	// scheduler is the sequential one) and joint batching forced on: the chain stays together for the whole run and
	// follows the plain world's chain. The two worlds hand the solver the rows in a different order (the plain world
	// sorts the constraints by island with an unstable sort), so they differ from the first step (~0.1 mm) and, the
	// chain being chaotic, the gap grows ~2x every 5 steps: they are compared over the first kMatchSteps, where a
	// joint the Mt solver mishandled would already be tens of centimetres off (links fall 0.55 m in a third of a
	// second).
	const double kMaxSeparation = 0.2;  // m, half a link, whole run (measured ~0.07 m in both worlds)
	const int kMatchSteps = 20;         // 1/3 s
	const double kMaxDeviation = 0.02;  // m, largest body-position difference in kMatchSteps (measured ~6 mm)
	const int kIterations = 20;         // solver iterations, both worlds (at 10 the whipping chain stretches to 0.18 m)
	SchedulerGuard guard;
	btSetTaskScheduler(btGetSequentialTaskScheduler());
	const int savedMinManifolds = btSequentialImpulseConstraintSolverMt::s_minimumContactManifoldsForBatching;
	const int savedMinBatch = btSequentialImpulseConstraintSolverMt::s_minBatchSize;
	btSequentialImpulseConstraintSolverMt::s_minimumContactManifoldsForBatching = 0;
	btSequentialImpulseConstraintSolverMt::s_minBatchSize = 2;

	btDefaultCollisionConfiguration config;
	btCollisionDispatcherMt dispatcher(&config);
	btDbvtBroadphase broadphase;
	const int kSolvers = 2;  // the pool owns (deletes) them
	btConstraintSolver* solvers[kSolvers] = {new btSequentialImpulseConstraintSolverMt,
											 new btSequentialImpulseConstraintSolverMt};
	btConstraintSolverPoolMt pool(solvers, kSolvers);
	btSequentialImpulseConstraintSolverMt solverMt;
	double separationMt = 0, separationPlain = 0, deviation = 0;
	{
		btDiscreteDynamicsWorldMt worldMt(&dispatcher, &broadphase, &pool, &solverMt, &config);
		worldMt.setGravity(btVector3(0, -10, 1));
		worldMt.getSolverInfo().m_numIterations = kIterations;
		qh_test::World plain(qh_test::SolverKind::SequentialImpulse, btVector3(0, -10, 1));
		Chain chainMt(worldMt, 1), chainPlain(plain.world(), 1);
		for (int s = 0; s < kSteps; ++s)
		{
			worldMt.stepSimulation(btScalar(1) / 60, 0, btScalar(1) / 60);
			plain.step(1, btScalar(1) / 60, kIterations);
			separationMt = std::max(separationMt, chainMt.maxSeparation());
			separationPlain = std::max(separationPlain, chainPlain.maxSeparation());
			for (int i = 0; i < kLinks && s < kMatchSteps; ++i)
				deviation = std::max(deviation, double((chainMt.bodies()[i]->getCenterOfMassPosition() -
														chainPlain.bodies()[i]->getCenterOfMassPosition())
														   .length()));
		}
	}
	btSequentialImpulseConstraintSolverMt::s_minimumContactManifoldsForBatching = savedMinManifolds;
	btSequentialImpulseConstraintSolverMt::s_minBatchSize = savedMinBatch;
	std::printf(
		"[ figures  ] Mt world: max separation %.3g m (plain world %.3g m) over %d steps; largest deviation "
		"from the plain world in the first %d steps %.3g m\n",
		separationMt, separationPlain, kSteps, kMatchSteps, deviation);
	EXPECT_TRUE(std::isfinite(separationMt) && std::isfinite(deviation));
	EXPECT_LT(separationMt, kMaxSeparation);
	EXPECT_LT(deviation, kMaxDeviation);
}
