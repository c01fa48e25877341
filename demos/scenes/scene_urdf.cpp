// Robots from URDF, read as pybullet's importer reads them (Bullet's examples/Importers/ImportURDFDemo), with urdfdom
// for the model and tinyxml2 for what urdfdom does not accept:
// - every link but the root a body at the zero configuration, with the mass and the principal moments of its inertia
//   tensor (diagonalized: the body frame is the inertial frame turned onto the principal axes). A link without
//   <inertial> gets pybullet's default (1 kg, moments 1 kg·m², frame at the link). The inertia is the file's (as
//   pybullet with URDF_USE_INERTIA_FROM_FILE; without that flag pybullet takes it from the collision shapes). A
//   massless link (mass 0: a converted multi-axis joint's intermediate link, as in Bullet's humanoid.urdf) cannot be
//   a rigid body, so it gets a stand-in (kMasslessMassFraction of the lightest link's mass and of the smallest
//   moment), said in the description;
// - the root link is the world (the robot hangs from its base); its collision shapes are drawn with the world;
// - every revolute or continuous joint a hinge; revolute with pybullet's limits: lower and upper default to 0 and −1,
//   and lower > upper is no limit (continuous), as URDF2Bullet; a fixed joint a hinge locked at 0; a prismatic joint
//   a slider (SceneSpec::sliders: a 6-dof constraint in every maximal-coordinate kind, as pybullet's
//   maximal-coordinate import; a prismatic link in the multibody kind),
//   its limits in metres read the same way;
// - every <collision> a piece of the body's compound shape: box, sphere, cylinder, capsule (pybullet's extension:
//   the cylinder part `length` long, along z; pybullet makes a cylinder a 32-sided hull unless asked for the implicit
//   cylinder, which this is), STL meshes (their vertices' convex hull) and OBJ meshes (a convex hull per group of
//   faces), as pybullet reads meshes for a moving link. The scene has no ground and no contacts: the shapes are
//   drawn. A link without <collision> is drawn as the box of its inertia.
// Anything else is refused, never dropped: a planar, floating or spherical joint, a zero axis, a mesh that
// is missing or neither STL nor OBJ (Collada), a file urdfdom cannot parse or reports an error in (with urdfdom's own
// message) make the scene unavailable with the file, the part and the reason. Not modelled (as pybullet's
// maximal-coordinate import): joint <dynamics> damping and friction, effort and velocity limits, <mimic>; the
// description counts the joints that have them.
// This file builds the scene; the XML pre-pass is UrdfPrepass.cpp, the collision shapes and meshes UrdfCollision.cpp.
#include "SceneSpec.h"
#include "UrdfLoader.h"

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
#include <mutex>
#include <sstream>
#include <stdexcept>

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
	btVector3 h(0, 0, 0);          // all four floats set (GCC -O3 warns of the unused fourth otherwise)
	for (int k = 0; k < 3; ++k)
	{
		const double sq = 3 / (2 * mass) * (double(moments[(k + 1) % 3]) + double(moments[(k + 2) % 3]) - double(moments[k]));
		h[k] = btScalar(std::max(kMinHalf, std::sqrt(std::max(0.0, sq))));
	}
	return h;
}
}  // namespace

#ifdef QUATHINGE_HAVE_URDFDOM
using namespace urdfimport;

