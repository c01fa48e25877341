// The stabilizer tests' scene (tests/test_stabilizer_*.cpp): a Bullet world that owns what is put in it, the chains
// and joints the tests build, the joint errors they measure and the tolerances they hold them to, per precision
// (Debian's float Bullet and BT_USE_DOUBLE_PRECISION).
#ifndef QUATHINGE_TESTS_STABILIZER_SCENE_H
#define QUATHINGE_TESTS_STABILIZER_SCENE_H

#include "quathinge/btQuaternionHingeConstraint.h"
#include "quathinge/btQuaternionHingeStabilizer.h"

#include <btBulletDynamicsCommon.h>

#include <memory>
#include <vector>

namespace qh_test
{
const btScalar kTimeStep = btScalar(1) / 60;  // s: the project's reference scenes run at 60 Hz, 10 solver iterations
const double kRadToDeg = 180.0 / 3.14159265358979323846;

#ifdef BT_USE_DOUBLE_PRECISION
const double kSeparationTolerance = 1e-9;       // m: the brief's double-precision target
const double kHeavySeparationTolerance = 1e-9;  // m: 1:1000 converges as far in double
const double kResidualTolerance = 1e-9;         // m or rad: ‖C‖∞ the projection leaves (default tolerance 1e-10)
#else
// m: float positions a few metres from the origin are resolved to ~5e-7 m, and the pivot separation is the difference
// of two rounded positions; the projection stops at 4ε|x| (MATH.md Q13; IslandProjection.cpp), ~5e-6 m at 10 m.
const double kSeparationTolerance = 1e-5;
const double kHeavySeparationTolerance = 1e-4;  // m: the brief's figure for a 1:1000 mass ratio in float
const double kResidualTolerance = 1e-5;         // m or rad: ‖C‖∞ left, the same rounding floor as the separation
#endif
const double kMisalignmentToleranceDeg = 1e-3;  // degrees between the two hinge axes: the brief's target (1.7e-5 rad)

/// The stabilizer's settings with only the hinges projected (projectPointConstraints, projectLockedConstraints and
/// projectContacts off, 0.1's defaults): for the tests of what happens to the constraints and contacts it leaves out.
inline btQuaternionHingeStabilizerSettings hingesOnly()
{
	btQuaternionHingeStabilizerSettings s;
	s.projectPointConstraints = s.projectLockedConstraints = s.projectContacts = false;
	return s;
}

// Owns a btDiscreteDynamicsWorld and everything in it; builds the scenes the tests share.
class StabilizerScene
{
public:
	StabilizerScene();
	~StabilizerScene();

	btDiscreteDynamicsWorld& world() { return *m_world; }

	void addAction(btActionInterface* action);

	/// A box of the given half extents; mass 0 makes it static.
	btRigidBody* box(const btVector3& halfExtents, btScalar mass, const btVector3& position,
					 const btQuaternion& rotation = btQuaternion::getIdentity());

	btQuaternionHingeConstraint* hinge(btRigidBody& a, btRigidBody& b, const btVector3& pivotInA,
									   const btVector3& pivotInB, const btVector3& axisInA, const btVector3& axisInB);

	btQuaternionHingeConstraint* hingeToWorld(btRigidBody& a, const btVector3& pivotInA, const btVector3& axisInA);

	void addConstraint(btTypedConstraint* c);

	/// The 3-D chain of the prototype figures (MATH.md): n links 0.5 m long along +x at height `height`, hinge axes
	/// alternating z and y, the first link hinged to the world; released horizontally. The last link has mass
	/// `lastMass` (1 kg like the others unless a heavy load is asked for).
	std::vector<btRigidBody*> chain(int n, btScalar lastMass = 1, btScalar height = 10);

	/// Largest pivot separation (m) and hinge-axis misalignment (degrees) over the scene's enabled hinges.
	void jointErrors(double& separation, double& misalignmentDeg) const;

	bool allFinite() const;

	/// Every collision object's world transform, in the world's order; setPoses puts them back (a projection called
	/// again on the same state, with no solver step between).
	std::vector<btTransform> poses() const;
	void setPoses(const std::vector<btTransform>& poses);

	const std::vector<btQuaternionHingeConstraint*>& hinges() const { return m_hinges; }

private:
	btDefaultCollisionConfiguration m_config;
	btCollisionDispatcher m_dispatcher;
	btDbvtBroadphase m_broadphase;
	btSequentialImpulseConstraintSolver m_solver;
	std::unique_ptr<btDiscreteDynamicsWorld> m_world;
	std::vector<std::unique_ptr<btCollisionShape>> m_shapes;
	std::vector<std::unique_ptr<btMotionState>> m_motionStates;
	std::vector<std::unique_ptr<btRigidBody>> m_bodies;
	std::vector<std::unique_ptr<btTypedConstraint>> m_constraints;
	std::vector<btQuaternionHingeConstraint*> m_hinges;
	std::vector<btActionInterface*> m_actions;
};

// A stabilizer's work per step, averaged over a run.
struct StabilizerWork
{
	double newtonPerStep = 0;          // Newton iterations (the most any island used)
	double factorizationsPerStep = 0;  // factorizations of K, all islands
};

// Steps `steps` times at 60 Hz and returns the largest separation and misalignment seen after any step; with
// `stabilizer` and `work`, also that stabilizer's mean work per step.
void runAndMeasure(StabilizerScene& scene, int steps, double& separation, double& misalignmentDeg,
				   const btQuaternionHingeStabilizer* stabilizer = nullptr, StabilizerWork* work = nullptr);

bool sameTransform(const btTransform& a, const btTransform& b);

}  // namespace qh_test

#endif
