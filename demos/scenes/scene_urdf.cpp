// Robots from URDF (urdfdom): every link a body at the zero configuration with the mass and principal inertia of its
// <inertial>, every revolute or continuous joint a hinge (fixed joints: a hinge locked at 0), the root link static.
// Collision geometry is not used (the scene has no contacts); each body is a small box for drawing only.
#include "SceneSpec.h"

#include <urdf_parser/urdf_parser.h>

#include <fstream>
#include <map>
#include <sstream>

namespace quathinge
{
namespace scenes
{
namespace
{
btTransform toBullet(const urdf::Pose& pose)
{
	return btTransform(btQuaternion(btScalar(pose.rotation.x), btScalar(pose.rotation.y), btScalar(pose.rotation.z),
									btScalar(pose.rotation.w)),
					   btVector3(btScalar(pose.position.x), btScalar(pose.position.y), btScalar(pose.position.z)));
}
}  // namespace

SceneSpec urdfScene(const std::string& name, const std::string& path)
{
	SceneSpec s;
	s.name = name;
	s.description = "robot from URDF " + path + " released from its zero configuration";
	s.gravity = btVector3(0, 0, -10);  // URDF convention: z up
	s.duration = 3;
	std::ifstream file(path);
	if (!file)
	{
		s.unavailable = "URDF file not found: " + path;
		return s;
	}
	std::stringstream text;
	text << file.rdbuf();
	urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(text.str());
	if (!model)
	{
		s.unavailable = "URDF file could not be parsed: " + path;
		return s;
	}
	// Forward kinematics at the zero configuration, root first.
	std::map<std::string, btTransform> linkPose;
	std::map<std::string, int> bodyOf;
	std::vector<urdf::LinkConstSharedPtr> queue{model->getRoot()};
	linkPose[model->getRoot()->name] = btTransform::getIdentity();
	for (size_t i = 0; i < queue.size(); ++i)
	{
		const urdf::LinkConstSharedPtr link = queue[i];
		const btTransform pose = linkPose[link->name];
		if (link->inertial && link != model->getRoot())
		{
			BodySpec body;
			body.mass = btScalar(link->inertial->mass);
			body.localInertia = btVector3(btScalar(link->inertial->ixx), btScalar(link->inertial->iyy), btScalar(link->inertial->izz));
			body.halfExtents = btVector3(btScalar(0.03), btScalar(0.03), btScalar(0.03));
			body.pose = pose * toBullet(link->inertial->origin);
			s.bodies.push_back(body);
			bodyOf[link->name] = int(s.bodies.size()) - 1;
		}
		for (const urdf::JointSharedPtr& joint : link->child_joints)
		{
			const btTransform childPose = pose * toBullet(joint->parent_to_joint_origin_transform);
			linkPose[joint->child_link_name] = childPose;
			queue.push_back(model->getLink(joint->child_link_name));
		}
	}
	for (const auto& entry : model->joints_)
	{
		const urdf::JointSharedPtr& joint = entry.second;
		if (!bodyOf.count(joint->child_link_name)) continue;
		if (joint->type != urdf::Joint::REVOLUTE && joint->type != urdf::Joint::CONTINUOUS &&
			joint->type != urdf::Joint::FIXED)
			continue;
		JointSpec j;
		j.parent = bodyOf.count(joint->parent_link_name) ? bodyOf[joint->parent_link_name] : -1;
		j.child = bodyOf[joint->child_link_name];
		const btTransform frame = linkPose[joint->child_link_name];
		j.pivot = frame.getOrigin();
		btVector3 axis(btScalar(joint->axis.x), btScalar(joint->axis.y), btScalar(joint->axis.z));
		if (axis.length2() == 0) axis = btVector3(1, 0, 0);
		j.axis = (frame.getBasis() * axis).normalized();
		if (joint->type == urdf::Joint::FIXED)
		{
			j.hasLimit = true;  // locked
		}
		else if (joint->type == urdf::Joint::REVOLUTE && joint->limits)
		{
			j.hasLimit = true;
			j.lower = btScalar(joint->limits->lower);
			j.upper = btScalar(joint->limits->upper);
		}
		s.joints.push_back(j);
	}
	if (s.joints.empty()) s.unavailable = "URDF has no revolute joint between bodies with inertia: " + path;
	return s;
}

}  // namespace scenes
}  // namespace quathinge
