// A rotor spinning at 100 or 1000 rad/s on a hinge whose base tumbles in free flight: gyroscopic coupling loads the
// hinge's two angular rows. (Bullet's integrator limits a body's rotation to π/4 per step, so at 60 Hz a rotor faster
// than 47 rad/s is slowed by the integrator, whatever the joint.)
#include "SceneSpec.h"

namespace quathinge
{
namespace scenes
{
SceneSpec rotorScene(double spin)
{
	SceneSpec s;
	s.name = "rotor" + std::to_string(int(spin));
	s.description = "rotor at " + std::to_string(int(spin)) + " rad/s on a tumbling base (free flight)";
	BodySpec base;
	base.mass = 5;
	base.halfExtents = btVector3(btScalar(0.3), btScalar(0.1), btScalar(0.3));
	base.angularVelocity = btVector3(2, 0, btScalar(0.5));
	BodySpec rotor;
	rotor.mass = 1;
	rotor.halfExtents = btVector3(btScalar(0.4), btScalar(0.02), btScalar(0.4));
	rotor.pose = btTransform(btQuaternion::getIdentity(), btVector3(0, btScalar(0.3), 0));
	rotor.angularVelocity = base.angularVelocity + btVector3(0, btScalar(spin), 0);
	rotor.linearVelocity = base.angularVelocity.cross(rotor.pose.getOrigin());
	s.bodies = {base, rotor};
	JointSpec j;
	j.parent = 0;
	j.child = 1;
	j.pivot = btVector3(0, btScalar(0.3), 0);
	j.axis = btVector3(0, 1, 0);
	s.joints = {j};
	s.gravity = btVector3(0, 0, 0);
	s.conservative = true;
	s.duration = 3;
	return s;
}

}  // namespace scenes
}  // namespace quathinge
