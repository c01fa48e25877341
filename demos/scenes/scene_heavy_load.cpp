// Heavy on light: a 5-link chain (1 kg links) carrying a load of `ratio` times a link's mass, released horizontally.
// Iterative solvers converge slowly on such mass ratios: this is where joints stretch or blow up.
#include "SceneSpec.h"

#include <cmath>

namespace quathinge
{
namespace scenes
{
SceneSpec heavyLoadScene(double ratio)
{
	SceneSpec s;
	s.name = "heavy" + std::to_string(int(ratio));
	s.description = "5-link chain carrying a load 1:" + std::to_string(int(ratio)) + " of a link's mass";
	appendChain(s, 5, btScalar(0.5), 1, btVector3(0, 0, 0), [](int) { return btVector3(0, 0, 1); });
	BodySpec load;
	load.mass = btScalar(ratio);
	load.halfExtents = btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1));
	load.pose = btTransform(btQuaternion::getIdentity(), btVector3(btScalar(2.5 + 0.1), 0, 0));
	s.bodies.push_back(load);
	JointSpec j;
	j.parent = 4;
	j.child = 5;
	j.pivot = btVector3(btScalar(2.5), 0, 0);
	j.axis = btVector3(0, 0, 1);
	s.joints.push_back(j);
	s.conservative = true;
	s.duration = 5;
	return s;
}

}  // namespace scenes
}  // namespace quathinge
