// Bullet's RagdollDemo ragdolls on the ground (RagdollDemo.h).
#include "RagdollDemo.h"

#include <algorithm>
#include <cmath>

namespace qh_test
{
namespace
{
btTransform pose(btScalar yaw, btScalar pitch, btScalar roll, const btVector3& origin)
{
	btTransform t;
	t.setIdentity();
	t.getBasis().setEulerZYX(yaw, pitch, roll);
	t.setOrigin(origin);
	return t;
}
}  // namespace

RagdollDemoWorld::RagdollDemoWorld(RagdollGround ground)
	: m_dispatcher(&m_config), m_world(new btDiscreteDynamicsWorld(&m_dispatcher, &m_broadphase, &m_solver, &m_config))
{
	m_world->setGravity(btVector3(0, -10, 0));
	btCollisionShape* shape = new btBoxShape(btVector3(200, 10, 200));
	const btTransform at = pose(0, 0, 0, btVector3(0, -10, 0));
	if (ground == RagdollGround::StaticBody) m_ground = body(0, shape, at);
	else
	{
		m_shapes.emplace_back(shape);
		m_groundObject.reset(new btCollisionObject());
		m_groundObject->setCollisionShape(shape);
		m_groundObject->setWorldTransform(at);
		m_world->addCollisionObject(m_groundObject.get());
		m_ground = m_groundObject.get();
	}
}

RagdollDemoWorld::~RagdollDemoWorld()
{
	for (int i = m_world->getNumConstraints() - 1; i >= 0; --i) m_world->removeConstraint(m_world->getConstraint(i));
	for (int i = m_world->getNumCollisionObjects() - 1; i >= 0; --i)
		m_world->removeCollisionObject(m_world->getCollisionObjectArray()[i]);
}

btRigidBody* RagdollDemoWorld::body(btScalar mass, btCollisionShape* shape, const btTransform& at)
{
	m_shapes.emplace_back(shape);
	btVector3 inertia(0, 0, 0);
	if (mass > 0) shape->calculateLocalInertia(mass, inertia);
	btRigidBody::btRigidBodyConstructionInfo info(mass, nullptr, shape, inertia);
	info.m_startWorldTransform = at;
	m_bodies.emplace_back(new btRigidBody(info));
	m_world->addRigidBody(m_bodies.back().get());
	return m_bodies.back().get();
}

void RagdollDemoWorld::addRagdoll(const btVector3& offset, btScalar yaw, btScalar spin)
{
	const btScalar halfPi = SIMD_HALF_PI, quarterPi = SIMD_PI / 4;
	const btTransform place = pose(0, yaw, 0, offset);  // setEulerZYX(z, y, x): yaw about y
	// the parts: capsule radius and height (m), centre (the ragdoll standing, feet at y = 0), roll about z
	struct Part
	{
		btScalar radius, height;
		btVector3 centre;
		btScalar roll;
	};
	const Part parts[11] = {
		{btScalar(0.15), btScalar(0.20), btVector3(0, 1, 0), 0},                                  // pelvis
		{btScalar(0.15), btScalar(0.28), btVector3(0, btScalar(1.2), 0), 0},                      // spine
		{btScalar(0.10), btScalar(0.05), btVector3(0, btScalar(1.6), 0), 0},                      // head
		{btScalar(0.07), btScalar(0.45), btVector3(btScalar(-0.18), btScalar(0.65), 0), 0},       // left thigh
		{btScalar(0.05), btScalar(0.37), btVector3(btScalar(-0.18), btScalar(0.2), 0), 0},        // left shin
		{btScalar(0.07), btScalar(0.45), btVector3(btScalar(0.18), btScalar(0.65), 0), 0},        // right thigh
		{btScalar(0.05), btScalar(0.37), btVector3(btScalar(0.18), btScalar(0.2), 0), 0},         // right shin
		{btScalar(0.05), btScalar(0.33), btVector3(btScalar(-0.35), btScalar(1.45), 0), halfPi},  // left upper arm
		{btScalar(0.04), btScalar(0.25), btVector3(btScalar(-0.7), btScalar(1.45), 0), halfPi},   // left forearm
		{btScalar(0.05), btScalar(0.33), btVector3(btScalar(0.35), btScalar(1.45), 0), -halfPi},  // right upper arm
		{btScalar(0.04), btScalar(0.25), btVector3(btScalar(0.7), btScalar(1.45), 0), -halfPi},   // right forearm
	};
	btRigidBody* b[11];
	for (int i = 0; i < 11; ++i)
	{
		b[i] = body(1, new btCapsuleShape(parts[i].radius, parts[i].height),
					place * pose(0, 0, parts[i].roll, parts[i].centre));
		b[i]->setDamping(btScalar(0.05), btScalar(0.85));
		b[i]->setDeactivationTime(btScalar(0.8));
		b[i]->setSleepingThresholds(btScalar(1.6), btScalar(2.5));
	}
	b[0]->setAngularVelocity(place.getBasis() * btVector3(0, 0, spin));
	auto hinge = [&](int a, int c, const btTransform& fa, const btTransform& fb, btScalar low, btScalar high) {
		auto* h = new btHingeConstraint(*b[a], *b[c], fa, fb);
		h->setLimit(low, high);
		m_constraints.emplace_back(h);
		m_world->addConstraint(h, true);
	};
	auto cone = [&](int a, int c, const btTransform& fa, const btTransform& fb, btScalar swing1, btScalar swing2, btScalar twist) {
		auto* k = new btConeTwistConstraint(*b[a], *b[c], fa, fb);
		k->setLimit(swing1, swing2, twist);
		m_constraints.emplace_back(k);
		m_world->addConstraint(k, true);
	};
	const btScalar y15 = btScalar(0.15), y225 = btScalar(0.225), y185 = btScalar(0.185), y18 = btScalar(0.18);
	hinge(0, 1, pose(0, halfPi, 0, btVector3(0, y15, 0)), pose(0, halfPi, 0, btVector3(0, -y15, 0)), -quarterPi, halfPi);
	cone(1, 2, pose(0, 0, halfPi, btVector3(0, btScalar(0.30), 0)), pose(0, 0, halfPi, btVector3(0, btScalar(-0.14), 0)),
		 quarterPi, quarterPi, halfPi);
	cone(0, 3, pose(0, 0, -5 * quarterPi, btVector3(-y18, btScalar(-0.10), 0)), pose(0, 0, -5 * quarterPi, btVector3(0, y225, 0)),
		 quarterPi, quarterPi, 0);
	hinge(3, 4, pose(0, halfPi, 0, btVector3(0, -y225, 0)), pose(0, halfPi, 0, btVector3(0, y185, 0)), 0, halfPi);
	cone(0, 5, pose(0, 0, quarterPi, btVector3(y18, btScalar(-0.10), 0)), pose(0, 0, quarterPi, btVector3(0, y225, 0)),
		 quarterPi, quarterPi, 0);
	hinge(5, 6, pose(0, halfPi, 0, btVector3(0, -y225, 0)), pose(0, halfPi, 0, btVector3(0, y185, 0)), 0, halfPi);
	cone(1, 7, pose(0, 0, SIMD_PI, btVector3(btScalar(-0.2), y15, 0)), pose(0, 0, halfPi, btVector3(0, -y18, 0)), halfPi,
		 halfPi, 0);
	hinge(7, 8, pose(0, halfPi, 0, btVector3(0, y18, 0)), pose(0, halfPi, 0, btVector3(0, btScalar(-0.14), 0)), 0, halfPi);
	cone(1, 9, pose(0, 0, 0, btVector3(btScalar(0.2), y15, 0)), pose(0, 0, halfPi, btVector3(0, -y18, 0)), halfPi, halfPi, 0);
	hinge(9, 10, pose(0, halfPi, 0, btVector3(0, y18, 0)), pose(0, halfPi, 0, btVector3(0, btScalar(-0.14), 0)), 0, halfPi);
}

void RagdollDemoWorld::jointSeparations(double& hinge, double& cone) const
{
	hinge = cone = 0;
	for (int i = 0; i < m_world->getNumConstraints(); ++i)
	{
		const btTypedConstraint* c = m_world->getConstraint(i);
		btTransform a, b;
		if (c->getConstraintType() == CONETWIST_CONSTRAINT_TYPE)
		{
			a = static_cast<const btConeTwistConstraint*>(c)->getAFrame();
			b = static_cast<const btConeTwistConstraint*>(c)->getBFrame();
		}
		else if (c->getConstraintType() == HINGE_CONSTRAINT_TYPE)
		{
			a = static_cast<const btHingeConstraint*>(c)->getAFrame();
			b = static_cast<const btHingeConstraint*>(c)->getBFrame();
		}
		else
			continue;
		const double d = ((c->getRigidBodyA().getCenterOfMassTransform() * a.getOrigin()) -
						  (c->getRigidBodyB().getCenterOfMassTransform() * b.getOrigin()))
							 .length();
		(c->getConstraintType() == CONETWIST_CONSTRAINT_TYPE ? cone : hinge) = std::max(
			c->getConstraintType() == CONETWIST_CONSTRAINT_TYPE ? cone : hinge, d);
	}
}

void RagdollDemoWorld::limitsPast(double& hinge, double& cone) const
{
	hinge = cone = 0;
	for (int i = 0; i < m_world->getNumConstraints(); ++i)
	{
		btTypedConstraint* c = m_world->getConstraint(i);
		const btTransform& tA = c->getRigidBodyA().getCenterOfMassTransform();
		const btTransform& tB = c->getRigidBodyB().getCenterOfMassTransform();
		if (c->getConstraintType() == HINGE_CONSTRAINT_TYPE)
		{
			btHingeConstraint& h = *static_cast<btHingeConstraint*>(c);
			const double angle = double(h.getHingeAngle(tA, tB));
			hinge = std::max(hinge, std::max(double(h.getLowerLimit()) - angle, angle - double(h.getUpperLimit())));
		}
		else if (c->getConstraintType() == CONETWIST_CONSTRAINT_TYPE)
		{
			btConeTwistConstraint& k = *static_cast<btConeTwistConstraint*>(c);
			const btVector3 xA = (tA.getBasis() * k.getAFrame().getBasis()).getColumn(0);
			const btVector3 xB = (tB.getBasis() * k.getBFrame().getBasis()).getColumn(0);
			const double swing = std::atan2(double(xA.cross(xB).length()), double(xA.dot(xB)));
			cone = std::max(cone, swing - double(k.getSwingSpan1()));
			k.calcAngleInfo2(tA, tB, c->getRigidBodyA().getInvInertiaTensorWorld(), c->getRigidBodyB().getInvInertiaTensorWorld());
			cone = std::max(cone, double(k.getTwistAngle() - k.getTwistSpan()));
		}
	}
}

double RagdollDemoWorld::groundPenetration(std::vector<const btCollisionObject*>* touching) const
{
	double deepest = 0;
	if (touching) touching->clear();
	btDispatcher& d = *m_world->getDispatcher();
	for (int m = 0; m < d.getNumManifolds(); ++m)
	{
		const btPersistentManifold* manifold = d.getManifoldByIndexInternal(m);
		const bool groundIsB = manifold->getBody1() == m_ground;
		if (!groundIsB && manifold->getBody0() != m_ground) continue;
		const btCollisionObject* part = groundIsB ? manifold->getBody0() : manifold->getBody1();
		if (touching && manifold->getNumContacts() > 0) touching->push_back(part);
		for (int p = 0; p < manifold->getNumContacts(); ++p)
		{
			const btManifoldPoint& point = manifold->getContactPoint(p);
			const btVector3 onPart = part->getWorldTransform() * (groundIsB ? point.m_localPointA : point.m_localPointB);
			deepest = std::max(deepest, -double(onPart.y()));
		}
	}
	return deepest;
}

void RagdollDemoWorld::partPenetrations(std::vector<double>& depths, std::vector<const btCollisionObject*>* bodies) const
{
	depths.clear();
	if (bodies) bodies->clear();
	for (const auto& b : m_bodies)
	{
		// the ground as a static body; every part of RagdollDemo's ragdolls is a capsule
		if (b->isStaticObject() || b->getCollisionShape()->getShapeType() != CAPSULE_SHAPE_PROXYTYPE) continue;
		const btCapsuleShape& capsule = *static_cast<const btCapsuleShape*>(b->getCollisionShape());
		btVector3 axis(0, 0, 0);
		axis[capsule.getUpAxis()] = capsule.getHalfHeight();
		const btTransform& t = b->getCenterOfMassTransform();
		const double lowest = std::min(double((t * axis).y()), double((t * -axis).y()));
		depths.push_back(double(capsule.getRadius()) - lowest);
		if (bodies) bodies->push_back(b.get());
	}
}
}  // namespace qh_test
