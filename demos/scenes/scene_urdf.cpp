// Robots from URDF (urdfdom): every link with an <inertial> a body at the zero configuration, with the mass and the
// principal moments of its inertia tensor (diagonalized: the body frame is the inertial frame turned onto the
// principal axes); every revolute or continuous joint a hinge (revolute: with its limits), a fixed joint a hinge
// locked at 0; the root link is the world. Each body's shape is a box sized from its inertia (the box of that mass
// with those principal moments); the scene has no ground and no contacts, so it only draws and sizes the body.
// A missing or unparsable file, or a build without urdfdom, makes the scene unavailable with the reason.
#include "SceneSpec.h"

#ifdef QUATHINGE_HAVE_URDFDOM
#include <urdf_parser/urdf_parser.h>
#ifdef QUATHINGE_HAVE_CONSOLE_BRIDGE
#include <console_bridge/console.h>
#endif
#endif

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

namespace quathinge
{
namespace scenes
{
namespace
{
/// Half extents (m) of the box of mass m (kg) whose principal moments (kg·m²) are `moments`:
/// I_x = m/3 (h_y² + h_z²) and cyclic, so h_x² = 3/(2m) (I_y + I_z − I_x). A moment triple that no box has (a
/// negative square: the triangle inequality fails) gives that side a small floor.
btVector3 boxFromInertia(double mass, const btVector3& moments)
{
	const double kMinHalf = 0.01;  // m
	btVector3 h(0, 0, 0);  // all four floats set (GCC -O3 warns of the unused fourth otherwise)
	for (int k = 0; k < 3; ++k)
	{
		const double sq = 3 / (2 * mass) * (double(moments[(k + 1) % 3]) + double(moments[(k + 2) % 3]) - double(moments[k]));
		h[k] = btScalar(std::max(kMinHalf, std::sqrt(std::max(0.0, sq))));
	}
	return h;
}
}  // namespace

#ifdef QUATHINGE_HAVE_URDFDOM
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
#ifdef QUATHINGE_HAVE_CONSOLE_BRIDGE
	console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_ERROR);  // not a warning per undefined material
#endif
	urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(text.str());
	if (!model || !model->getRoot())
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
		if (link->inertial && link != model->getRoot() && link->inertial->mass > 0)
		{
			const urdf::Inertial& in = *link->inertial;
			btMatrix3x3 tensor(btScalar(in.ixx), btScalar(in.ixy), btScalar(in.ixz), btScalar(in.ixy), btScalar(in.iyy),
							   btScalar(in.iyz), btScalar(in.ixz), btScalar(in.iyz), btScalar(in.izz));
			// I = R D Rᵀ: `tensor` becomes D, `principal` is R, the principal axes (its columns) in the inertial frame
			btMatrix3x3 principal;
			tensor.diagonalize(principal, btScalar(1e-9), 30);
			BodySpec body;
			body.mass = btScalar(in.mass);
			body.localInertia = btVector3(tensor[0][0], tensor[1][1], tensor[2][2]);
			body.halfExtents = boxFromInertia(in.mass, body.localInertia);
			body.pose = pose * toBullet(in.origin) * btTransform(principal);
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
	// no limits, no drives, no contacts: energy is conserved (a stop can take energy out)
	s.conservative = std::none_of(s.joints.begin(), s.joints.end(), [](const JointSpec& j) { return j.hasLimit; });
	return s;
}
#else
SceneSpec urdfScene(const std::string& name, const std::string& path)
{
	SceneSpec s;
	s.name = name;
	s.description = "robot from URDF " + path;
	s.unavailable = "built without urdfdom (liburdfdom-dev): cannot read " + path;
	(void)boxFromInertia;
	return s;
}
#endif

}  // namespace scenes
}  // namespace quathinge
