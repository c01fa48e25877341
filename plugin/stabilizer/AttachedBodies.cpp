// Carrying the attached bodies with their hosts (AttachedBodies.h).
#include "AttachedBodies.h"

#include "BulletDynamics/ConstraintSolver/btTypedConstraint.h"
#include "BulletDynamics/Dynamics/btRigidBody.h"

namespace quathinge
{
namespace stabilizer
{
namespace
{
btRigidBody* otherBody(const btTypedConstraint& c, const btRigidBody& body)
{
	btRigidBody& a = const_cast<btTypedConstraint&>(c).getRigidBodyA();
	btRigidBody& b = const_cast<btTypedConstraint&>(c).getRigidBodyB();
	return &a == &body ? &b : &a;
}
}  // namespace

void findAttachedBodies(btRigidBody& host, const IslandBodyMap& islandBodies, Array<AttachedBody>& out)
{
	for (int k = 0; k < host.getNumConstraintRefs(); ++k)
	{
		const btTypedConstraint* c = host.getConstraintRef(k);
		if (!c->isEnabled()) continue;
		btRigidBody* body = otherBody(*c, host);
		if (body == &host || islandBodies.count(body) || body->getInvMass() == 0 || !body->isActive()) continue;
		bool onlyToHost = true;
		for (int m = 0; m < body->getNumConstraintRefs() && onlyToHost; ++m)
		{
			const btTypedConstraint* other = body->getConstraintRef(m);
			onlyToHost = !other->isEnabled() || otherBody(*other, *body) == &host;
		}
		if (!onlyToHost) continue;
		bool known = false;  // two constraints to the same host: carried once
		for (const AttachedBody& a : out) known = known || a.body == body;
		if (!known)
			out.push_back({&host, body, host.getCenterOfMassTransform(), host.getLinearVelocity(), host.getAngularVelocity()});
	}
}

int carryAttachedBodies(const Array<AttachedBody>& attached)
{
	int moved = 0;
	for (const AttachedBody& a : attached)
	{
		const btTransform& hostAfter = a.host->getCenterOfMassTransform();
		const btVector3 hostV = a.host->getLinearVelocity(), hostW = a.host->getAngularVelocity();
		if (hostAfter == a.hostBefore && hostV == a.hostLinearVelocity && hostW == a.hostAngularVelocity) continue;
		btRigidBody& body = *a.body;
		// the body's pose and velocity relative to its host, kept: T' = H' H⁻¹ T, and the velocity the host's rigid
		// motion gives the body's centre plus its own relative part turned with the host (R = H' H⁻¹'s rotation)
		const btTransform delta = hostAfter * a.hostBefore.inverse();
		const btMatrix3x3& turn = delta.getBasis();
		const btVector3 x = body.getCenterOfMassPosition();
		const btVector3 relW = body.getAngularVelocity() - a.hostAngularVelocity;
		const btVector3 relV =
			body.getLinearVelocity() - (a.hostLinearVelocity + a.hostAngularVelocity.cross(x - a.hostBefore.getOrigin()));
		const btTransform t = delta * body.getCenterOfMassTransform();
		const btVector3 w = hostW + turn * relW;
		const btVector3 v = hostV + hostW.cross(t.getOrigin() - hostAfter.getOrigin()) + turn * relV;
		body.setWorldTransform(t);
		body.setInterpolationWorldTransform(t);
		body.updateInertiaTensor();
		body.setLinearVelocity(v);
		body.setAngularVelocity(w);
		body.setInterpolationLinearVelocity(v);
		body.setInterpolationAngularVelocity(w);
		++moved;
	}
	return moved;
}

}  // namespace stabilizer
}  // namespace quathinge
