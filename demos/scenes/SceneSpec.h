// The scene library shared by the comparison demo, the benchmark and the tests. A scene is a plain description —
// bodies, hinge joints (pivot and axis in world at the start), gravity, duration, which reference it is judged by —
// and a joint kind (JointKinds.h) turns it into a Bullet world. Every scene is deterministic: it takes a seed and
// draws any randomness from it. One file per scene (scene_*.cpp); SceneRegistry.cpp lists them.
#ifndef QUATHINGE_SCENE_SPEC_H
#define QUATHINGE_SCENE_SPEC_H

#include "LinearMath/btQuaternion.h"
#include "LinearMath/btTransform.h"
#include "LinearMath/btVector3.h"

#include <functional>
#include <string>
#include <vector>

namespace quathinge
{
namespace scenes
{
/// A body's collision shape (it also gives the inertia when BodySpec::localInertia is zero).
enum class Shape
{
	Box,        ///< btBoxShape(halfExtents)
	Capsule,    ///< btCapsuleShape along local y: radius halfExtents.x, total length 2·halfExtents.y (caps included)
	Sphere,     ///< btSphereShape(halfExtents.x)
	Cylinder,   ///< btCylinderShape along local y: radius halfExtents.x, half height halfExtents.y
	ConvexHull  ///< btConvexHullShape of ShapePart::points (a mesh's vertices); only as a ShapePart
};

/// One piece of a body's compound collision shape (a URDF <collision> element).
struct ShapePart
{
	Shape shape = Shape::Box;
	btVector3 halfExtents = btVector3(0, 0, 0);      ///< m (see Shape)
	btTransform local = btTransform::getIdentity();  ///< the piece's pose in its body's frame
	std::vector<btVector3> points;                   ///< Shape::ConvexHull: the vertices (m, the piece's frame)
};

struct BodySpec
{
	btScalar mass = 1;  ///< kg; 0 makes a static body
	/// Principal moments of inertia (kg·m²) in the body frame; zero: those of the box (URDF bodies give their own).
	btVector3 localInertia = btVector3(0, 0, 0);
	Shape shape = Shape::Box;
	btVector3 halfExtents = btVector3(btScalar(0.05), btScalar(0.25), btScalar(0.05));  ///< m (see Shape)
	btTransform pose = btTransform::getIdentity();                                      ///< world pose at t = 0
	btVector3 linearVelocity = btVector3(0, 0, 0);                                      ///< m/s
	btVector3 angularVelocity = btVector3(0, 0, 0);                                     ///< rad/s (world)
	bool collides = false;                                                              ///< take part in contacts (ragdoll on the ground)
	/// When not empty, the body's collision shape is the compound of these (`shape` and `halfExtents` then unused).
	std::vector<ShapePart> parts;
};

enum class Drive
{
	None,
	Velocity,  ///< target angular velocity `target` (rad/s) with at most `maxEffort` N·m (each kind converts it to its
			   ///< own unit: an impulse of maxEffort·h per step for btHingeConstraint's motor and the multibody motor)
	Servo      ///< target angle `target` (rad) at most `maxSpeed` rad/s with at most `maxEffort` N·m
};

/// A hinge. Angles are θ: the child's rotation about +axis relative to the parent, 0 at the start pose.
struct JointSpec
{
	int parent = -1;  ///< body index, −1 for the world
	int child = 0;    ///< body index
	btVector3 pivot;  ///< world, at t = 0
	btVector3 axis;   ///< world unit vector, at t = 0
	/// Rotation applied to the child's joint frame: the joint starts misaligned by it (flipped starts). Identity
	/// for an assembled joint.
	btQuaternion childFrameTwist = btQuaternion::getIdentity();
	/// Offset (m, world, at t = 0) of the child's pivot from `pivot`: the joint starts separated by it. Zero for an
	/// assembled joint.
	btVector3 childPivotOffset = btVector3(0, 0, 0);
	bool hasLimit = false;
	btScalar lower = 0, upper = 0;  ///< rad (θ)
	Drive drive = Drive::None;
	btScalar target = 0, maxSpeed = SIMD_INFINITY, maxEffort = 0;
};

/// A prismatic joint (a URDF robot's gripper fingers): the child slides along `axis` relative to the parent, every
/// other degree of freedom locked. It is not a hinge, so it is not one of the compared joints: every
/// maximal-coordinate kind builds it the same way (btGeneric6DofSpring2Constraint, as pybullet's maximal-coordinate
/// URDF import does), the multibody kind as a prismatic link (as pybullet's default import), and the metrics measure
/// it on its own (Metrics::maxSliderSeparation).
struct SliderSpec
{
	int parent = -1;  ///< body index, −1 for the world
	int child = 0;    ///< body index
	btVector3 pivot;  ///< world, at t = 0: the joint frame's origin (slide 0)
	btVector3 axis;   ///< world unit vector, at t = 0
	bool hasLimit = false;
	btScalar lower = 0, upper = 0;  ///< m along axis from the start
};

/// How a scene's trajectory error is judged.
enum class Reference
{
	FineStep,        ///< the same scene and kind at a 16× smaller step with 100 iterations
	PendulumPeriod,  ///< the exact period of a physical pendulum (complete elliptic integral)
	None             ///< no trajectory reference (contacts, loaded scenes): drift and stability only
};

struct SceneSpec
{
	std::string name;
	std::string description;
	std::vector<BodySpec> bodies;
	std::vector<JointSpec> joints;
	std::vector<SliderSpec> sliders;  ///< prismatic joints (URDF robots); not compared (SliderSpec)
	btVector3 gravity = btVector3(0, -10, 0);
	double duration = 5;        ///< s simulated by default
	bool conservative = false;  ///< energy should be conserved (no drives, limits, contacts or damping)
	bool ground = false;        ///< a static ground plane at y = 0
	/// Bodies may be deactivated (Bullet's sleeping); false keeps them awake (DISABLE_DEACTIVATION), as games keep
	/// ragdolls and vehicles.
	bool allowSleep = false;
	/// Shapes fixed to the world, drawn with it and without contacts (a URDF's root link, which is the world).
	std::vector<ShapePart> worldParts;
	Reference reference = Reference::FineStep;
	double exactPeriod = 0;  ///< s, for Reference::PendulumPeriod
	/// s: the scene's own time step where its source fixes one (Gazebo's 1 ms world); 0: none. The sweep
	/// (demos/sweep) runs it at this step; quathinge-compare runs every scene at its --dt.
	double dt = 0;
	/// rad: when ≥ 0, runScene measures Gazebo's out-of-plane angle (the largest |pitch| and |yaw| of any body's
	/// ZYX Euler angles, Metrics::maxOutOfPlaneRad) and this is the bound its source holds it to.
	double outOfPlaneBound = -1;
	/// For scenes loaded from files: a reason the scene cannot run here (a missing file, a part the loader cannot
	/// represent: the file, the part and why); empty when it can.
	std::string unavailable;
	/// For scenes that are a file rather than a description (spider.bullet): builds the bodies and stock hinges
	/// into a world; the kinds then convert the hinges. Empty for described scenes.
	std::string bulletFile;
};

/// The tree test for reduced-coordinate kinds: every body has at most one parent joint and there is no loop.
bool isTree(const SceneSpec& scene);

/// The step a scene runs at by its own measure: SceneSpec::dt where its source fixes one, else 60 Hz (the
/// project's reference step, RunSettings' default).
inline double sceneStep(const SceneSpec& scene) { return scene.dt > 0 ? scene.dt : 1.0 / 60; }

/// Every scene name, in a stable order.
std::vector<std::string> sceneNames();
/// Where the models (URDF, .bullet) are: $QUATHINGE_MODELS_DIR when set; else `share/quathinge/models` beside the
/// installed program (`<prefix>/bin/../share/quathinge/models`) when it exists; else the source tree's demos/models.
std::string defaultModelsDir();
/// Where the manual (docs/*.md) is, for the programs' --help: `share/doc/quathinge/docs` beside the installed program
/// (`<prefix>/bin/../share/doc/quathinge/docs`) when it exists; else the source tree's docs/.
std::string manualDir();
/// The scene of that name (throws std::invalid_argument for an unknown name). `modelsDir` is where the models are
/// (URDF, .bullet; empty: defaultModelsDir()); `seed` drives any randomness.
SceneSpec makeScene(const std::string& name, unsigned seed = 1, const std::string& modelsDir = "");

// The scene builders (one file each).
SceneSpec pendulumScene();
SceneSpec chainScene(int links, unsigned seed);
SceneSpec heavyLoadScene(double ratio);
SceneSpec doublePendulumScene();
SceneSpec rotorScene(double spin);
SceneSpec flippedStartScene(double degrees);
SceneSpec limitHitScene();
SceneSpec limitAcrossPiScene();
SceneSpec limitWideScene();
SceneSpec motorLiftScene();
SceneSpec fourBarScene();
SceneSpec ragdollScene(unsigned seed);
SceneSpec restScene(int chains, int links, bool sleeping);
SceneSpec spiderScene(const std::string& modelsDir);
/// Gazebo classic's inertia-ratio pendulum (massRatio ≤ 0), or the same with a light:heavy mass ratio of 1:massRatio.
SceneSpec inertiaRatioScene(double massRatio);
SceneSpec urdfScene(const std::string& name, const std::string& path);

/// A chain of boxes hanging from the world, link i's top at `top` + i·(0, −length, 0) (helper for several scenes).
void appendChain(SceneSpec& scene, int links, btScalar length, btScalar mass, const btVector3& top,
				 const std::function<btVector3(int)>& axisOf);

}  // namespace scenes
}  // namespace quathinge

#endif
