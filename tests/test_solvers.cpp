// The joint runs under every Bullet solver a user might pick: sequential impulse, NNCG, MLCP (Dantzig), and in a
// btMultiBodyDynamicsWorld between rigid bodies.
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/World.h"

#include "BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h"
#include "BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

namespace
{
// Five links of 0.5 m released horizontally; 2 s at 60 Hz, 10 iterations. An iterative solver lets such a chain
// stretch by about 4 cm (stock and quaternion rows alike, MATH.md "Beyond the rows"); a solver that does not handle
// the joint lets it fall apart (0.5 m links). Bound: a fifth of a link.
const double kMaxSeparation = 0.1;  // m

double runChain(btDiscreteDynamicsWorld& world, std::vector<std::unique_ptr<btRigidBody>>& bodies,
				std::vector<std::unique_ptr<btQuaternionHingeConstraint>>& joints, btCollisionShape& shape)
{
	btVector3 inertia;
	shape.calculateLocalInertia(1, inertia);
	btRigidBody* parent = nullptr;
	for (int i = 0; i < 5; ++i)
	{
		bodies.emplace_back(new btRigidBody(1, nullptr, &shape, inertia));
		btRigidBody* body = bodies.back().get();
		body->setWorldTransform(btTransform(btQuaternion::getIdentity(), btVector3(btScalar(0.25 + 0.5 * i), 0, 0)));
		body->setActivationState(DISABLE_DEACTIVATION);
		world.addRigidBody(body);
		if (!parent)
			joints.emplace_back(new btQuaternionHingeConstraint(*body, btVector3(btScalar(-0.25), 0, 0), btVector3(0, 0, 1)));
		else
			joints.emplace_back(new btQuaternionHingeConstraint(*parent, *body, btVector3(btScalar(0.25), 0, 0),
																btVector3(btScalar(-0.25), 0, 0), btVector3(0, 0, 1), btVector3(0, 0, 1)));
		world.addConstraint(joints.back().get(), true);
		parent = body;
	}
	double worst = 0;
	for (int step = 0; step < 120; ++step)
	{
		world.stepSimulation(btScalar(1) / 60, 0, btScalar(1) / 60);
		for (auto& j : joints)
		{
			const double sep = qh_test::separation(j->getRigidBodyA(), j->getAFrame(), j->getRigidBodyB(), j->getBFrame());
			if (!std::isfinite(sep)) return INFINITY;
			worst = std::max(worst, sep);
		}
	}
	for (auto& j : joints) world.removeConstraint(j.get());
	for (auto& b : bodies) world.removeRigidBody(b.get());
	return worst;
}
}  // namespace

TEST(Solvers, ChainRunsUnderEveryRigidBodySolver)
{
	// Same chain under SI, NNCG and MLCP(Dantzig): finite, and the pivots stay together.
	const char* names[] = {"sequential impulse", "NNCG", "MLCP Dantzig"};
	const qh_test::SolverKind kinds[] = {qh_test::SolverKind::SequentialImpulse, qh_test::SolverKind::NNCG,
										 qh_test::SolverKind::MLCPDantzig};
	for (int k = 0; k < 3; ++k)
	{
		qh_test::World world(kinds[k]);
		btBoxShape shape(btVector3(btScalar(0.25), btScalar(0.05), btScalar(0.05)));
		std::vector<std::unique_ptr<btRigidBody>> bodies;
		std::vector<std::unique_ptr<btQuaternionHingeConstraint>> joints;
		const double sep = runChain(world.world(), bodies, joints, shape);
		std::printf("[ figures  ] %s: max separation %.3g m\n", names[k], sep);
		EXPECT_LT(sep, kMaxSeparation) << names[k];
	}
}

TEST(Solvers, ChainRunsInAMultiBodyWorldBetweenRigidBodies)
{
	// btMultiBodyDynamicsWorld with btMultiBodyConstraintSolver solves rigid-body constraints too.
	btDefaultCollisionConfiguration config;
	btCollisionDispatcher dispatcher(&config);
	btDbvtBroadphase broadphase;
	btMultiBodyConstraintSolver solver;
	btMultiBodyDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
	world.setGravity(btVector3(0, -10, 0));
	btBoxShape shape(btVector3(btScalar(0.25), btScalar(0.05), btScalar(0.05)));
	std::vector<std::unique_ptr<btRigidBody>> bodies;
	std::vector<std::unique_ptr<btQuaternionHingeConstraint>> joints;
	const double sep = runChain(world, bodies, joints, shape);
	std::printf("[ figures  ] multibody world: max separation %.3g m\n", sep);
	EXPECT_LT(sep, kMaxSeparation);
}
