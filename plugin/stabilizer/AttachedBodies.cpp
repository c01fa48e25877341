// Carrying the attached bodies with their hosts (AttachedBodies.h).
#include "AttachedBodies.h"
#include "PointRows.h"

#include "BulletDynamics/ConstraintSolver/btGeneric6DofSpring2Constraint.h"
#include "BulletDynamics/ConstraintSolver/btTypedConstraint.h"
#include "BulletDynamics/Dynamics/btRigidBody.h"

#include <cmath>

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

/// Sets the body's pose and velocities (and what Bullet's integration reads of them).
void setState(btRigidBody& body, const btTransform& t, const btVector3& v, const btVector3& w)
{
	body.setWorldTransform(t);
	body.setInterpolationWorldTransform(t);
	body.updateInertiaTensor();
	body.setLinearVelocity(v);
	body.setAngularVelocity(w);
	body.setInterpolationLinearVelocity(v);
	body.setInterpolationAngularVelocity(w);
}

/// The velocity of the body's material point at world point p (Bullet's getVelocityInLocalPoint takes p's arm).
btVector3 pointVelocity(const btRigidBody& body, const btVector3& p)
{
	return body.getVelocityInLocalPoint(p - body.getCenterOfMassPosition());
}

/// The forms closeAttachedConstraints knows (AttachedBodies.h).
enum class Form
{
	None,
	Point,  // pivots meet at `offset`: p_B − p_A = R_FA · offset (offset 0 but for a 6-dof's locked linear values)
	Slider  // frames' bases equal; the offset along each locked linear axis its locked value
};

struct Closable
{
	Form form = Form::None;
	btTransform frameA, frameB;  // in A's and B's centre-of-mass frames (a point: origins only)
	btVector3 offset{0, 0, 0};   // locked linear values in frame A (a 6-dof)
	bool locked[3] = {false, false, false};
};

Closable closableForm(const btTypedConstraint& c)
{
	Closable k;
	k.frameA.setIdentity();
	k.frameB.setIdentity();
	// a 6-dof first: its point form keeps its locked offset here (hasPointRows takes it as a point too)
	const DofLocks dof = dofLocks(c);
	if (dof.isDof)
	{
		k.frameA = dof.frameA;
		k.frameB = dof.frameB;
		k.offset = dof.offset;
		for (int i = 0; i < 3; ++i) k.locked[i] = dof.linear[i];
		if (dof.anglesLockedAtZero) k.form = Form::Slider;
		else if (dof.allLinear) k.form = Form::Point;
		return k;
	}
	if (hasPointRows(c, dof))
	{
		btVector3 inA, inB;
		pointPivots(c, inA, inB);
		k.frameA.setOrigin(inA);
		k.frameB.setOrigin(inB);
		k.form = Form::Point;
	}
	return k;
}

