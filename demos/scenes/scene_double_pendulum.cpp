// A double pendulum with a 1:400 inertia ratio between its links and gravity tilted 3° toward the hinge axes, so
// any axis drift shows as out-of-plane motion.
#include "SceneSpec.h"

#include <cmath>

namespace quathinge
{
namespace scenes
{
SceneSpec doublePendulumScene()
{
	SceneSpec s;
	s.name = "double_pendulum";
	s.description = "double pendulum, light thin upper link and a heavy wide lower link, gravity 3° off the plane";
	const btQuaternion alongX(btVector3(0, 0, 1), -SIMD_HALF_PI);
	BodySpec upper;
	upper.mass = 1;
	upper.halfExtents = btVector3(btScalar(0.02), btScalar(0.5), btScalar(0.02));
	upper.pose = btTransform(alongX, btVector3(btScalar(0.5), 0, 0));
	BodySpec lower;
	lower.mass = 20;
	lower.halfExtents = btVector3(btScalar(0.6), btScalar(0.5), btScalar(0.6));
	lower.pose = btTransform(alongX, btVector3(btScalar(1.5), 0, 0));
	s.bodies = {upper, lower};
	JointSpec top;
	top.parent = -1;
	top.child = 0;
	top.pivot = btVector3(0, 0, 0);
	top.axis = btVector3(0, 0, 1);
	JointSpec elbow = top;
	elbow.parent = 0;
	elbow.child = 1;
	elbow.pivot = btVector3(1, 0, 0);
	s.joints = {top, elbow};
	const double tilt = 3 * M_PI / 180;
	s.gravity = btVector3(0, btScalar(-10 * std::cos(tilt)), btScalar(-10 * std::sin(tilt)));
	s.conservative = true;
	s.duration = 5;
	return s;
}

}  // namespace scenes
}  // namespace quathinge
