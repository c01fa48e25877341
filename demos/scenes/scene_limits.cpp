// Limits: a stop hit at 20 rad/s, a range straddling ±π, a range wider than a turn. A bar on a vertical hinge (gravity
// exerts no torque about the axis), so only the limit decides the motion.
#include "SceneSpec.h"

namespace quathinge
{
namespace scenes
{
namespace
{
SceneSpec bar(const std::string& name, const std::string& description)
{
	SceneSpec s;
	s.name = name;
	s.description = description;
	BodySpec body;
	body.halfExtents = btVector3(btScalar(0.5), btScalar(0.05), btScalar(0.05));
	s.bodies = {body};
	JointSpec j;
	j.parent = -1;
	j.child = 0;
	j.pivot = btVector3(0, 0, 0);
	j.axis = btVector3(0, 1, 0);
	s.joints = {j};
	s.reference = Reference::FineStep;
	s.duration = 2;
	return s;
}
}  // namespace

SceneSpec limitHitScene()
{
	SceneSpec s = bar("limit_hit", "bar at 20 rad/s into a stop at ±1 rad");
	s.joints[0].hasLimit = true;
	s.joints[0].lower = -1;
	s.joints[0].upper = 1;
	s.bodies[0].angularVelocity = btVector3(0, 20, 0);
	return s;
}

SceneSpec limitAcrossPiScene()
{
	SceneSpec s = bar("limit_across_pi", "limit [2.5, 3.8] rad straddling π, bar starting at 3.0 rad spun at 8 rad/s");
	s.joints[0].childFrameTwist = btQuaternion(btVector3(0, 0, 1), btScalar(3.0));  // θ = 3.0 at the start
	s.joints[0].hasLimit = true;
	s.joints[0].lower = btScalar(2.5);
	s.joints[0].upper = btScalar(3.8);
	s.bodies[0].angularVelocity = btVector3(0, 8, 0);
	return s;
}

SceneSpec limitWideScene()
{
	SceneSpec s = bar("limit_wide", "limit [-3π, 3π] (1.5 turns each way), driven by a 6 rad/s motor");
	s.joints[0].hasLimit = true;
	s.joints[0].lower = -3 * SIMD_PI;
	s.joints[0].upper = 3 * SIMD_PI;
	s.joints[0].drive = Drive::Velocity;
	s.joints[0].target = 6;
	s.joints[0].maxEffort = 20;  // N·m: reaches 6 rad/s within 0.03 s, then pushes the stop with 20 N·m
	s.duration = 3;
	return s;
}

}  // namespace scenes
}  // namespace quathinge
