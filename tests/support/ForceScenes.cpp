// The forces a Bullet app applies, on small chains (ForceScenes.h).
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/ForceScenes.h"

#include <algorithm>
#include <cmath>

namespace qh_test
{
double ForceRecord::mean(double t0, double t1) const
{
	const int a = std::max(0, int(std::lround(t0 * hz))), b = std::min(int(energy.size()), int(std::lround(t1 * hz)));
	double sum = 0;
	for (int i = a; i < b; ++i) sum += energy[size_t(i)];
	return b > a ? sum / (b - a) : 0;
}

double kineticEnergy(const btRigidBody& b)
{
	if (b.getInvMass() == 0) return 0;
	const btVector3 local = b.getCenterOfMassTransform().getBasis().transpose() * b.getAngularVelocity();
	const btVector3& inv = b.getInvInertiaDiagLocal();
	double e = 0.5 * double(b.getLinearVelocity().length2()) / double(b.getInvMass());
	for (int i = 0; i < 3; ++i) e += 0.5 * double(local[i]) * double(local[i]) / double(inv[i]);
	return e;
}

namespace
{
const double kLength = 0.5;  // m, each link
const double kPivotY = 10;   // m

// The free chain's angular momentum about its centre of mass and its linear momentum.
void momenta(const std::vector<btRigidBody*>& links, btVector3& angular, btVector3& linear)
{
	btScalar mass = 0;
	btVector3 centre(0, 0, 0);
	linear.setZero();
	for (const btRigidBody* b : links)
	{
		const btScalar m = 1 / b->getInvMass();
		mass += m;
		centre += m * b->getCenterOfMassPosition();
		linear += m * b->getLinearVelocity();
	}
	centre /= mass;
	angular.setZero();
	for (const btRigidBody* b : links)
	{
		const btScalar m = 1 / b->getInvMass();
		const btMatrix3x3& r = b->getCenterOfMassTransform().getBasis();
		const btVector3 local = r.transpose() * b->getAngularVelocity();
		const btVector3& inv = b->getInvInertiaDiagLocal();
		const btVector3 spin = r * btVector3(local.x() / inv.x(), local.y() / inv.y(), local.z() / inv.z());
		angular += (b->getCenterOfMassPosition() - centre).cross(m * b->getLinearVelocity()) + spin;
	}
}
}  // namespace

ForceRecord runForceChain(const ForceChain& chain, const ForceHooks& hooks, ForceKind kind, double hz, double seconds)
{
	StabilizerScene scene;
	scene.world().setGravity(btVector3(0, btScalar(chain.free ? 0 : -chain.gravity), 0));
	btRigidBody* anchor = nullptr;
	if (!chain.free)
	{
		anchor = scene.box(btVector3(btScalar(0.05), btScalar(0.05), btScalar(0.05)), 0, btVector3(0, btScalar(kPivotY), 0));
		if (chain.kinematic)
		{
			anchor->setCollisionFlags(anchor->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
			anchor->setActivationState(DISABLE_DEACTIVATION);
		}
	}
	std::vector<btRigidBody*> links;
	std::vector<btTypedConstraint*> joints;
	const btVector3 along = chain.hanging ? btVector3(0, -1, 0) : btVector3(1, 0, 0);
	const btVector3 half = chain.hanging ? btVector3(btScalar(0.05), btScalar(kLength / 2), btScalar(0.05))
										 : btVector3(btScalar(kLength / 2), btScalar(0.05), btScalar(0.05));
	const btVector3 second = chain.hanging ? btVector3(1, 0, 0) : btVector3(0, 1, 0);
	for (int i = 0; i < chain.links; ++i)
	{
		const btScalar mass = btScalar(i == chain.links - 1 ? chain.lastMass : 1);
		btRigidBody* link =
			scene.box(half, mass, btVector3(0, btScalar(kPivotY), 0) + along * btScalar(kLength * (i + 0.5)));
		link->setDamping(btScalar(chain.damping), btScalar(chain.damping));
		link->setSleepingThresholds(0, 0);
		if (!chain.gyroscopic) link->setFlags(link->getFlags() & ~BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY);
		const btVector3 axis = chain.planar || i % 2 == 0 ? btVector3(0, 0, 1) : second;
		const btVector3 pivotA = along * btScalar(kLength / 2), pivotB = -pivotA;
		btRigidBody* previous = i > 0 ? links.back() : anchor;
		if (previous)
		{
			const btVector3 pa = i > 0 ? pivotA : btVector3(0, 0, 0);
			btTypedConstraint* c;
			if (kind == ForceKind::Stock) c = new btHingeConstraint(*previous, *link, pa, pivotB, axis, axis);
			else c = scene.hinge(*previous, *link, pa, pivotB, axis, axis);
			if (kind == ForceKind::Stock) scene.addConstraint(c);
			joints.push_back(c);
		}
		links.push_back(link);
	}
	btQuaternionHingeStabilizer stabilizer;
	const bool stabilized = kind == ForceKind::Stabilized || kind == ForceKind::StabilizedInvalidated;
	if (stabilized) scene.addAction(&stabilizer);
	if (hooks.start) hooks.start(links);

	// no contacts: the links pass through each other and the anchor (the scenes measure the joints' energy alone)
	for (int i = 0; i < scene.world().getNumCollisionObjects(); ++i)
		scene.world().getCollisionObjectArray()[i]->getBroadphaseHandle()->m_collisionFilterMask = 0;
	// the potential's zero: each link's lowest reach (the chain hanging at rest has energy 0)
	auto energy = [&] {
		const double g = -double(scene.world().getGravity().y());
		double e = hooks.extraEnergy ? hooks.extraEnergy(links) : 0;
		for (size_t i = 0; i < links.size(); ++i)
		{
			const btRigidBody& b = *links[i];
			const double lowest = kPivotY - kLength * (double(i) + 0.5);
			e += kineticEnergy(b) + g / double(b.getInvMass()) * (double(b.getCenterOfMassPosition().y()) - lowest);
		}
		return e;
	};
	ForceRecord r;
	r.hz = hz;
	btVector3 angular0, linear0;
	if (chain.free) momenta(links, angular0, linear0);
	const double h = 1 / hz;
	const int steps = int(std::lround(seconds * hz));
	for (int step = 0; step < steps; ++step)
	{
		if (hooks.before) hooks.before(scene, links, anchor, joints, step * h, h);
		if (kind == ForceKind::StabilizedInvalidated) stabilizer.invalidateStructure();
		scene.world().stepSimulation(btScalar(h), 0, btScalar(h));
		r.energy.push_back(energy());
		if (stabilized && r.guardTrip < 0 && stabilizer.getLastStats().energyGuardedIslands > 0)
			r.guardTrip = (step + 1) * h;
		if (kind != ForceKind::Stock)
		{
			double separation, misalignment;
			scene.jointErrors(separation, misalignment);
			r.maxSeparation = std::max(r.maxSeparation, separation);
		}
		if (chain.free)
		{
			btVector3 angular, linear;
			momenta(links, angular, linear);
			r.angularDrift = std::max(r.angularDrift, double((angular - angular0).length() / angular0.length()));
			r.linearMomentum = std::max(r.linearMomentum, double((linear - linear0).length()));
		}
	}
	r.finite = scene.allFinite();
	return r;
}
}  // namespace qh_test
#endif
