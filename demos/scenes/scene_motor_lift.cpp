// A motor lifting a load: a 1 m arm with a 5 kg load at its end, driven from hanging (θ = 0) to θ = 1.2 rad at most
// 2 rad/s with at most 200 N·m, then holding it against gravity.
#include "SceneSpec.h"

namespace quathinge
{
namespace scenes
{
SceneSpec motorLiftScene()
{
	SceneSpec s;
	s.name = "motor_lift";
	s.description = "servo lifts a 1 m arm with a 5 kg load to 1.2 rad and holds it";
	BodySpec arm;
	arm.mass = 1;
	arm.halfExtents = btVector3(btScalar(0.05), btScalar(0.5), btScalar(0.05));
	arm.pose = btTransform(btQuaternion::getIdentity(), btVector3(0, btScalar(-0.5), 0));
	BodySpec load;
	load.mass = 5;
	load.halfExtents = btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1));
	load.pose = btTransform(btQuaternion::getIdentity(), btVector3(0, btScalar(-1.1), 0));
	s.bodies = {arm, load};
	JointSpec shoulder;
	shoulder.parent = -1;
	shoulder.child = 0;
	shoulder.pivot = btVector3(0, 0, 0);
	shoulder.axis = btVector3(0, 0, 1);
	shoulder.drive = Drive::Servo;
	shoulder.target = btScalar(1.2);
	shoulder.maxSpeed = 2;
	shoulder.maxEffort = 200;
	JointSpec wrist;
	wrist.parent = 0;
	wrist.child = 1;
	wrist.pivot = btVector3(0, -1, 0);
	wrist.axis = btVector3(0, 0, 1);
	wrist.hasLimit = true;  // the load hangs rigidly from the arm
	s.joints = {shoulder, wrist};
	s.duration = 4;
	return s;
}

}  // namespace scenes
}  // namespace quathinge
