#include "support/World.h"

#include "BulletDynamics/ConstraintSolver/btNNCGConstraintSolver.h"
#include "BulletDynamics/MLCPSolvers/btDantzigSolver.h"
#include "BulletDynamics/MLCPSolvers/btMLCPSolver.h"

#include <cmath>

namespace qh_test
{
struct World::Extra
{
	btDantzigSolver dantzig;
};

World::World(SolverKind solver, const btVector3& gravity)
	: m_config(new btDefaultCollisionConfiguration),
	  m_dispatcher(new btCollisionDispatcher(m_config.get())),
	  m_broadphase(new btDbvtBroadphase),
	  m_extra(new Extra)
{
	switch (solver)
	{
		case SolverKind::SequentialImpulse:
			m_solver.reset(new btSequentialImpulseConstraintSolver);
			break;
		case SolverKind::NNCG:
			m_solver.reset(new btNNCGConstraintSolver);
			break;
		case SolverKind::MLCPDantzig:
			m_solver.reset(new btMLCPSolver(&m_extra->dantzig));
			break;
	}
	m_world.reset(new btDiscreteDynamicsWorld(m_dispatcher.get(), m_broadphase.get(), m_solver.get(), m_config.get()));
	m_world->setGravity(gravity);
}

World::World(std::unique_ptr<btConstraintSolver> solver, const btVector3& gravity)
	: m_config(new btDefaultCollisionConfiguration),
	  m_dispatcher(new btCollisionDispatcher(m_config.get())),
	  m_broadphase(new btDbvtBroadphase),
	  m_solver(std::move(solver)),
	  m_extra(new Extra)
{
	m_world.reset(new btDiscreteDynamicsWorld(m_dispatcher.get(), m_broadphase.get(), m_solver.get(), m_config.get()));
	m_world->setGravity(gravity);
}

World::~World()
{
	for (auto& c : m_constraints) m_world->removeConstraint(c.get());
	for (auto& b : m_bodies) m_world->removeRigidBody(b.get());
}

btRigidBody* World::addBox(btScalar mass, const btVector3& halfExtents, const btTransform& pose)
{
	m_shapes.emplace_back(new btBoxShape(halfExtents));
	btVector3 inertia(0, 0, 0);
	if (mass > 0) m_shapes.back()->calculateLocalInertia(mass, inertia);
	btRigidBody::btRigidBodyConstructionInfo info(mass, nullptr, m_shapes.back().get(), inertia);
	info.m_startWorldTransform = pose;
	m_bodies.emplace_back(new btRigidBody(info));
	m_bodies.back()->setActivationState(DISABLE_DEACTIVATION);
	m_world->addRigidBody(m_bodies.back().get());
	return m_bodies.back().get();
}

void World::step(int steps, btScalar dt, int iterations)
{
	m_world->getSolverInfo().m_numIterations = iterations;
	for (int i = 0; i < steps; ++i) m_world->stepSimulation(dt, 0, dt);
}

double separation(const btRigidBody& a, const btTransform& frameA, const btRigidBody& b, const btTransform& frameB)
{
	return ((b.getCenterOfMassTransform() * frameB.getOrigin()) - (a.getCenterOfMassTransform() * frameA.getOrigin()))
		.length();
}

double misalignmentDeg(const btRigidBody& a, const btTransform& frameA, const btRigidBody& b,
					   const btTransform& frameB)
{
	const btVector3 za = a.getCenterOfMassTransform().getBasis() * frameA.getBasis().getColumn(2);
	const btVector3 zb = b.getCenterOfMassTransform().getBasis() * frameB.getBasis().getColumn(2);
	// atan2(|za × zb|, za·zb): accurate for small angles too (acos of a dot product near 1 is not)
	return std::atan2(double(za.cross(zb).length()), double(za.dot(zb))) * kDeg;
}

btQuaternion expRotation(const btVector3& w)
{
	const btScalar angle = w.length();
	if (angle == 0) return btQuaternion::getIdentity();
	return btQuaternion(w / angle, angle);
}

bool finiteState(const btRigidBody& body)
{
	const btTransform& t = body.getCenterOfMassTransform();
	const btVector3 sum = t.getOrigin() + t.getBasis()[0] + t.getBasis()[1] + t.getBasis()[2] +
						  body.getLinearVelocity() + body.getAngularVelocity();
	return std::isfinite(double(sum.x())) && std::isfinite(double(sum.y())) && std::isfinite(double(sum.z()));
}

int constraintRefs(btRigidBody& body, const btTypedConstraint* constraint)
{
	int refs = 0;
	for (int i = 0; i < body.getNumConstraintRefs(); ++i) refs += body.getConstraintRef(i) == constraint;
	return refs;
}

void placeOnHinge(btRigidBody& a, const btTransform& frameA, btRigidBody& b, const btTransform& frameB, btScalar theta)
{
	const btTransform turn(btQuaternion(btVector3(0, 0, 1), theta));
	if (b.getInvMass() == 0 && a.getInvMass() != 0)
		a.setCenterOfMassTransform(b.getCenterOfMassTransform() * frameB * turn.inverse() * frameA.inverse());
	else
		b.setCenterOfMassTransform(a.getCenterOfMassTransform() * frameA * turn * frameB.inverse());
}

}  // namespace qh_test
