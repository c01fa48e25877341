// A ragdoll falling onto the ground: hinged knees and elbows, and — so that every joint is of the kind compared —
// hinges also at the hips, shoulders and neck (about the body's lateral axis). Joints together with contacts.
#include "SceneSpec.h"

#include <random>

namespace quathinge
{
namespace scenes
{
SceneSpec ragdollScene(unsigned seed)
{
	SceneSpec s;
	s.name = "ragdoll";
	s.description = "ragdoll (10 boxes, 9 hinges) dropped from 1.5 m onto the ground, tumbling";
	std::mt19937 rng(seed);
	std::uniform_real_distribution<double> spin(-2, 2);
	const btScalar y0 = btScalar(1.5);
	auto box = [&](btScalar mass, btVector3 half, btVector3 centre) {
		BodySpec b;
		b.mass = mass;
		b.halfExtents = half;
		b.pose = btTransform(btQuaternion::getIdentity(), centre + btVector3(0, y0, 0));
		b.collides = true;
		s.bodies.push_back(b);
		return int(s.bodies.size()) - 1;
	};
	const btVector3 limb(btScalar(0.06), btScalar(0.2), btScalar(0.06));
	const int torso = box(20, btVector3(btScalar(0.2), btScalar(0.3), btScalar(0.1)), btVector3(0, 0, 0));
	const int head = box(4, btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)), btVector3(0, btScalar(0.42), 0));
	const int upperArmL = box(2, limb, btVector3(btScalar(-0.28), btScalar(0.1), 0));
	const int lowerArmL = box(1, limb, btVector3(btScalar(-0.28), btScalar(-0.32), 0));
	const int upperArmR = box(2, limb, btVector3(btScalar(0.28), btScalar(0.1), 0));
	const int lowerArmR = box(1, limb, btVector3(btScalar(0.28), btScalar(-0.32), 0));
	const int thighL = box(5, limb, btVector3(btScalar(-0.1), btScalar(-0.52), 0));
	const int shinL = box(3, limb, btVector3(btScalar(-0.1), btScalar(-0.94), 0));
	const int thighR = box(5, limb, btVector3(btScalar(0.1), btScalar(-0.52), 0));
	const int shinR = box(3, limb, btVector3(btScalar(0.1), btScalar(-0.94), 0));
	auto hinge = [&](int parent, int child, btVector3 pivot, btScalar lo, btScalar hi) {
		JointSpec j;
		j.parent = parent;
		j.child = child;
		j.pivot = pivot + btVector3(0, y0, 0);
		j.axis = btVector3(1, 0, 0);
		j.hasLimit = true;
		j.lower = lo;
		j.upper = hi;
		s.joints.push_back(j);
	};
	hinge(torso, head, btVector3(0, btScalar(0.31), 0), btScalar(-0.5), btScalar(0.5));           // neck
	hinge(torso, upperArmL, btVector3(btScalar(-0.28), btScalar(0.31), 0), -2, 2);                // shoulders
	hinge(torso, upperArmR, btVector3(btScalar(0.28), btScalar(0.31), 0), -2, 2);
	hinge(upperArmL, lowerArmL, btVector3(btScalar(-0.28), btScalar(-0.11), 0), btScalar(-2.5), 0);  // elbows
	hinge(upperArmR, lowerArmR, btVector3(btScalar(0.28), btScalar(-0.11), 0), btScalar(-2.5), 0);
	hinge(torso, thighL, btVector3(btScalar(-0.1), btScalar(-0.31), 0), btScalar(-1.5), btScalar(0.5));  // hips
	hinge(torso, thighR, btVector3(btScalar(0.1), btScalar(-0.31), 0), btScalar(-1.5), btScalar(0.5));
	hinge(thighL, shinL, btVector3(btScalar(-0.1), btScalar(-0.73), 0), 0, btScalar(2.5));        // knees
	hinge(thighR, shinR, btVector3(btScalar(0.1), btScalar(-0.73), 0), 0, btScalar(2.5));
	s.bodies[size_t(torso)].angularVelocity = btVector3(btScalar(spin(rng)), btScalar(spin(rng)), btScalar(spin(rng)));
	s.ground = true;
	s.reference = Reference::None;
	s.duration = 3;
	return s;
}

}  // namespace scenes
}  // namespace quathinge
