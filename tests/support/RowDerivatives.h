// The finite-difference check of a joint's position-level rows that the stabilizer's row tests share
// (tests/test_stabilizer_stock.cpp, tests/test_stabilizer_locked.cpp): central differences of the values under small
// translations and rotations (about world axes through the centre of mass) of either body, against the analytic
// derivative of each value along each of J's 12 columns (v_A, ω_A, v_B, ω_B). Relative error per max(1, |entry|):
// 1e-6 in double, 2e-3 in float, at a step of 1e-5 in double or float's ε^⅓ (the step that balances the
// difference's truncation against its rounding).
#ifndef QUATHINGE_TESTS_ROW_DERIVATIVES_H
#define QUATHINGE_TESTS_ROW_DERIVATIVES_H

#include "support/World.h"

#include <btBulletDynamicsCommon.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <functional>
#include <string>

namespace qh_test
{
const double kRowDerivativeTolerance = kDouble ? 1e-6 : 2e-3;  // dimensionless, per max(1, |entry|)
// m or rad
inline btScalar rowDerivativeStep() { return kDouble ? btScalar(1e-5) : btScalar(std::cbrt(double(FLT_EPSILON))); }

// t moved by s along column k of a body's 6 (k < 3: a translation along world axis k; else a rotation about world
// axis k − 3 through the centre of mass).
inline btTransform movedAlong(const btTransform& t, int k, btScalar s)
{
	btTransform moved = t;
	btVector3 e(0, 0, 0);
	e[k % 3] = s;
	if (k < 3) moved.setOrigin(t.getOrigin() + e);
	else moved.setRotation(expRotation(e) * t.getRotation());
	return moved;
}

// values(tA, tB, out) writes `count` values at the given transforms; derivative(r, column) is value r's analytic
// derivative along column 0–11. Every value along every column of both bodies is checked; `label` names the case.
// `step` (m or rad; 0: rowDerivativeStep()) is for values whose third derivative is large, where the default step's
// truncation error would exceed the tolerance: a smaller step balances it against rounding there.
inline void expectRowDerivatives(const std::function<void(const btTransform&, const btTransform&, double*)>& values,
								 const std::function<double(int, int)>& derivative, const btTransform& tA,
								 const btTransform& tB, int count, const std::string& label, btScalar step = 0)
{
	const btScalar h = step > 0 ? step : rowDerivativeStep();
	double plus[8], minus[8];
	ASSERT_LE(count, 8);
	for (int side = 0; side < 2; ++side)
		for (int k = 0; k < 6; ++k)
		{
			values(side == 0 ? movedAlong(tA, k, h) : tA, side == 1 ? movedAlong(tB, k, h) : tB, plus);
			values(side == 0 ? movedAlong(tA, k, -h) : tA, side == 1 ? movedAlong(tB, k, -h) : tB, minus);
			for (int r = 0; r < count; ++r)
			{
				const double fd = (plus[r] - minus[r]) / (2 * double(h));
				const double entry = derivative(r, 6 * side + k);
				EXPECT_NEAR(fd, entry, kRowDerivativeTolerance * std::max(1.0, std::fabs(entry)))
					<< label << " value " << r << " side " << side << " column " << k;
			}
		}
}
}  // namespace qh_test

#endif
