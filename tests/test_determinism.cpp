// Determinism: the same scene gives the same bits. A 10-link 3-D chain of quaternion hinges (a limit on the first
// joint, a motor on the fifth) stepped 120 times hashes (FNV-1a over the raw bytes of every body transform after
// every step) to the same value on every run in a process, and to a constant fixed per precision.
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/World.h"

#include <gtest/gtest.h>

#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

namespace
{
const int kLinks = 10;
const int kSteps = 120;                                  // at 60 Hz: 2 s
const btScalar kHalfLength = btScalar(0.2);              // m, half a link
const btScalar kLimitLow = btScalar(-0.5);               // rad, first joint
const btScalar kLimitHigh = btScalar(0.5);               // rad
const btScalar kMotorSpeed = btScalar(2);                // rad/s, fifth joint
const btScalar kMotorImpulse = btScalar(0.5);            // N·m·s per step
const int kMotorJoint = 4;
const btScalar kLimitSlack = btScalar(0.1);              // rad: how far past a stop the sanity check lets it be

// The expected hash of the trajectory (GCC, x86-64: the Release build at -O2 and the sanitizer build at -O0 give the
// same bits, SSE arithmetic having no excess precision and GCC contracting nothing into FMAs without -march). It
// changes only when the joint's arithmetic changes (rows, errors, limit or motor logic, the order of floating-point
// operations) or Bullet's does: whoever moves the numbers deliberately updates these constants (run the test, copy
// the hash it prints).
#ifdef BT_USE_DOUBLE_PRECISION
const std::uint64_t kExpectedHash = 0x498a2c689caba9d6ULL;
#else
const std::uint64_t kExpectedHash = 0xe70183069a052b31ULL;
#endif

// 64-bit FNV-1a.
struct Fnv1a
{
	std::uint64_t h = 0xcbf29ce484222325ULL;
	void add(const void* bytes, std::size_t n)
	{
		const unsigned char* p = static_cast<const unsigned char*>(bytes);
		for (std::size_t i = 0; i < n; ++i)
		{
			h ^= p[i];
			h *= 0x100000001b3ULL;
		}
	}
	// A transform's raw bytes: the nine basis entries and the origin (btVector3's unused fourth lane is not part of
	// the transform and is skipped).
	void add(const btTransform& t)
	{
		for (int r = 0; r < 3; ++r) add(t.getBasis()[r].m_floats, 3 * sizeof(btScalar));
		add(t.getOrigin().m_floats, 3 * sizeof(btScalar));
	}
};

// The hinge axis of joint i: turning through z, y and two tilted axes so the chain moves in 3-D.
btVector3 axisOf(int i)
{
	const btVector3 axes[] = {btVector3(0, 0, 1), btVector3(0, 1, 0), btVector3(0, 1, 1), btVector3(1, 0, 1)};
	return axes[i % 4].normalized();
}

struct ChainRun
{
	std::uint64_t hash;
	btVector3 tip;           // last link's centre at the end (m)
	btScalar firstAngle;     // first joint's multi-turn angle at the end (rad)
};

ChainRun runChain()
{
	qh_test::World world;
	btRigidBody* parent = nullptr;
	std::vector<btRigidBody*> links;
	btQuaternionHingeConstraint* first = nullptr;
	for (int i = 0; i < kLinks; ++i)
	{
		const btTransform pose(btQuaternion::getIdentity(), btVector3((2 * i + 1) * kHalfLength, 0, 0));
		btRigidBody* body = world.addBox(1, btVector3(kHalfLength, btScalar(0.04), btScalar(0.04)), pose);
		// No contacts: the hash follows the joints and the solver only (mask 0 collides with nothing).
		world.world().removeRigidBody(body);
		world.world().addRigidBody(body, 1, 0);
		const btVector3 pivot(-kHalfLength, 0, 0), axis = axisOf(i);
		btQuaternionHingeConstraint* joint =
			parent ? world.add(new btQuaternionHingeConstraint(*parent, *body, btVector3(kHalfLength, 0, 0), pivot, axis, axis))
				   : world.add(new btQuaternionHingeConstraint(*body, pivot, axis));
		if (i == 0)
		{
			joint->setLimit(kLimitLow, kLimitHigh);
			first = joint;
		}
		if (i == kMotorJoint) joint->enableAngularMotor(true, kMotorSpeed, kMotorImpulse);
		links.push_back(body);
		parent = body;
	}
	Fnv1a hash;
	for (int s = 0; s < kSteps; ++s)
	{
		world.step(1);
		for (btRigidBody* b : links) hash.add(b->getCenterOfMassTransform());
	}
	return {hash.h, links.back()->getCenterOfMassPosition(), first->getMultiTurnAngle()};
}
}  // namespace

TEST(Determinism, SameChainGivesTheSameBitsEveryRun)
{
	// Two runs in one process hash to the same value, and to the constant of this precision.
	const ChainRun a = runChain();
	const ChainRun b = runChain();
	std::printf("[ figures  ] %s trajectory hash 0x%016" PRIx64 " (again 0x%016" PRIx64
				"); tip (%.6f, %.6f, %.6f) m; first joint %.6f rad\n",
				qh_test::kDouble ? "double" : "float", a.hash, b.hash, double(a.tip.x()), double(a.tip.y()),
				double(a.tip.z()), double(a.firstAngle));
	EXPECT_EQ(a.hash, b.hash) << "two runs of the same scene differ";
	EXPECT_GE(a.firstAngle, kLimitLow - kLimitSlack);  // sanity: the limit held
	EXPECT_LE(a.firstAngle, kLimitHigh + kLimitSlack);
	EXPECT_EQ(a.hash, kExpectedHash) << std::hex << "hash 0x" << a.hash
									 << ": the joint's arithmetic changed; if deliberately, update kExpectedHash";
}
