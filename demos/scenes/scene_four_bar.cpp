// A four-bar linkage: crank, coupler and rocker hinged to each other and to the world — a closed loop whose planar
// hinges are redundant in 3-D (four hinges, one degree of freedom).
#include "SceneSpec.h"

namespace quathinge
{
namespace scenes
{
namespace
{
BodySpec barBetween(const btVector3& from, const btVector3& to)
{
	BodySpec b;
	const btVector3 d = to - from;
	b.halfExtents = btVector3(btScalar(0.03), d.length() / 2, btScalar(0.03));
	b.pose = btTransform(shortestArcQuat(btVector3(0, 1, 0), d.normalized()), (from + to) / 2);
	return b;
}
}  // namespace

SceneSpec fourBarScene()
{
	SceneSpec s;
	s.name = "four_bar";
	s.description = "four-bar linkage (closed loop, redundant constraints), crank spun at 3 rad/s";
	const btVector3 a(0, 0, 0), b(0, btScalar(0.5), 0), c(1, btScalar(0.8), 0), d(1, 0, 0);
	s.bodies = {barBetween(a, b), barBetween(b, c), barBetween(c, d)};
	s.bodies[0].angularVelocity = btVector3(0, 0, -3);
	s.bodies[0].linearVelocity = btVector3(0, 0, -3).cross(s.bodies[0].pose.getOrigin() - a);
	const btVector3 z(0, 0, 1);
	JointSpec j;
	j.axis = z;
	j.parent = -1, j.child = 0, j.pivot = a;
	s.joints.push_back(j);
	j.parent = 0, j.child = 1, j.pivot = b;
	s.joints.push_back(j);
	j.parent = 1, j.child = 2, j.pivot = c;
	s.joints.push_back(j);
	j.parent = -1, j.child = 2, j.pivot = d;
	s.joints.push_back(j);
	s.conservative = true;
	s.duration = 4;
	return s;
}

}  // namespace scenes
}  // namespace quathinge
