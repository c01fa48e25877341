// A physical pendulum released at 90°: the one scene with an exact answer, its period (complete elliptic integral).
#include "SceneSpec.h"

#include <cmath>

namespace quathinge
{
namespace scenes
{
namespace
{
// K(k) by the arithmetic–geometric mean: K = π / (2 AGM(1, √(1 − k²))).
double ellipticK(double k)
{
	double a = 1, b = std::sqrt(1 - k * k);
	for (int i = 0; i < 30; ++i)
	{
		const double an = 0.5 * (a + b);
		b = std::sqrt(a * b);
		a = an;
	}
	return M_PI / (2 * a);
}
}  // namespace

SceneSpec pendulumScene()
{
	SceneSpec s;
	s.name = "pendulum";
	s.description = "1 m box pendulum released horizontally (90°); period checked against the elliptic integral";
	const double half = 0.5, thick = 0.05, mass = 1, g = 10, theta0 = M_PI / 2;
	BodySpec bob;
	bob.mass = btScalar(mass);
	bob.halfExtents = btVector3(btScalar(thick), btScalar(half), btScalar(thick));
	bob.pose = btTransform(btQuaternion(btVector3(0, 0, 1), -SIMD_HALF_PI), btVector3(btScalar(half), 0, 0));
	s.bodies.push_back(bob);
	JointSpec j;
	j.parent = -1;
	j.child = 0;
	j.pivot = btVector3(0, 0, 0);
	j.axis = btVector3(0, 0, 1);
	s.joints.push_back(j);
	s.gravity = btVector3(0, btScalar(-g), 0);
	s.conservative = true;
	s.reference = Reference::PendulumPeriod;
	// physical pendulum: I about the pivot = m/3 (a² + b²) + m d² for a box of half extents a, b; d = b
	const double inertia = mass / 3 * (thick * thick + half * half) + mass * half * half;
	s.exactPeriod = 4 * std::sqrt(inertia / (mass * g * half)) * ellipticK(std::sin(theta0 / 2));
	s.duration = 5;
	return s;
}

}  // namespace scenes
}  // namespace quathinge
