// A 6-dof's error as Bullet's own 6-dof reads it (calculateTransforms: getRelativePivotPosition, frame A's axes ·
// (p_B − p_A), and getAngle, its Euler angles), against each locked axis's value (low == high): the stabilizer tests'
// independent measure of how well a locked 6-dof holds (test_stabilizer_locked.cpp, test_stabilizer_euler_locks.cpp),
// and of how far its limited axes are past their limits.
#ifndef QUATHINGE_TESTS_LOCKED_DOF_ERROR_H
#define QUATHINGE_TESTS_LOCKED_DOF_ERROR_H

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>

namespace qh_test
{
/// Raises `distance` (m) and `angle` (rad) to the largest error of c's locked linear axes and angles, now.
template <class Dof>
void lockedDofError(Dof& c, double& distance, double& angle)
{
	c.calculateTransforms();
	btVector3 low, high, angularLow, angularHigh;
	c.getLinearLowerLimit(low);
	c.getLinearUpperLimit(high);
	c.getAngularLowerLimit(angularLow);
	c.getAngularUpperLimit(angularHigh);
	for (int k = 0; k < 3; ++k)
	{
		if (low[k] == high[k]) distance = std::max(distance, std::fabs(double(c.getRelativePivotPosition(k) - low[k])));
		if (angularLow[k] == angularHigh[k]) angle = std::max(angle, std::fabs(double(c.getAngle(k) - angularLow[k])));
	}
}

/// Raises `distance` (m) and `angle` (rad) to how far c's limited axes (low < high) are past their limits, now.
template <class Dof>
void limitedDofPast(Dof& c, double& distance, double& angle)
{
	c.calculateTransforms();
	btVector3 low, high, angularLow, angularHigh;
	c.getLinearLowerLimit(low);
	c.getLinearUpperLimit(high);
	c.getAngularLowerLimit(angularLow);
	c.getAngularUpperLimit(angularHigh);
	for (int k = 0; k < 3; ++k)
	{
		const double x = double(c.getRelativePivotPosition(k)), a = double(c.getAngle(k));
		if (low[k] < high[k]) distance = std::max({distance, double(low[k]) - x, x - double(high[k])});
		if (angularLow[k] < angularHigh[k])
			angle = std::max({angle, double(angularLow[k]) - a, a - double(angularHigh[k])});
	}
}
}  // namespace qh_test

#endif
