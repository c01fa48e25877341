// The stabilizer leaves out islands at rest (plugin/stabilizer/IslandRestCache.h): an island that starts a step bit
// for bit as it started the last one gets the last projection's result back. Each test runs two identical worlds in
// lockstep, one whose stabilizer may replay and one whose kept results are forgotten before every step
// (setSettings(getSettings())), and asserts that the two stay identical to the bit — the replay is exact, whatever
// the scene does — and that the replay happens where the scene is at rest and not where anything changes.
// Built with the stabilizer only (tests/CMakeLists.txt defines QUATHINGE_HAVE_STABILIZER then).
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/StabilizerScene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <functional>
#include <vector>

using namespace qh_test;

namespace
{
// Hanging chains (links straight down from the world, hinge axes alternating z and x), at rest from the start.
struct RestWorld
{
	StabilizerScene scene;
	btQuaternionHingeStabilizer stabilizer;
	std::vector<btRigidBody*> links;

	// limits: 0 none, 1 every joint within [−0.5, 0.5] rad (the chains hang clear of the stops), 2 every joint held
	// at a stop, all axes along z (the first joint within [0.3, 0.6] rad, the others within [−0.6, −0.3]: each chain
	// swings and comes to rest folded in its plane against its stops; with the axes alternating z and x the folded
	// chains keep bouncing on their stops in a cycle of 20 steps at up to 0.16 m/s: not at rest)
	RestWorld(int chains, int linksPerChain, int limits)
	{
		for (int c = 0; c < chains; ++c)
		{
			btRigidBody* previous = nullptr;
			for (int i = 0; i < linksPerChain; ++i)
			{
				// (chains 1 m apart; 3 m when folded, which reaches a neighbour 1 m away)
				const btVector3 centre(btScalar(limits == 2 ? 3 * c : c), btScalar(-0.25 - 0.5 * i), 0);
				btRigidBody* link = scene.box(btVector3(btScalar(0.05), btScalar(0.25), btScalar(0.05)), 1, centre);
				const btVector3 axis = i % 2 == 0 || limits == 2 ? btVector3(0, 0, 1) : btVector3(1, 0, 0);
				btQuaternionHingeConstraint* joint =
					previous ? scene.hinge(*previous, *link, btVector3(0, btScalar(-0.25), 0),
										   btVector3(0, btScalar(0.25), 0), axis, axis)
							 : scene.hingeToWorld(*link, btVector3(0, btScalar(0.25), 0), axis);
				if (limits == 1) joint->setLimit(btScalar(-0.5), btScalar(0.5));
				if (limits == 2)
				{
					if (previous) joint->setLimit(btScalar(-0.6), btScalar(-0.3));
					else joint->setLimit(btScalar(0.3), btScalar(0.6));
				}
				links.push_back(link);
				previous = link;
			}
		}
		scene.addAction(&stabilizer);
	}
	void step() { scene.world().stepSimulation(kTimeStep, 0, kTimeStep); }
};

// The pose, velocities and Bullet's world inverse inertia of links [first, first + count) (every link by default), as
// bytes.
std::vector<unsigned char> state(const RestWorld& w, std::size_t first = 0, std::size_t count = std::size_t(-1))
{
	std::vector<unsigned char> bytes;
	auto add = [&bytes](const btVector3& v) {
		const btScalar xyz[3] = {v.x(), v.y(), v.z()};
		const unsigned char* p = reinterpret_cast<const unsigned char*>(xyz);
		bytes.insert(bytes.end(), p, p + sizeof(xyz));
	};
	for (std::size_t k = first; k < w.links.size() && k - first < count; ++k)
	{
		const btRigidBody* b = w.links[k];
		const btTransform& t = b->getCenterOfMassTransform();
		for (int r = 0; r < 3; ++r) add(t.getBasis()[r]);
		add(t.getOrigin());
		for (int r = 0; r < 3; ++r) add(b->getInvInertiaTensorWorld()[r]);
		add(b->getLinearVelocity());
		add(b->getAngularVelocity());
		const btTransform& i = b->getInterpolationWorldTransform();
		for (int r = 0; r < 3; ++r) add(i.getBasis()[r]);
		add(i.getOrigin());
		add(b->getInterpolationLinearVelocity());
		add(b->getInterpolationAngularVelocity());
	}
	return bytes;
}

// Runs `steps` steps of two copies in lockstep (the second forgets its kept results before each step); `disturb`
// (step index, world) is applied to both before each step. Returns the replaying world's resting-island count
// summed over the steps; fails the test on the first step at which the two differ.
int lockstep(int chains, int links, int limits, int steps, const std::function<void(int, RestWorld&)>& disturb)
{
	RestWorld replaying(chains, links, limits), projecting(chains, links, limits);
	int resting = 0;
	for (int i = 0; i < steps; ++i)
	{
		disturb(i, replaying);
		disturb(i, projecting);
		projecting.stabilizer.setSettings(projecting.stabilizer.getSettings());  // forgets what it kept
		replaying.step();
		projecting.step();
		resting += replaying.stabilizer.getLastStats().restingIslands;
		EXPECT_EQ(projecting.stabilizer.getLastStats().restingIslands, 0);
		if (state(replaying) != state(projecting))
		{
			ADD_FAILURE() << "the replaying world left the projecting one at step " << i;
			break;
		}
	}
	return resting;
}

void nothing(int, RestWorld&) {}
}  // namespace