namespace
{
/// A massless link's stand-in: this fraction of the lightest link's mass and of the model's smallest moment of
/// inertia. Smaller is nearer the massless model but harder for the maximal-coordinate solver: humanoid.urdf, 3 s at
/// 60 Hz, stock's max separation is 11.7 m at 0.01, 1.13 m at 0.1, 0.14 m at 1 (quaternion+stab ≤ 1.5e-6 m in all).
const double kMasslessMassFraction = 0.1;
/// m: half the side of the cube that draws a massless link (it has no inertia of its own to draw a box of).
const btScalar kStandInHalfExtent = btScalar(0.02);

#ifdef QUATHINGE_HAVE_CONSOLE_BRIDGE
/// Collects urdfdom's error messages (so a refusal says what urdfdom found) while it is installed.
class CollectErrors : public console_bridge::OutputHandler
{
public:
	CollectErrors() { console_bridge::useOutputHandler(this); }
	~CollectErrors() override { console_bridge::restorePreviousOutputHandler(); }
	CollectErrors(const CollectErrors&) = delete;
	CollectErrors& operator=(const CollectErrors&) = delete;
	void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override
	{
		if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) messages += (messages.empty() ? "" : "; ") + text;
	}
	std::string messages;
};
#endif

/// The scene of a parsed, preprocessed model (throws Refusal naming the part it cannot represent).
void buildScene(SceneSpec& s, const urdf::ModelInterface& model, const Preprocessed& pre, const std::string& path)
{
	// the massless links' stand-in: a fraction of the lightest link's mass and of the smallest positive moment
	double lightestMass = 0, smallestMoment = 0;
	for (const auto& entry : model.links_)
	{
		const urdf::Inertial* in = entry.second->inertial.get();
		if (!in || !(in->mass > 0) || entry.second == model.getRoot()) continue;
		if (lightestMass == 0 || in->mass < lightestMass) lightestMass = in->mass;
		for (double moment : {in->ixx, in->iyy, in->izz})
			if (moment > 0 && (smallestMoment == 0 || moment < smallestMoment)) smallestMoment = moment;
	}
	// Forward kinematics at the zero configuration, root first.
	std::map<std::string, btTransform> linkPose;
	std::map<std::string, int> bodyOf;
	std::vector<urdf::LinkConstSharedPtr> queue{model.getRoot()};
	linkPose[model.getRoot()->name] = btTransform::getIdentity();
	int standIns = 0;
	for (size_t i = 0; i < queue.size(); ++i)
	{
		const urdf::LinkConstSharedPtr link = queue[i];
		const btTransform pose = linkPose[link->name];
		const std::vector<bool>& capsules = pre.capsule.at(link->name);
		if (capsules.size() != link->collision_array.size())
			throw Refusal("link '" + link->name + "': urdfdom read " + std::to_string(link->collision_array.size()) +
						  " of its " + std::to_string(capsules.size()) + " <collision> elements");
		if (!link->inertial && std::find(pre.inertial.begin(), pre.inertial.end(), link->name) != pre.inertial.end())
			throw Refusal("link '" + link->name + "': urdfdom did not read its <inertial>");
		std::vector<ShapePart> parts;  // in the link's frame
		for (size_t c = 0; c < link->collision_array.size(); ++c) try
			{
				for (ShapePart& part : collisionParts(*link->collision_array[c], capsules[c], path)) parts.push_back(std::move(part));
			}
			catch (const Refusal& e)
			{
				throw Refusal("link '" + link->name + "' <collision> " + std::to_string(c + 1) + ": " + e.what());
			}
		if (link == model.getRoot())
		{
			s.worldParts = parts;
		}
		else
		{
			BodySpec body;
			btTransform inertialFrame = btTransform::getIdentity();  // the principal frame in the link's frame
			if (!link->inertial)
			{
				body.mass = 1;  // pybullet's default for a link without <inertial>
				body.localInertia = btVector3(1, 1, 1);
			}
			else if (link->inertial->mass > 0)
			{
				const urdf::Inertial& in = *link->inertial;
				btMatrix3x3 tensor(btScalar(in.ixx), btScalar(in.ixy), btScalar(in.ixz), btScalar(in.ixy), btScalar(in.iyy),
								   btScalar(in.iyz), btScalar(in.ixz), btScalar(in.iyz), btScalar(in.izz));
				// I = R D Rᵀ: `tensor` becomes D, `principal` is R, the principal axes (its columns) in the inertial frame
				btMatrix3x3 principal;
				tensor.diagonalize(principal, btScalar(1e-9), 30);
				body.mass = btScalar(in.mass);
				body.localInertia = btVector3(tensor[0][0], tensor[1][1], tensor[2][2]);
				inertialFrame = toBullet(in.origin) * btTransform(principal);
			}
			else if (link->inertial->mass == 0 && lightestMass > 0 && smallestMoment > 0)
			{
				const btScalar moment = btScalar(kMasslessMassFraction * smallestMoment);
				body.mass = btScalar(kMasslessMassFraction * lightestMass);
				body.localInertia = btVector3(moment, moment, moment);
				inertialFrame = toBullet(link->inertial->origin);
				++standIns;
			}
			else
			{
				throw Refusal("link '" + link->name + "': mass " + std::to_string(link->inertial->mass) +
							  (lightestMass > 0 && smallestMoment > 0 ? " is negative or not a number"
																	  : " and no link has mass and inertia"));
			}
			for (int k = 0; k < 3; ++k)
				if (!(body.localInertia[k] >= 0))
					throw Refusal("link '" + link->name + "': a principal moment of inertia is negative or not a number");
			// A link without <collision> is drawn as the box of its inertia; a massless link's stand-in has no inertia
			// of its own to draw (the box of its stand-in values can be metres wide: Bullet's panda.urdf gives every
			// link 0.1 kg·m², so its massless panda_link8 would be a 2.4 m box): a small cube marks where it is.
			const bool standIn = link->inertial && !(link->inertial->mass > 0);
			body.halfExtents = standIn ? btVector3(kStandInHalfExtent, kStandInHalfExtent, kStandInHalfExtent)
									   : boxFromInertia(double(body.mass), body.localInertia);
			body.pose = pose * inertialFrame;
			for (ShapePart& part : parts) part.local = inertialFrame.inverse() * part.local;
			body.parts = parts;
			s.bodies.push_back(body);
			bodyOf[link->name] = int(s.bodies.size()) - 1;
		}
		for (const urdf::JointSharedPtr& joint : link->child_joints)
		{
			linkPose[joint->child_link_name] = pose * toBullet(joint->parent_to_joint_origin_transform);
			queue.push_back(model.getLink(joint->child_link_name));
		}
	}
	int damped = 0, mimics = 0;
	for (const auto& entry : model.joints_)
	{
		const urdf::Joint& joint = *entry.second;
		const std::string who = "joint '" + joint.name + "'";
		if (joint.type != urdf::Joint::REVOLUTE && joint.type != urdf::Joint::CONTINUOUS &&
			joint.type != urdf::Joint::FIXED && joint.type != urdf::Joint::PRISMATIC)
			throw Refusal(who + ": a joint type that no hinge or slider can represent");
		if (!bodyOf.count(joint.child_link_name)) throw Refusal(who + ": its child link is not in the tree");
		JointSpec j;
		j.parent = bodyOf.count(joint.parent_link_name) ? bodyOf[joint.parent_link_name] : -1;
		j.child = bodyOf[joint.child_link_name];
		const btTransform frame = linkPose[joint.child_link_name];
		j.pivot = frame.getOrigin();
		btVector3 axis(btScalar(joint.axis.x), btScalar(joint.axis.y), btScalar(joint.axis.z));
		if (joint.type == urdf::Joint::FIXED) axis = btVector3(1, 0, 0);  // locked: any axis
		else if (!(axis.length2() > 0) || !std::isfinite(double(axis.length2())))
			throw Refusal(who + ": axis is zero or not finite");
		j.axis = (frame.getBasis() * axis).normalized();
		if (joint.type == urdf::Joint::FIXED)
		{
			j.hasLimit = true;  // locked
		}
		else if (joint.type != urdf::Joint::CONTINUOUS)  // revolute (rad) or prismatic (m)
		{
			const auto limit = pre.limits.find(joint.name);
			if (limit == pre.limits.end()) throw Refusal(who + ": revolute or prismatic without <limit>");
			j.hasLimit = limit->second.first <= limit->second.second;  // lower > upper: no limit, as URDF2Bullet
			if (j.hasLimit)
			{
				j.lower = btScalar(limit->second.first);
				j.upper = btScalar(limit->second.second);
			}
		}
		if (joint.dynamics && (joint.dynamics->damping != 0 || joint.dynamics->friction != 0)) ++damped;
		if (joint.mimic) ++mimics;
		if (joint.type == urdf::Joint::PRISMATIC)
			s.sliders.push_back(SliderSpec{j.parent, j.child, j.pivot, j.axis, j.hasLimit, j.lower, j.upper});
		else
			s.joints.push_back(j);
	}
	if (s.joints.empty()) throw Refusal("no revolute, continuous or fixed joint");
	if (!s.sliders.empty()) s.description += "; " + std::to_string(s.sliders.size()) + " prismatic joints as sliders";
	if (standIns > 0)
	{
		std::ostringstream say;
		say << "; " << standIns << " massless links given a stand-in (" << kMasslessMassFraction
			<< " of the lightest link's mass and of the smallest moment)";
		s.description += say.str();
	}
	if (damped > 0) s.description += "; joint damping/friction not modelled (" + std::to_string(damped) + " joints)";
	if (mimics > 0) s.description += "; <mimic> not modelled (" + std::to_string(mimics) + " joints)";
}
}  // namespace

