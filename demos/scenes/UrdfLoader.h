// What the URDF loader's parts pass each other (scene_urdf.cpp builds the scene from the XML UrdfPrepass.cpp
// prepares and the shapes UrdfCollision.cpp reads). Only with urdfdom and tinyxml2 (QUATHINGE_HAVE_URDFDOM).
#ifndef QUATHINGE_URDF_LOADER_H
#define QUATHINGE_URDF_LOADER_H
#ifdef QUATHINGE_HAVE_URDFDOM

#include "SceneSpec.h"

#include <urdf_parser/urdf_parser.h>

#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace quathinge
{
namespace scenes
{
namespace urdfimport
{
/// A part of the model the loader cannot represent: the scene is refused with this message.
struct Refusal : std::runtime_error
{
	using std::runtime_error::runtime_error;
};

inline btTransform toBullet(const urdf::Pose& pose)
{
	return btTransform(btQuaternion(btScalar(pose.rotation.x), btScalar(pose.rotation.y), btScalar(pose.rotation.z),
									btScalar(pose.rotation.w)),
					   btVector3(btScalar(pose.position.x), btScalar(pose.position.y), btScalar(pose.position.z)));
}

/// What the XML says that urdfdom would reject or read differently, and the XML urdfdom then reads.
struct Preprocessed
{
	std::string xml;
	std::map<std::string, std::vector<bool>> capsule;  ///< per link, per <collision> in order: a <capsule>
	/// per joint with <limit>: pybullet's lower and upper (absent: 0 and −1; urdfdom reads an absent bound as 0)
	std::map<std::string, std::pair<double, double>> limits;
	std::vector<std::string> inertial;  ///< the links with an <inertial> element
};

/// The XML as pybullet reads it, for urdfdom (UrdfPrepass.cpp); throws Refusal.
Preprocessed preprocess(const std::string& text);

/// One <collision> as pieces of a compound shape, in the link's frame: one piece, or one per convex part of an OBJ.
std::vector<ShapePart> collisionParts(const urdf::Collision& collision, bool capsule, const std::string& urdfPath);

}  // namespace urdfimport
}  // namespace scenes
}  // namespace quathinge

#endif
#endif