TEST(StabilizerRest, HangingChainsAtRestAreReplayedToTheBit)
{
	// 4 chains of 10 links kept awake: after a few steps every step is a replay, and the result is the projection's.
	RestWorld w(4, 10, 0);
	for (int i = 0; i < 60; ++i) w.step();
	const btQuaternionHingeStabilizerStats& stats = w.stabilizer.getLastStats();
	EXPECT_EQ(stats.islands, 4);
	EXPECT_EQ(stats.restingIslands, 4);
	EXPECT_EQ(stats.factorizations, 0);
	EXPECT_EQ(stats.solves, 0);
	EXPECT_LE(stats.residualAfter, kResidualTolerance);  // m: the replayed pose is the projected one
	double separation = 0, misalignmentDeg = 0;
	w.scene.jointErrors(separation, misalignmentDeg);
	EXPECT_LE(separation, kSeparationTolerance);
	EXPECT_LE(misalignmentDeg, kMisalignmentToleranceDeg);
	EXPECT_GT(lockstep(4, 10, 0, 120, nothing), 0);
}

TEST(StabilizerRest, LimitedChainsAtRestAreReplayedToTheBit)
{
	// with a limit on every joint the projection also reads each joint's multi-turn angle
	EXPECT_GT(lockstep(2, 6, 1, 120, nothing), 0);
}

