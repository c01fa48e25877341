// Shared test fixture: a small Bullet world that owns its bodies and constraints, steps at a fixed rate, and measures
// what the tests compare (joint separation in m, axis misalignment in degrees) for any hinge-like joint; with it the
// scratch solver rows (ScratchRows.h). Both are in the QuatHingeTestSupport library (support/CMakeLists.txt).
#ifndef QUATHINGE_TESTS_WORLD_H
#define QUATHINGE_TESTS_WORLD_H

#include "support/ScratchRows.h"

#include <btBulletDynamicsCommon.h>

#include <memory>
#include <vector>

namespace qh_test
{
enum class SolverKind
{
	SequentialImpulse,
	NNCG,
	MLCPDantzig
};

/// Degrees per radian.
constexpr double kDeg = 180.0 / 3.14159265358979323846;

class World
{
public:
	explicit World(SolverKind solver = SolverKind::SequentialImpulse, const btVector3& gravity = btVector3(0, -10, 0));
	/// With a solver of the test's own (e.g. one that records the rows' impulses); the world owns it.
	World(std::unique_ptr<btConstraintSolver> solver, const btVector3& gravity);
	~World();
	World(const World&) = delete;
	World& operator=(const World&) = delete;

	/// A box body of the given half extents; mass 0 makes it static.
	btRigidBody* addBox(btScalar mass, const btVector3& halfExtents, const btTransform& pose);
	/// Adds (and owns) a constraint.
	template <class T>
	T* add(T* constraint, bool disableCollisions = true)
	{
		m_constraints.emplace_back(constraint);
		m_world->addConstraint(constraint, disableCollisions);
		return constraint;
	}
	void step(int steps = 1, btScalar dt = btScalar(1) / 60, int iterations = 10);
	btDiscreteDynamicsWorld& world() { return *m_world; }

private:
	std::unique_ptr<btDefaultCollisionConfiguration> m_config;
	std::unique_ptr<btCollisionDispatcher> m_dispatcher;
	std::unique_ptr<btBroadphaseInterface> m_broadphase;
	std::unique_ptr<btConstraintSolver> m_solver;
	std::unique_ptr<btDiscreteDynamicsWorld> m_world;
	std::vector<std::unique_ptr<btCollisionShape>> m_shapes;
	std::vector<std::unique_ptr<btRigidBody>> m_bodies;
	std::vector<std::unique_ptr<btTypedConstraint>> m_constraints;
	struct Extra;
	std::unique_ptr<Extra> m_extra;
};

/// Distance between the two world pivots (m) and angle between the two world hinge axes (deg), given a joint's frames.
double separation(const btRigidBody& a, const btTransform& frameA, const btRigidBody& b, const btTransform& frameB);
double misalignmentDeg(const btRigidBody& a, const btTransform& frameA, const btRigidBody& b,
					   const btTransform& frameB);

/// Rotation by the rotation vector w (axis · angle).
btQuaternion expRotation(const btVector3& w);

/// True when the body's transform and velocities are all finite.
bool finiteState(const btRigidBody& body);

/// How many times `body` holds `constraint` among its constraint references: a world registers a constraint with
/// its bodies when it was added with disableCollisionsBetweenLinkedBodies = true (once), else not at all.
int constraintRefs(btRigidBody& body, const btTypedConstraint* constraint);

/// Moves the dynamic one of the two bodies (B unless B is static) so that the joint frames coincide in position and
/// hinge axis, with joint frame B turned by theta (rad) about the hinge axis from joint frame A: the pose of a perfect
/// hinge at quaternion angle θ (MATH.md Q4, Q11).
void placeOnHinge(btRigidBody& a, const btTransform& frameA, btRigidBody& b, const btTransform& frameB, btScalar theta);

/// True when btScalar is double.
constexpr bool kDouble = sizeof(btScalar) == 8;

}  // namespace qh_test

#endif
