// A scene's Bullet world for one joint kind (JointKinds.h), without the metrics: what runScene measures and what the
// benchmark (demos/bench/) builds and steps. Defined in Simulation.cpp; the multibody kind in SimulationMultiBody.cpp.
#ifndef QUATHINGE_SIMULATION_H
#define QUATHINGE_SIMULATION_H

#include "JointFactory.h"
#include "JointKinds.h"
#include "SceneSpec.h"

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <vector>

class btMultiBody;
class btMultiBodyConstraint;
class btMultiBodyLinkCollider;
class btBulletWorldImporter;
class btQuaternionHingeStabilizer;
class btMLCPSolverInterface;

namespace quathinge
{
namespace scenes
{
/// One measured joint: the two bodies and the joint frames in them (the same for every kind).
struct MeasuredJoint
{
	btRigidBody* a;
	btRigidBody* b;
	btTransform frameA, frameB;
	bool hasLimit = false;
	double lower = 0, upper = 0;  // θ, rad (a slider's: m along its slide, frame A's x)
	double theta = 0;             // continuous θ measured from the frames (independent of the kind's own angle)
	bool thetaValid = false;
};

/// A joint's error now: the distance between its pivots (m) and the angle between its axes (deg), measured from the
/// bodies and the scene's frames (not from the kind's own rows). The one place the demos compute it (RunScene.cpp).
struct JointError
{
	double separation;
	double misalignmentDeg;
};
JointError measureJointError(const MeasuredJoint& j);
/// Joint errors gathered over a run: the largest over joints and steps, and the RMS over both (runScene's measures,
/// and MatchedStates.h's).
struct JointErrorStats
{
	double maxSeparation = 0;       ///< m
	double maxMisalignmentDeg = 0;  ///< deg
	double sumSeparation2 = 0, sumMisalignment2 = 0;
	long samples = 0;
	void add(const JointError& e)
	{
		maxSeparation = std::max(maxSeparation, e.separation);
		maxMisalignmentDeg = std::max(maxMisalignmentDeg, e.misalignmentDeg);
		sumSeparation2 += e.separation * e.separation;
		sumMisalignment2 += e.misalignmentDeg * e.misalignmentDeg;
		++samples;
	}
	double rmsSeparation() const { return samples ? std::sqrt(sumSeparation2 / double(samples)) : 0; }
	double rmsMisalignmentDeg() const { return samples ? std::sqrt(sumMisalignment2 / double(samples)) : 0; }
};
/// A slider's (SceneSpec::sliders) error now: the distance (m) of the child's joint origin from the parent's slide
/// line (the frames' x axis), the direction a prismatic joint leaves free excluded.
double measureSliderSeparation(const MeasuredJoint& j);
/// How far (m) a slider's child is past its limits (MeasuredJoint::lower, upper) along the slide, frame A's x ·
/// (p_B − p_A); 0 within them or without a limit.
double measureSliderPastLimits(const MeasuredJoint& j);

/// Updates j.theta from the joint's frames (Simulation.cpp): at the start, and every step for runScene's limit figures.
void trackTheta(MeasuredJoint& j);

/// A world with one kind of joint in it: the scene's bodies, and its joints from the kind's factory (JointFactory.h)
/// or, for the multibody kinds, btMultiBody trees (loops closed by btMultiBodyPoint2Point). Throws std::runtime_error for
/// a scene the kind cannot build (multibody: misaligned starts, .bullet files; MLCP: past kMlcpMaxRows).
class Simulation
{
public:
	Simulation(const SceneSpec& scene, Kind kind);
	~Simulation();
	Simulation(const Simulation&) = delete;
	Simulation& operator=(const Simulation&) = delete;
	/// One internal step of dt (s) with that many solver iterations (stepSimulation(dt, 0, dt)).
	void step(double dt, int iterations);
	/// Solver rows of the compared joints at the last step.
	int rows();
	double energy() const;
	bool finiteAndBounded() const;
	/// btMultiBody::setMaxCoordinateVelocity on every multibody (its constructor clamps joint rates at 100 rad/s; the
	/// common reference lifts the clamp, Reference.h). No effect on the maximal-coordinate kinds.
	void setMaxCoordinateVelocity(double rate);
	/// btMLCPSolver::getNumFallbacks(): the solves Dantzig failed and sequential impulse redid; −1 for other solvers.
	int mlcpFallbacks() const;
	std::vector<btVector3> positions() const;
	/// The world (for the benchmark's counters: contacts, constraints).
	btDiscreteDynamicsWorld& world() { return *m_world; }
	/// The post-stabilizer (Kind::QuaternionStabilized), else null.
	const btQuaternionHingeStabilizer* stabilizer() const;
	btQuaternionHingeStabilizer* stabilizer();
	std::vector<MeasuredJoint> joints;
	/// The scene's prismatic joints (SceneSpec::sliders), frames with x along the slide; not among the compared joints.
	std::vector<MeasuredJoint> sliders;
	std::vector<btRigidBody*> bodies;  // the scene's dynamic bodies, in scene order

private:
	void loadBulletFile(const SceneSpec& scene);
	void buildMultiBodies(const SceneSpec& scene, btRigidBody* anchor);
	void addSlider(const SliderSpec& s, btRigidBody& a, btRigidBody& b);
	void syncProxies();
	Kind m_kind;
	bool m_multiBody;               // a multibody kind (solverOf)
	const JointFactory* m_factory;  // null for the multibody kinds
	btVector3 m_gravity;
	std::unique_ptr<btDefaultCollisionConfiguration> m_config;
	std::unique_ptr<btCollisionDispatcher> m_dispatcher;
	std::unique_ptr<btDbvtBroadphase> m_broadphase;
	std::unique_ptr<btMLCPSolverInterface> m_dantzig;  // the MLCP kinds' direct solver (m_solver uses it)
	std::unique_ptr<btConstraintSolver> m_solver;
	std::unique_ptr<btDiscreteDynamicsWorld> m_world;
	// Multibody kind: the multibodies, their constraints and colliders, and for each scene body a proxy rigid body
	// (not in the world) that mirrors its link's state, so every metric reads the same btRigidBody interface.
	struct LinkRef
	{
		btMultiBody* mb;
		int link;  // −1: the base
	};
	std::vector<std::unique_ptr<btMultiBody>> m_multiBodies;
	std::vector<std::unique_ptr<btMultiBodyConstraint>> m_mbConstraints;
	std::vector<std::unique_ptr<btMultiBodyLinkCollider>> m_colliders;
	std::vector<LinkRef> m_proxyOf;  // per scene body
	int m_mbRows = 0;
	std::vector<std::unique_ptr<btCollisionShape>> m_shapes;
	std::vector<std::unique_ptr<btRigidBody>> m_ownedBodies;
	std::vector<std::unique_ptr<btTypedConstraint>> m_ownedJoints;
	std::vector<btTypedConstraint*> m_compared;   // the joints being compared (rows counted)
	std::unique_ptr<btActionInterface> m_action;  // the kind's action (a post-stabilizer), if any
	std::vector<StepHook> m_beforeStep;           // the kind's drive settings that depend on the step
	// Only set when built with the Bullet world importer (QUATHINGE_HAVE_WORLD_IMPORTER, private to the scene
	// library): the deleter is defined there, so this layout does not depend on that definition.
	struct ImporterDeleter
	{
		void operator()(btBulletWorldImporter* importer) const;
	};
	std::unique_ptr<btBulletWorldImporter, ImporterDeleter> m_importer;
};

}  // namespace scenes
}  // namespace quathinge

#endif
