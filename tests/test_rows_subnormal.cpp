// The rows never hand Bullet's solver a subnormal number (MatrixLanes.h, storeXyz): round-off products of the frames
// underflow there, and on x86 cores a subnormal operand costs a microcode assist in every solver iteration (r2d2.urdf
// stepped 3.3 × slower on an Intel Xeon, README "Cost").
#include "MatrixLanes.h"
#include "support/ScratchRows.h"

#ifdef QUATHINGE_HAVE_SCENES
#include "JointKinds.h"
#include "SceneSpec.h"
#include "Simulation.h"
#endif

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

namespace
{
bool subnormal(btScalar x) { return std::fpclassify(x) == FP_SUBNORMAL; }

bool sameBits(btScalar a, btScalar b) { return std::memcmp(&a, &b, sizeof a) == 0; }
}  // namespace

TEST(RowsSubnormal, FlushKeepsEveryValueButSubnormals)
{
	using Limits = std::numeric_limits<btScalar>;
	const btScalar tiny = Limits::min() / 4, smallest = Limits::denorm_min();
	const struct
	{
		btScalar in, out;
	} cases[] = {
		{Limits::min(), Limits::min()},   // the smallest normal number stays
		{-Limits::min(), -Limits::min()},
		{tiny, btScalar(0)},              // subnormals become a zero of their sign
		{-tiny, -btScalar(0)},
		{smallest, btScalar(0)},
		{btScalar(0), btScalar(0)},
		{-btScalar(0), -btScalar(0)},
		{btScalar(1), btScalar(1)},
		{btScalar(-2.5e-17), btScalar(-2.5e-17)},
		{Limits::max(), Limits::max()},
		{Limits::infinity(), Limits::infinity()},
		{-Limits::infinity(), -Limits::infinity()},
	};
	for (const auto& c : cases)
	{
		const quathinge::Lanes in = {c.in, c.in, c.in, c.in};
		const quathinge::Lanes out = quathinge::flushSubnormals(in);
		for (int k = 0; k < 4; ++k) EXPECT_TRUE(sameBits(out[k], c.out)) << double(c.in) << " → " << double(out[k]);
	}
	const quathinge::Lanes nan = {Limits::quiet_NaN(), tiny, btScalar(1), -tiny};
	const quathinge::Lanes flushed = quathinge::flushSubnormals(nan);
	EXPECT_TRUE(std::isnan(flushed[0])) << "a NaN stays a NaN (the joint's own checks report it)";
	EXPECT_TRUE(sameBits(flushed[1], btScalar(0)));
	EXPECT_TRUE(sameBits(flushed[2], btScalar(1)));
	EXPECT_TRUE(sameBits(flushed[3], -btScalar(0)));
}

#ifdef QUATHINGE_HAVE_SCENES
TEST(RowsSubnormal, R2d2sRowsHaveNoSubnormalAfterThreeSeconds)
{
	// Bullet's r2d2.urdf with quaternion hinges, 3 s at 60 Hz: before the rows were flushed, 8 of their Jacobian
	// entries were subnormal (its axial rows' −1, −8.9e-18, −2.5e-39; a point row's −1.6e-41, 8.9e-25, 1), where
	// stock's rows had none
	using namespace quathinge::scenes;
	const SceneSpec r2d2 = makeScene("r2d2");
	if (r2d2.unavailable.rfind("built without", 0) == 0) GTEST_SKIP() << r2d2.unavailable;  // urdfdom is optional
	ASSERT_TRUE(r2d2.unavailable.empty()) << r2d2.unavailable;
	Simulation sim(r2d2, Kind::Quaternion);
	int rows = 0, found = 0;
	for (int step = 0; step < 180; ++step)
	{
		sim.step(1.0 / 60, 10);
		btDiscreteDynamicsWorld& world = sim.world();
		for (int c = 0; c < world.getNumConstraints(); ++c)
		{
			btTypedConstraint* joint = world.getConstraint(c);
			btTypedConstraint::btConstraintInfo1 info1;
			joint->getInfo1(&info1);
			qh_test::ScratchRows scratch;
			joint->getInfo2(&scratch.info);
			for (int r = 0; r < info1.m_numConstraintRows; ++r, ++rows)
				for (int k = 0; k < 3; ++k)
					found += subnormal(scratch.linA(r)[k]) + subnormal(scratch.angA(r)[k]) + subnormal(scratch.linB(r)[k]) +
							 subnormal(scratch.angB(r)[k]);
		}
	}
	EXPECT_GT(rows, 0);
	EXPECT_EQ(found, 0) << "subnormal Jacobian entries over " << rows << " rows";
}
#endif