SceneSpec urdfScene(const std::string& name, const std::string& path)
{
	SceneSpec s;
	s.name = name;
	s.description = "robot from URDF " + path + " released from its zero configuration, root link fixed to the world";
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
	try
	{
		const Preprocessed pre = preprocess(text.str());
		urdf::ModelInterfaceSharedPtr model;
		std::string urdfdomSays;
		{
			static std::mutex parsing;  // console_bridge's handler is global: one parse at a time
			const std::lock_guard<std::mutex> lock(parsing);
#ifdef QUATHINGE_HAVE_CONSOLE_BRIDGE
			CollectErrors errors;  // not a warning per undefined material on the console, the errors in the refusal
			model = urdf::parseURDF(pre.xml);
			urdfdomSays = errors.messages;
#else
			model = urdf::parseURDF(pre.xml);
#endif
		}
		// urdfdom reports some parts it cannot read and goes on without them: any error refuses the file
		if (!model || !model->getRoot() || !urdfdomSays.empty())
			throw Refusal("urdfdom cannot parse it" + (urdfdomSays.empty() ? std::string() : ": " + urdfdomSays));
		try
		{
			buildScene(s, *model, pre, path);
		}
		catch (const Refusal& e)  // what urdfdom said (e.g. of a <collision> it dropped) explains it
		{
			throw Refusal(e.what() + (urdfdomSays.empty() ? std::string() : " (urdfdom: " + urdfdomSays + ")"));
		}
	}
	catch (const Refusal& e)
	{
		s.bodies.clear();
		s.joints.clear();
		s.sliders.clear();
		s.worldParts.clear();
		s.unavailable = "URDF " + path + ": " + e.what();
		return s;
	}
	// no limits, no drives, no contacts: energy is conserved (a stop can take energy out)
	s.conservative = std::none_of(s.joints.begin(), s.joints.end(), [](const JointSpec& j) { return j.hasLimit; }) &&
					 std::none_of(s.sliders.begin(), s.sliders.end(), [](const SliderSpec& j) { return j.hasLimit; });
	return s;
}
#else
SceneSpec urdfScene(const std::string& name, const std::string& path)
{
	SceneSpec s;
	s.name = name;
	s.description = "robot from URDF " + path;
	s.unavailable = "built without urdfdom and tinyxml2 (liburdfdom-dev, libtinyxml2-dev): cannot read " + path;
	(void)boxFromInertia;
	return s;
}
#endif

}  // namespace scenes
}  // namespace quathinge