TEST(StabilizerRest, ChainsRestingAgainstTheirStopsAreReplayedToTheBit)
{
	// Chains folded against their stops do not reach a fixed point: Bullet's stop rows and the projection settle into a
	// cycle of states. The rest cache keeps the last 8 projections and replays any, so a chain whose state comes back
	// every second, third … eighth step (the bodies' velocities go round to the bit) is replayed at every step (with
	// two kept, a cycle of six was projected every step). How long the cycle is, is a matter of the
	// platform's bits (docs/PLATFORMS.md): over steps 200-299 of 2 chains of 4 links, both in a cycle of two on
	// x86-64 Linux, both in a cycle of six on Windows x86-64 (MinGW-w64; one of them bouncing on its stops at
	// 0.14 m/s). So the test finds the chains whose state repeats that of one of the 8 steps before and asserts that
	// exactly those are replayed, at least one at every step.
	const int chains = 2, links = 4;
	RestWorld w(chains, links, 2);
	std::vector<std::vector<unsigned char>> history[chains];  // each chain's state at the start of the last 9 steps
	int resting = 0, cycling = 0, longest = 0;
	for (int i = 0; i < 300; ++i)
	{
		int cyclingNow = 0;
		for (int c = 0; c < chains; ++c)
		{
			history[c].push_back(state(w, std::size_t(c * links), std::size_t(links)));
			if (history[c].size() > 9) history[c].erase(history[c].begin());
			for (std::size_t age = 1; age < history[c].size(); ++age)
				if (history[c].back() == history[c][history[c].size() - 1 - age])  // starts as `age` steps ago
				{
					++cyclingNow;
					if (i >= 200) longest = std::max(longest, int(age));
					break;
				}
		}
		w.step();
		if (i < 200) continue;
		const btQuaternionHingeStabilizerStats& stats = w.stabilizer.getLastStats();
		resting += stats.restingIslands;
		cycling += cyclingNow;
		EXPECT_EQ(stats.restingIslands, cyclingNow) << "step " << i;
		if (stats.restingIslands == stats.islands)
		{
			EXPECT_EQ(stats.factorizations, 0) << "step " << i;  // nothing left to project
		}
	}
	std::printf(
		"[ figures  ] islands replayed over steps 200-299: %d of %d (chains in a cycle of up to 8 steps: %d; "
		"the longest cycle: %d steps)\n",
		resting, 100 * chains, cycling, longest);
	EXPECT_GE(resting, 100);                                    // at least one chain at every one of the last 100 steps
	EXPECT_GT(w.stabilizer.getLastStats().activeLimitRows, 0);  // at their stops
	// and to the bit what the projection gives
	EXPECT_GT(lockstep(chains, links, 2, 300, nothing), 0);
}

// A state for a projection to work on: every link 1 mm lower and falling at 5 cm/s (the solver's sag at rest).
struct BodyState
{
	btTransform pose;
	btVector3 linear, angular;
};
std::vector<BodyState> sagged(const RestWorld& w)
{
	std::vector<BodyState> out;
	for (const btRigidBody* b : w.links)
	{
		btTransform t = b->getCenterOfMassTransform();
		t.getOrigin() += btVector3(0, btScalar(-1e-3), 0);
		out.push_back({t, btVector3(0, btScalar(-0.05), 0), btVector3(0, 0, 0)});
	}
	return out;
}
void setState(RestWorld& w, const std::vector<BodyState>& s)
{
	for (size_t i = 0; i < s.size(); ++i)
	{
		btRigidBody& b = *w.links[i];
		b.setCenterOfMassTransform(s[i].pose);
		b.setLinearVelocity(s[i].linear);
		b.setAngularVelocity(s[i].angular);
		b.setInterpolationLinearVelocity(s[i].linear);
		b.setInterpolationAngularVelocity(s[i].angular);
	}
}

