// A ragdoll falling onto the ground: capsule torso and limbs (btCapsuleShape), a sphere head; hinged knees and elbows,
// and — so that every joint is of the kind compared — the same hinge kind also at the hips, shoulders and neck (about
// the body's lateral axis), not btConeTwistConstraint. Joints together with contacts.
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
	s.description = "ragdoll (9 capsules and a sphere, 9 hinges with limits) dropped from 1.5 m onto the ground, tumbling";
	std::mt19937 rng(seed);
	std::uniform_real_distribution<double> spin(-2, 2);
	const btScalar y0 = btScalar(1.5);
	auto body = [&](btScalar mass, Shape shape, btVector3 half, btVector3 centre) {
		BodySpec b;
		b.mass = mass;
		b.shape = shape;
		b.halfExtents = half;
		b.pose = btTransform(btQuaternion::getIdentity(), centre + btVector3(0, y0, 0));
		b.collides = true;
		s.bodies.push_back(b);
		return int(s.bodies.size()) - 1;
	};
	const btVector3 limb(btScalar(0.06), btScalar(0.2), btScalar(0.06));  // capsule: radius 0.06 m, 0.4 m long
	auto capsule = [&](btScalar mass, btVector3 half, btVector3 centre) { return body(mass, Shape::Capsule, half, centre); };
	const int torso = capsule(20, btVector3(btScalar(0.15), btScalar(0.3), btScalar(0.15)), btVector3(0, 0, 0));
	const int head = body(4, Shape::Sphere, btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)), btVector3(0, btScalar(0.42), 0));
	const int upperArmL = capsule(2, limb, btVector3(btScalar(-0.28), btScalar(0.1), 0));
	const int lowerArmL = capsule(1, limb, btVector3(btScalar(-0.28), btScalar(-0.32), 0));
	const int upperArmR = capsule(2, limb, btVector3(btScalar(0.28), btScalar(0.1), 0));
	const int lowerArmR = capsule(1, limb, btVector3(btScalar(0.28), btScalar(-0.32), 0));
	const int thighL = capsule(5, limb, btVector3(btScalar(-0.1), btScalar(-0.52), 0));
	const int shinL = capsule(3, limb, btVector3(btScalar(-0.1), btScalar(-0.94), 0));
	const int thighR = capsule(5, limb, btVector3(btScalar(0.1), btScalar(-0.52), 0));
	const int shinR = capsule(3, limb, btVector3(btScalar(0.1), btScalar(-0.94), 0));
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
	hinge(torso, head, btVector3(0, btScalar(0.31), 0), btScalar(-0.5), btScalar(0.5));  // neck
	hinge(torso, upperArmL, btVector3(btScalar(-0.28), btScalar(0.31), 0), -2, 2);       // shoulders
	hinge(torso, upperArmR, btVector3(btScalar(0.28), btScalar(0.31), 0), -2, 2);
	hinge(upperArmL, lowerArmL, btVector3(btScalar(-0.28), btScalar(-0.11), 0), btScalar(-2.5), 0);  // elbows
	hinge(upperArmR, lowerArmR, btVector3(btScalar(0.28), btScalar(-0.11), 0), btScalar(-2.5), 0);
	hinge(torso, thighL, btVector3(btScalar(-0.1), btScalar(-0.31), 0), btScalar(-1.5), btScalar(0.5));  // hips
	hinge(torso, thighR, btVector3(btScalar(0.1), btScalar(-0.31), 0), btScalar(-1.5), btScalar(0.5));
	hinge(thighL, shinL, btVector3(btScalar(-0.1), btScalar(-0.73), 0), 0, btScalar(2.5));  // knees
	hinge(thighR, shinR, btVector3(btScalar(0.1), btScalar(-0.73), 0), 0, btScalar(2.5));
	s.bodies[size_t(torso)].angularVelocity = btVector3(btScalar(spin(rng)), btScalar(spin(rng)), btScalar(spin(rng)));
	s.ground = true;
	s.reference = Reference::None;
	s.duration = 3;
	return s;
}

}  // namespace scenes
}  // namespace quathinge
