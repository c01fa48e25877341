// The stabilizer tests' scene (StabilizerScene.h): building the world, bodies, hinges and chains; measuring them.
// Built when the QuatHinge::Stabilizer target is (tests/CMakeLists.txt defines QUATHINGE_HAVE_STABILIZER then).
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/StabilizerScene.h"

#include <algorithm>
#include <cmath>

namespace qh_test
{
StabilizerScene::StabilizerScene()
	: m_dispatcher(&m_config),
	  m_world(new btDiscreteDynamicsWorld(&m_dispatcher, &m_broadphase, &m_solver, &m_config))
{
	m_world->setGravity(btVector3(0, -10, 0));
}

StabilizerScene::~StabilizerScene()
{
	for (btActionInterface* a : m_actions) m_world->removeAction(a);
	for (auto& c : m_constraints) m_world->removeConstraint(c.get());
	for (auto& b : m_bodies) m_world->removeRigidBody(b.get());
}

void StabilizerScene::addAction(btActionInterface* action)
{
	m_world->addAction(action);
	m_actions.push_back(action);
}

btRigidBody* StabilizerScene::box(const btVector3& halfExtents, btScalar mass, const btVector3& position,
								  const btQuaternion& rotation)
{
	m_shapes.emplace_back(new btBoxShape(halfExtents));
	btVector3 inertia(0, 0, 0);
	if (mass > 0) m_shapes.back()->calculateLocalInertia(mass, inertia);
	m_motionStates.emplace_back(new btDefaultMotionState(btTransform(rotation, position)));
	btRigidBody::btRigidBodyConstructionInfo info(mass, m_motionStates.back().get(), m_shapes.back().get(), inertia);
	m_bodies.emplace_back(new btRigidBody(info));
	btRigidBody* body = m_bodies.back().get();
	if (mass > 0) body->setActivationState(DISABLE_DEACTIVATION);
	m_world->addRigidBody(body);
	return body;
}

btQuaternionHingeConstraint* StabilizerScene::hinge(btRigidBody& a, btRigidBody& b, const btVector3& pivotInA,
													const btVector3& pivotInB, const btVector3& axisInA,
													const btVector3& axisInB)
{
	auto* c = new btQuaternionHingeConstraint(a, b, pivotInA, pivotInB, axisInA, axisInB);
	m_constraints.emplace_back(c);
	m_hinges.push_back(c);
	m_world->addConstraint(c, true);
	return c;
}

btQuaternionHingeConstraint* StabilizerScene::hingeToWorld(btRigidBody& a, const btVector3& pivotInA,
														   const btVector3& axisInA)
{
	auto* c = new btQuaternionHingeConstraint(a, pivotInA, axisInA);
	m_constraints.emplace_back(c);
	m_hinges.push_back(c);
	m_world->addConstraint(c, true);
	return c;
}

void StabilizerScene::addConstraint(btTypedConstraint* c)
{
	m_constraints.emplace_back(c);
	m_world->addConstraint(c, true);
}

std::vector<btRigidBody*> StabilizerScene::chain(int n, btScalar lastMass, btScalar height)
{
	const btScalar length = btScalar(0.5);
	std::vector<btRigidBody*> links;
	for (int i = 0; i < n; ++i)
	{
		const btScalar mass = i == n - 1 ? lastMass : btScalar(1);
		btRigidBody* link =
			box(btVector3(length / 2, btScalar(0.05), btScalar(0.05)), mass,
				btVector3(length * (btScalar(i) + btScalar(0.5)), height, 0));
		const btVector3 axis = i % 2 == 0 ? btVector3(0, 0, 1) : btVector3(0, 1, 0);
		if (i == 0) hingeToWorld(*link, btVector3(-length / 2, 0, 0), axis);
		else hinge(*links.back(), *link, btVector3(length / 2, 0, 0), btVector3(-length / 2, 0, 0), axis, axis);
		links.push_back(link);
	}
	return links;
}

void StabilizerScene::jointErrors(double& separation, double& misalignmentDeg) const
{
	separation = 0;
	misalignmentDeg = 0;
	for (const btQuaternionHingeConstraint* h : m_hinges)
	{
		if (!h->isEnabled()) continue;
		const btTransform a = h->getRigidBodyA().getCenterOfMassTransform() * h->getAFrame();
		const btTransform b = h->getRigidBodyB().getCenterOfMassTransform() * h->getBFrame();
		separation = std::max(separation, double((b.getOrigin() - a.getOrigin()).length()));
		const btVector3 za = a.getBasis().getColumn(2), zb = b.getBasis().getColumn(2);
		misalignmentDeg =
			std::max(misalignmentDeg, double(btAtan2(za.cross(zb).length(), za.dot(zb))) * kRadToDeg);
	}
}

bool StabilizerScene::allFinite() const
{
	for (const auto& b : m_bodies)
	{
		const btTransform& t = b->getCenterOfMassTransform();
		const btVector3& v = b->getLinearVelocity();
		for (int k = 0; k < 3; ++k)
			if (!std::isfinite(t.getOrigin()[k]) || !std::isfinite(v[k]) || !std::isfinite(t.getBasis()[k][0]))
				return false;
	}
	return true;
}

void runAndMeasure(StabilizerScene& scene, int steps, double& separation, double& misalignmentDeg,
				   const btQuaternionHingeStabilizer* stabilizer, StabilizerWork* work)
{
	separation = 0;
	misalignmentDeg = 0;
	double newton = 0, factorizations = 0;
	for (int i = 0; i < steps; ++i)
	{
		scene.world().stepSimulation(kTimeStep, 0);
		if (stabilizer)
		{
			newton += stabilizer->getLastStats().iterations;
			factorizations += stabilizer->getLastStats().factorizations;
		}
		double s, m;
		scene.jointErrors(s, m);
		separation = std::max(separation, s);
		misalignmentDeg = std::max(misalignmentDeg, m);
	}
	if (work)
	{
		work->newtonPerStep = newton / steps;
		work->factorizationsPerStep = factorizations / steps;
	}
}

bool sameTransform(const btTransform& a, const btTransform& b)
{
	for (int i = 0; i < 3; ++i)
		if (a.getOrigin()[i] != b.getOrigin()[i] || a.getBasis()[i] != b.getBasis()[i]) return false;
	return true;
}

std::vector<btTransform> StabilizerScene::poses() const
{
	std::vector<btTransform> out;
	for (int i = 0; i < m_world->getNumCollisionObjects(); ++i)
		out.push_back(m_world->getCollisionObjectArray()[i]->getWorldTransform());
	return out;
}

void StabilizerScene::setPoses(const std::vector<btTransform>& poses)
{
	for (int i = 0; i < m_world->getNumCollisionObjects(); ++i)
		m_world->getCollisionObjectArray()[i]->setWorldTransform(poses[size_t(i)]);
}

}  // namespace qh_test
#endif  // QUATHINGE_HAVE_STABILIZER
