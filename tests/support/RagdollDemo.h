// Bullet's RagdollDemo ragdoll (the 2.x Demos/RagdollDemo; the same ragdoll is the RagDoll of bullet3's
// examples/Benchmarks/BenchmarkDemo.cpp), built here in this project's own code from its published layout: 11 capsules
// of 1 kg, hinges at the spine, knees and elbows, btConeTwistConstraints at the neck, hips and shoulders, the demo's
// damping and sleeping thresholds, every joint added with collisions between its bodies disabled. The ground is a
// static btCollisionObject, as the demo makes it, or a static btRigidBody (BenchmarkDemo's). Built when
// QuatHinge::Stabilizer is (tests/test_stabilizer_ragdoll_demo.cpp, tests/test_stabilizer_mixed.cpp).
#ifndef QUATHINGE_TESTS_RAGDOLL_DEMO_H
#define QUATHINGE_TESTS_RAGDOLL_DEMO_H

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <memory>
#include <vector>

namespace qh_test
{
enum class RagdollGround
{
	CollisionObject,  ///< a static btCollisionObject (RagdollDemo's ground)
	StaticBody        ///< a static btRigidBody of mass 0
};

/// A world of RagdollDemo ragdolls on a ground box whose top is at y = 0 (gravity −10 m/s², Bullet's defaults otherwise).
class RagdollDemoWorld
{
public:
	explicit RagdollDemoWorld(RagdollGround ground);
	~RagdollDemoWorld();
	btDiscreteDynamicsWorld& world() { return *m_world; }
	/// The ground (a btCollisionObject or a static btRigidBody, as constructed).
	const btCollisionObject* ground() const { return m_ground; }
	/// One ragdoll standing with its feet `offset` above the origin, turned by `yaw` about y, its pelvis spun at
	/// `spin` rad/s about z (so that ragdolls fall differently).
	void addRagdoll(const btVector3& offset, btScalar yaw, btScalar spin);
	/// The largest pivot separation (m) of the world's enabled hinges, and of its cone twists.
	void jointSeparations(double& hinge, double& cone) const;
	/// How far past its limits (rad, ≥ 0) the world's hinges are at most (getHingeAngle against its limits), and its
	/// cone twists (the swing, the angle between the frames' x axes, past its span: RagdollDemo's cones are round;
	/// the twist, Bullet's own getTwistAngle after calcAngleInfo2, past its twist span).
	void limitsPast(double& hinge, double& cone) const;
	/// The deepest penetration (m, ≥ 0) of a contact point into the ground at the bodies' current poses (the
	/// manifolds' points on the bodies, against the ground's top y = 0). `touching` (optional): the parts with a point
	/// in a manifold with the ground.
	double groundPenetration(std::vector<const btCollisionObject*>* touching = nullptr) const;
	/// Each ragdoll part's penetration (m; negative: its clearance) into the ground's top y = 0 at its current pose,
	/// in the order the parts were made: the depth of the capsule's deepest point (one of its two spheres' bottoms),
	/// which is what Bullet's next collision detection finds. A manifold point is a material point of the part, and a
	/// turn can bring one towards the bottom of its sphere, deeper, without the part going any deeper.
	/// `bodies` (optional): the parts, in the same order.
	void partPenetrations(std::vector<double>& depths, std::vector<const btCollisionObject*>* bodies = nullptr) const;

private:
	btRigidBody* body(btScalar mass, btCollisionShape* shape, const btTransform& pose);

	btDefaultCollisionConfiguration m_config;
	btCollisionDispatcher m_dispatcher;
	btDbvtBroadphase m_broadphase;
	btSequentialImpulseConstraintSolver m_solver;
	std::unique_ptr<btDiscreteDynamicsWorld> m_world;
	std::vector<std::unique_ptr<btCollisionShape>> m_shapes;
	std::unique_ptr<btCollisionObject> m_groundObject;  // the ground as a btCollisionObject, or null
	btCollisionObject* m_ground = nullptr;
	std::vector<std::unique_ptr<btRigidBody>> m_bodies;
	std::vector<std::unique_ptr<btTypedConstraint>> m_constraints;
};

/// An action that records, when it runs, the deepest ground contact (RagdollDemoWorld::groundPenetration: the
/// manifolds' points at the bodies' current transforms, not Bullet's stored distances, which are those of the last
/// collision detection), each ragdoll part's own penetration (RagdollDemoWorld::partPenetrations) and which parts
/// touch the ground (a ground manifold with a point): added just before and just after the stabilizer, the pair
/// measures what one call of it did to the contacts.
class RagdollGroundProbe : public btActionInterface
{
public:
	explicit RagdollGroundProbe(const RagdollDemoWorld& world) : m_world(world) {}
	void updateAction(btCollisionWorld*, btScalar) override
	{
		depth = m_world.groundPenetration(&touching);
		m_world.partPenetrations(parts, &partBodies);
	}
	void debugDraw(btIDebugDraw*) override {}
	// m: the most a part (of those touching the ground at `before`'s run, or of the others) is deeper now than then,
	// penetrations only (a part that leaves the ground, or stays above it, deepens nothing)
	double deepeningSince(const RagdollGroundProbe& before, bool touchingParts) const
	{
		double most = 0;
		for (size_t i = 0; i < parts.size() && i < before.parts.size(); ++i)
		{
			const bool touched =
				std::find(before.touching.begin(), before.touching.end(), partBodies[i]) != before.touching.end();
			if (touched == touchingParts) most = std::max(most, std::max(parts[i], 0.0) - std::max(before.parts[i], 0.0));
		}
		return most;
	}
	double depth = 0;                                  // m
	std::vector<double> parts;                         // m
	std::vector<const btCollisionObject*> partBodies;  // … whose
	std::vector<const btCollisionObject*> touching;    // the parts touching the ground

private:
	const RagdollDemoWorld& m_world;
};

}  // namespace qh_test

#endif