TEST(StabilizerRest, EveryInputOfTheProjectionIsCompared)
{
	// Two identical worlds are projected from the same sagged state; then each is put back in that state with one
	// input of the projection changed and projected again. The replaying world must see the change (and project),
	// so both end to the bit the same. Without a change it replays (the control).
	const btScalar bump = btScalar(1e-4);
	const std::function<void(RestWorld&)> changes[] = {
		[](RestWorld&) {},  // the control
		[&](RestWorld& w) { w.links[3]->setLinearVelocity(w.links[3]->getLinearVelocity() + btVector3(bump, 0, 0)); },
		[&](RestWorld& w) { w.links[3]->setAngularVelocity(btVector3(0, bump, 0)); },
		[&](RestWorld& w) {
			btTransform t = w.links[4]->getCenterOfMassTransform();
			t.getOrigin() += btVector3(0, 0, bump);
			w.links[4]->setCenterOfMassTransform(t);
		},
		[&](RestWorld& w) {
			btTransform t = w.links[4]->getCenterOfMassTransform();
			t.setRotation(btQuaternion(btVector3(0, 1, 0), bump) * t.getRotation());
			w.links[4]->setCenterOfMassTransform(t);
		},
		[&](RestWorld& w) {
			btQuaternionHingeConstraint* j = w.scene.hinges()[2];
			btTransform frameB = j->getFrameOffsetB();
			frameB.getOrigin() += btVector3(bump, 0, 0);
			j->setFrames(j->getFrameOffsetA(), frameB);
		},
		[&](RestWorld& w) {
			btQuaternionHingeConstraint* j = w.scene.hinges()[2];
			btTransform frameA = j->getFrameOffsetA();
			frameA.getOrigin() += btVector3(0, 0, bump);
			j->setFrames(frameA, j->getFrameOffsetB());
		},
		[](RestWorld& w) { w.links[5]->setMassProps(2, w.links[5]->getLocalInertia()); },  // the mass alone
		[](RestWorld& w) { w.links[5]->setMassProps(1, w.links[5]->getLocalInertia() * 3); },
		[](RestWorld& w) { w.links[5]->setLinearFactor(btVector3(1, 1, 0)); },
		[](RestWorld& w) { w.links[5]->setAngularFactor(btVector3(0, 1, 1)); },
		// the limits: a stop the sag now crosses (link 1 turned past it first)
		[](RestWorld& w) { w.scene.hinges()[1]->setLimit(btScalar(0.01), btScalar(0.5)); },
	};
	int index = 0;
	for (const auto& change : changes)
	{
		RestWorld replaying(1, 6, 1), projecting(1, 6, 1);
		for (int i = 0; i < 30; ++i)
		{
			replaying.step();
			projecting.step();
		}
		const std::vector<BodyState> start = sagged(replaying);
		for (RestWorld* w : {&replaying, &projecting})
		{
			setState(*w, start);
			w->stabilizer.stabilize(&w->scene.world(), kTimeStep);
			setState(*w, start);
			change(*w);
		}
		projecting.stabilizer.setSettings(projecting.stabilizer.getSettings());  // forgets what it kept
		replaying.stabilizer.stabilize(&replaying.scene.world(), kTimeStep);
		projecting.stabilizer.stabilize(&projecting.scene.world(), kTimeStep);
		EXPECT_GT(projecting.stabilizer.getLastStats().factorizations, 0) << "change " << index;
		EXPECT_EQ(replaying.stabilizer.getLastStats().restingIslands, index == 0 ? 1 : 0) << "change " << index;
		EXPECT_TRUE(state(replaying) == state(projecting)) << "change " << index;
		++index;
	}
}

TEST(StabilizerRest, AnythingThatChangesIsProjectedAgain)
{
	// Each change below alters one input of the projection while the chains rest; the replaying world must project
	// it (or the lockstep comparison fails) and must go back to replaying once the chains rest again.
	const std::function<void(int, RestWorld&)> changes[] = {
		// a push far below the velocity tolerance (1e-9 m/s)
		[](int i, RestWorld& w) {
			if (i == 60) w.links[3]->applyCentralImpulse(btVector3(btScalar(1e-9), 0, 0));
		},
		// the joint's frame in B moved by one unit in the last place
		[](int i, RestWorld& w) {
			if (i != 60) return;
			btQuaternionHingeConstraint* j = w.scene.hinges()[2];
			btTransform frameB = j->getFrameOffsetB();
			frameB.getOrigin().setX(std::nextafter(frameB.getOrigin().x(), btScalar(1)));
			j->setFrames(j->getFrameOffsetA(), frameB);
		},
		// a heavier link
		[](int i, RestWorld& w) {
			if (i == 60) w.links[5]->setMassProps(2, w.links[5]->getLocalInertia() * 2);
		},
		// a changed limit
		[](int i, RestWorld& w) {
			if (i == 60) w.scene.hinges()[1]->setLimit(btScalar(-0.4), btScalar(0.6));
		},
	};
	for (const auto& change : changes)
	{
		const int resting = lockstep(2, 6, 1, 200, change);
		EXPECT_GT(resting, 0);
	}
}

#endif  // QUATHINGE_HAVE_STABILIZER