/// Puts `body` on constraint `k` to `host`, the host held fixed (AttachedBodies.h); false if it has no known form.
bool close(btRigidBody& body, const btRigidBody& host, const Closable& k, bool bodyIsA)
{
	if (k.form == Form::None) return false;
	// Bullet's linear and angular factors would change what an impulse does; such a body is left as it is
	if (body.getLinearFactor() != btVector3(1, 1, 1) || body.getAngularFactor() != btVector3(1, 1, 1)) return false;
	const btTransform& hostT = host.getCenterOfMassTransform();
	btTransform t = body.getCenterOfMassTransform();
	btVector3 v = body.getLinearVelocity(), w = body.getAngularVelocity();
	// the host's frame and the body's frame of the constraint, world
	const btTransform& hostFrame = bodyIsA ? k.frameB : k.frameA;
	const btTransform& bodyFrame = bodyIsA ? k.frameA : k.frameB;
	const btTransform hostWorld = hostT * hostFrame;
	if (k.form == Form::Slider)
	{
		// turned to the host's frame, then moved along the locked axes of frame A (the host's, or its own once turned)
		t.setBasis(hostWorld.getBasis() * bodyFrame.getBasis().transpose());
		const btMatrix3x3& axes = hostWorld.getBasis();  // frame A's axes, equal to frame B's now
		const btVector3 pivot = t * bodyFrame.getOrigin();
		// d = R_FAᵀ (p_B − p_A), in frame A; the body's pivot is p_B when it is B, p_A when it is A
		const btVector3 d = axes.transpose() * (bodyIsA ? hostWorld.getOrigin() - pivot : pivot - hostWorld.getOrigin());
		btVector3 target = d;
		for (int i = 0; i < 3; ++i)
			if (k.locked[i]) target[i] = k.offset[i];
		const btVector3 move = axes * (target - d);
		t.setOrigin(t.getOrigin() + (bodyIsA ? -move : move));
		w = host.getAngularVelocity();
		const btVector3 at = t * bodyFrame.getOrigin();
		const btVector3 relative = (v + w.cross(at - t.getOrigin())) - pointVelocity(host, at);
		for (int i = 0; i < 3; ++i)
			if (k.locked[i])
			{
				const btVector3 axis = axes.getColumn(i);
				v -= axis * axis.dot(relative);
			}
	}
	else
	{
		// moved along so the pivots meet at the offset (R_FA: the host's frame when it is A, else the body's)
		const btVector3 pivot = t * bodyFrame.getOrigin();
		const btMatrix3x3 axesA = bodyIsA ? t.getBasis() * bodyFrame.getBasis() : hostWorld.getBasis();
		const btVector3 offset = axesA * k.offset;  // p_B − p_A wanted
		const btVector3 wanted = bodyIsA ? hostWorld.getOrigin() - offset : hostWorld.getOrigin() + offset;
		t.setOrigin(t.getOrigin() + (wanted - pivot));
		// the impulse P at the pivot that takes out its relative velocity: (m⁻¹ I − [r]× I⁻¹ [r]×) P = −v_rel
		const btVector3 r = wanted - t.getOrigin();
		const btVector3 relative = (v + w.cross(r)) - pointVelocity(host, wanted);
		const btMatrix3x3 cross(0, -r.z(), r.y(), r.z(), 0, -r.x(), -r.y(), r.x(), 0);
		const btMatrix3x3& inverseInertia = body.getInvInertiaTensorWorld();  // the turn is a translation: unchanged
		btMatrix3x3 effective = cross * inverseInertia * cross;
		for (int i = 0; i < 3; ++i)
			for (int j = 0; j < 3; ++j) effective[i][j] = (i == j ? body.getInvMass() : btScalar(0)) - effective[i][j];
		if (effective.determinant() <= btScalar(0)) return false;
		const btVector3 impulse = effective.inverse() * -relative;
		v += impulse * body.getInvMass();
		w += inverseInertia * r.cross(impulse);
	}
	// a body near float's end (or with an inverse mass that is not finite) must not be handed a non-finite state
	btScalar sum = t.getOrigin().length2() + v.length2() + w.length2();
	for (int i = 0; i < 3; ++i) sum += t.getBasis()[i].length2();
	if (!std::isfinite(sum)) return false;
	setState(body, t, v, w);
	return true;
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
		int enabled = 0;
		for (int m = 0; m < body->getNumConstraintRefs() && onlyToHost; ++m)
		{
			const btTypedConstraint* other = body->getConstraintRef(m);
			onlyToHost = !other->isEnabled() || otherBody(*other, *body) == &host;
			enabled += other->isEnabled() ? 1 : 0;
		}
		if (!onlyToHost) continue;
		bool known = false;  // two constraints to the same host: carried once
		for (const AttachedBody& a : out) known = known || a.body == body;
		if (!known)
			out.push_back({&host, body, host.getCenterOfMassTransform(), host.getLinearVelocity(), host.getAngularVelocity(),
						   enabled == 1 ? c : nullptr});
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
		setState(body, t, v, w);
		++moved;
	}
	return moved;
}

int closeAttachedConstraints(const Array<AttachedBody>& attached)
{
	int closed = 0;
	for (const AttachedBody& a : attached)
	{
		if (!a.only) continue;
		const bool bodyIsA = &const_cast<btTypedConstraint*>(a.only)->getRigidBodyA() == a.body;
		if (close(*a.body, *a.host, closableForm(*a.only), bodyIsA)) ++closed;
	}
	return closed;
}

}  // namespace stabilizer
}  // namespace quathinge
