// A 6-dof's error as Bullet's own 6-dof reads it (calculateTransforms: getRelativePivotPosition, frame A's axes ·
// (p_B − p_A), and getAngle, its Euler angles), against each locked axis's value (low == high): the stabilizer tests'
// independent measure of how well a locked 6-dof holds (test_stabilizer_locked.cpp, test_stabilizer_euler_locks.cpp),
// and of how far its limited axes are past their limits; and Dof2, the tests' btGeneric6DofSpring2Constraint factory.
#ifndef QUATHINGE_TESTS_LOCKED_DOF_ERROR_H
#define QUATHINGE_TESTS_LOCKED_DOF_ERROR_H

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>

namespace qh_test
{
/// Calls f(position, angle, low, high, angularLow, angularHigh) for each axis k of c, with c's own reading now
/// (getRelativePivotPosition, getAngle: m, rad) and its limits.
template <class Dof, class F>
void forEachDofAxis(Dof& c, F f)
{
	c.calculateTransforms();
	btVector3 low, high, angularLow, angularHigh;
	c.getLinearLowerLimit(low);
	c.getLinearUpperLimit(high);
	c.getAngularLowerLimit(angularLow);
	c.getAngularUpperLimit(angularHigh);
	for (int k = 0; k < 3; ++k)
		f(double(c.getRelativePivotPosition(k)), double(c.getAngle(k)), double(low[k]), double(high[k]),
		  double(angularLow[k]), double(angularHigh[k]));
}

/// Raises `distance` (m) and `angle` (rad) to the largest error of c's locked linear axes and angles, now.
template <class Dof>
void lockedDofError(Dof& c, double& distance, double& angle)
{
	forEachDofAxis(c, [&](double x, double a, double low, double high, double angularLow, double angularHigh) {
		if (low == high) distance = std::max(distance, std::fabs(x - low));
		if (angularLow == angularHigh) angle = std::max(angle, std::fabs(a - angularLow));
	});
}

/// Raises `distance` (m) and `angle` (rad) to how far c's limited axes (low < high) are past their limits, now.
template <class Dof>
void limitedDofPast(Dof& c, double& distance, double& angle)
{
	forEachDofAxis(c, [&](double x, double a, double low, double high, double angularLow, double angularHigh) {
		if (low < high) distance = std::max({distance, low - x, x - high});
		if (angularLow < angularHigh) angle = std::max({angle, angularLow - a, a - angularHigh});
	});
}

/// A btGeneric6DofSpring2Constraint made as a btGeneric6DofConstraint is (it has no useLinearReferenceFrameA): one
/// constructor for the tests' random 6-dofs of either family (test_stabilizer_euler_locks.cpp, _dof_limits.cpp).
struct Dof2 : btGeneric6DofSpring2Constraint
{
	Dof2(btRigidBody& a, btRigidBody& b, const btTransform& fa, const btTransform& fb, bool)
		: btGeneric6DofSpring2Constraint(a, b, fa, fb)
	{
	}
};
}  // namespace qh_test

#endif
