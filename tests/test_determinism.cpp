// Determinism: the same scene gives the same bits. A 10-link 3-D chain of quaternion hinges (a limit on the first
// joint, a motor on the fifth) stepped 120 times hashes (FNV-1a over the raw bytes of every body transform after
// every step) to the same value on every run in a process, and to a constant fixed per platform and precision.
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
const int kSteps = 120;                        // at 60 Hz: 2 s
const btScalar kHalfLength = btScalar(0.2);    // m, half a link
const btScalar kLimitLow = btScalar(-0.5);     // rad, first joint
const btScalar kLimitHigh = btScalar(0.5);     // rad
const btScalar kMotorSpeed = btScalar(2);      // rad/s, fifth joint
const btScalar kMotorImpulse = btScalar(0.5);  // N·m·s per step
const int kMotorJoint = 4;
const btScalar kLimitSlack = btScalar(0.1);  // rad: how far past a stop the sanity check lets it be

// The expected hash of the trajectory: a golden of one platform and one Bullet build, since the bits depend on the
// instruction set, on whether the compiler fuses a*b+c into one rounding (FMA contraction), on the maths functions
// (sinf, cosf, ... in Bullet's integration), and on how Bullet itself was compiled. Each changes only when the joint's
// arithmetic changes (rows, errors, limit or motor logic, the order of floating-point operations) or Bullet's does:
// whoever moves the numbers deliberately updates these constants (run the test on that platform, copy the hash it
// prints; cmake/ci-cross.sh runs the cross ones). docs/PLATFORMS.md lists them.
//  - x86-64 Linux, GCC, Debian's Bullet packages: the Release build at -O2 and the sanitizer build at -O0 give the same
//    bits, SSE arithmetic having no excess precision and GCC contracting nothing into FMAs without -march.
//  - aarch64 Linux, GCC, Bullet 3.24 from source (Release): GCC contracts into fused multiply-adds by default there
//    (-ffp-contract=fast, and every ARMv8 core has them), in QuatHinge's code and in Bullet's; measured under
//    qemu-aarch64, which computes a fused multiply-add exactly as the hardware does.
//  - Windows x86-64, MinGW-w64 GCC, Bullet 3.24 from source (Release): the maths functions are MinGW-w64's own, linked
//    into the program (it imports none from msvcrt.dll), so the bits measured under wine are those on Windows.
// Elsewhere, or in a precision not measured there, there is no golden: the test then checks that two runs give the
// same bits, and says so.
#if defined(__x86_64__) && defined(__linux__)
#define QH_GOLDEN_PLATFORM "x86-64 Linux, Debian's Bullet"
#ifdef BT_USE_DOUBLE_PRECISION
#define QH_GOLDEN_HASH 0x8bdcfa08cbe16eb2ULL
#else
#define QH_GOLDEN_HASH 0x94eb0d13902d887fULL
#endif
#elif defined(__aarch64__) && defined(__linux__) && !defined(BT_USE_DOUBLE_PRECISION)
#define QH_GOLDEN_PLATFORM "aarch64 Linux, Bullet from source"
#define QH_GOLDEN_HASH 0x3524b0fa7c5a8007ULL
#elif defined(_WIN64) && defined(__MINGW64__) && !defined(BT_USE_DOUBLE_PRECISION)
#define QH_GOLDEN_PLATFORM "Windows x86-64 MinGW-w64, Bullet from source"
#define QH_GOLDEN_HASH 0x30daafa0592a6c46ULL
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
	btVector3 tip;        // last link's centre at the end (m)
	btScalar firstAngle;  // first joint's multi-turn angle at the end (rad)
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
#ifdef QH_GOLDEN_HASH
	EXPECT_EQ(a.hash, std::uint64_t(QH_GOLDEN_HASH))
		<< std::hex << "hash 0x" << a.hash << " on " << QH_GOLDEN_PLATFORM
		<< ": the joint's arithmetic changed; if deliberately, update that platform's constant";
#else
	std::printf("[ figures  ] no golden hash for this platform and precision: two runs compared only\n");
#endif
}
