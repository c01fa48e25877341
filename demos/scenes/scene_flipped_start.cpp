// A joint that starts with its axes flipped by 90°, 179° or exactly 180° (MATH.md Q12): the child's joint frame is
// turned about x, so the constraint starts that far from satisfied and must recover.
#include "SceneSpec.h"

#include <cmath>

namespace quathinge
{
namespace scenes
{
SceneSpec flippedStartScene(double degrees)
{
	SceneSpec s;
	s.name = "flipped" + std::to_string(int(degrees));
	s.description = "two free boxes joined by a hinge whose axes start " + std::to_string(int(degrees)) + "° apart";
	BodySpec a;
	a.halfExtents = btVector3(btScalar(0.5), btScalar(0.1), btScalar(0.2));
	BodySpec b = a;
	s.bodies = {a, b};
	JointSpec j;
	j.parent = 0;
	j.child = 1;
	j.pivot = btVector3(0, 0, 0);
	j.axis = btVector3(0, 0, 1);
	j.childFrameTwist = btQuaternion(btVector3(1, 0, 0), btScalar(degrees * M_PI / 180));
	s.joints = {j};
	s.gravity = btVector3(0, 0, 0);
	s.reference = Reference::None;
	s.duration = 2;
	return s;
}

}  // namespace scenes
}  // namespace quathinge
