// Chains hanging at rest: 50 chains of 10 links straight down from the world, nothing moving. What a game keeps in
// its world most of the time (ragdolls and vehicles waiting, kept awake so that they answer a touch at once), and
// where a stabilizer has nothing to do: it should cost next to nothing (issue 15). `sleeping`: Bullet may deactivate
// the bodies (its default); else they stay awake (DISABLE_DEACTIVATION, as every other scene here).
#include "SceneSpec.h"

namespace quathinge
{
namespace scenes
{
SceneSpec restScene(int chains, int links, bool sleeping)
{
	SceneSpec s;
	s.name = "rest" + std::to_string(chains * links) + (sleeping ? "_asleep" : "");
	s.description = std::to_string(chains) + " chains of " + std::to_string(links) +
					" links hanging at rest (0.5 m links)" + (sleeping ? ", allowed to sleep" : ", kept awake");
	const btScalar length = btScalar(0.5);
	for (int c = 0; c < chains; ++c)
	{
		const btVector3 top(btScalar(0.5) * btScalar(c), 0, 0);
		const int first = int(s.bodies.size());
		for (int i = 0; i < links; ++i)
		{
			BodySpec body;
			body.mass = 1;
			body.halfExtents = btVector3(btScalar(0.05), length / 2, btScalar(0.05));  // long axis along y: hanging
			body.pose = btTransform(btQuaternion::getIdentity(), top - btVector3(0, length * (btScalar(i) + btScalar(0.5)), 0));
			s.bodies.push_back(body);
			JointSpec joint;
			joint.parent = i == 0 ? -1 : first + i - 1;
			joint.child = first + i;
			joint.pivot = top - btVector3(0, length * btScalar(i), 0);
			joint.axis = i % 2 == 0 ? btVector3(0, 0, 1) : btVector3(1, 0, 0);
			s.joints.push_back(joint);
		}
	}
	s.allowSleep = sleeping;
	s.conservative = true;
	s.reference = Reference::None;  // the answer is known: nothing moves
	s.duration = 5;
	return s;
}

}  // namespace scenes
}  // namespace quathinge
