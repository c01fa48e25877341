// With float Bullet the rows never hand the solver a non-zero entry below 2^-40 (MatrixLanes.h, flushRoundOff,
// storeXyz): the frames' round-off makes some (a unit axis's component of 8.9e-18), the solver's products with them
// underflow into subnormal numbers, and on x86 cores a subnormal operand costs a microcode assist in every solver
// iteration (r2d2.urdf's bare quaternion world stepped 1.23 × stock's on an Intel Xeon before, 1.04 × after; README
// "Cost"). Double Bullet flushes only below 2^-300, so its rows keep their bits.
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
bool sameBits(btScalar a, btScalar b) { return std::memcmp(&a, &b, sizeof a) == 0; }
}  // namespace

TEST(RowsRoundOff, FlushKeepsEveryValueFromTheSmallestRowEntryUp)
{
	using Limits = std::numeric_limits<btScalar>;
	const btScalar smallest = btScalar(quathinge::kSmallestRowEntry), below = smallest / 2;
#ifdef BT_USE_DOUBLE_PRECISION
	EXPECT_EQ(double(smallest), std::ldexp(1.0, -300));
	const btScalar roundOff = btScalar(8.9e-18);  // kept: double's round-off stalls nothing
#else
	EXPECT_EQ(double(smallest), std::ldexp(1.0, -40));
	const btScalar roundOff = btScalar(0);  // flushed: r2d2's round-off
#endif
	const struct
	{
		btScalar in, out;
	} cases[] = {
		{smallest, smallest},  // 2^-40 itself stays
		{-smallest, -smallest},
		{btScalar(1e-12), btScalar(1e-12)},
		{btScalar(2) * smallest, btScalar(2) * smallest},
		{below, btScalar(0)},  // below it: a zero of the value's sign
		{-below, -btScalar(0)},
		{btScalar(8.9e-18), roundOff},
		{Limits::min(), btScalar(0)},
		{-Limits::denorm_min(), -btScalar(0)},
		{btScalar(0), btScalar(0)},
		{-btScalar(0), -btScalar(0)},
		{btScalar(1), btScalar(1)},
		{btScalar(-0.25), btScalar(-0.25)},
		{Limits::max(), Limits::max()},
		{Limits::infinity(), Limits::infinity()},
		{-Limits::infinity(), -Limits::infinity()},
	};
	for (const auto& c : cases)
	{
		const quathinge::Lanes in = quathinge::makeLanes(c.in, c.in, c.in, c.in);
		const quathinge::Lanes out = quathinge::flushRoundOff(in);
		for (int k = 0; k < 4; ++k) EXPECT_TRUE(sameBits(out[k], c.out)) << double(c.in) << " → " << double(out[k]);
	}
	const quathinge::Lanes mixed = quathinge::makeLanes(Limits::quiet_NaN(), below, btScalar(1), -Limits::denorm_min());
	const quathinge::Lanes flushed = quathinge::flushRoundOff(mixed);
	EXPECT_TRUE(std::isnan(flushed[0])) << "a NaN stays a NaN (the joint's own checks report it)";
	EXPECT_TRUE(sameBits(flushed[1], btScalar(0)));
	EXPECT_TRUE(sameBits(flushed[2], btScalar(1)));
	EXPECT_TRUE(sameBits(flushed[3], -btScalar(0)));
}

#if defined(QUATHINGE_HAVE_SCENES) && defined(QUATHINGE_HAVE_URDF)  // r2d2.urdf (urdfdom is optional)
namespace
{
// non-zero and below the smallest entry the rows keep
bool roundOff(btScalar x) { return x != 0 && std::fabs(double(x)) < quathinge::kSmallestRowEntry; }
}  // namespace

TEST(RowsRoundOff, R2d2sRowsHaveNoEntryBelowTheSmallestRowEntry)
{
	// Bullet's r2d2.urdf with quaternion hinges, 3 s at 60 Hz: before the rows were flushed, 8 of their Jacobian
	// entries at the end were subnormal (its axial rows' −1, −8.9e-18, −2.5e-39; a point row's −1.6e-41, 8.9e-25, 1),
	// where stock's rows had none; now no entry is non-zero and below kSmallestRowEntry (2^-40 in float)
	using namespace quathinge::scenes;
	const SceneSpec r2d2 = makeScene("r2d2");
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
					found += roundOff(scratch.linA(r)[k]) + roundOff(scratch.angA(r)[k]) + roundOff(scratch.linB(r)[k]) +
							 roundOff(scratch.angB(r)[k]);
		}
	}
	EXPECT_GT(rows, 0);
	EXPECT_EQ(found, 0) << "Jacobian entries below kSmallestRowEntry over " << rows << " rows";
}
#endif
