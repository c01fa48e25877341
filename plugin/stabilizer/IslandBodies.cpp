// The island's bodies: M⁻¹ in the projection's metric, and their poses and velocities (IslandBodies.h).
#include "IslandBodies.h"

#include "BulletDynamics/Dynamics/btRigidBody.h"

#include <algorithm>

namespace quathinge
{
namespace stabilizer
{
// M⁻¹ of a body in double: m⁻¹ times the linear factor, and S R diag(I_local⁻¹) Rᵀ S (S the angular factor, R the
// body's basis) formed here rather than taken from getInvInertiaTensorWorld: that float product is not exactly
// symmetric, and its 1e-7 asymmetry makes a redundant K (closed loops) indefinite far above the regularization.
// The position correction's metric has every inertia multiplied by the rotation weight w (island.rotationWeight;
// 1 in the velocity stage): I⁻¹ → I⁻¹/w. With the island's stiff metric on (see projectIsland), it uses
// (M + M_ref)⁻¹ as well: every body made as heavy as the island's heaviest (m_ref, I_ref), so a correction no longer
// prefers swinging light bodies a long way (m⁻¹ → m⁻¹/(1 + m⁻¹ m_ref), the same per inertia axis; an infinite mass
// stays infinite).
namespace
{
void loadInverseMass(IslandBody& b, const Island& island)
{
	const btRigidBody& body = *b.rigid;
	const double massRef = island.stiffMetric ? island.referenceMass : 0;
	const double inertiaRef = island.stiffMetric ? island.referenceInertia : 0;
	const btVector3& af = body.getAngularFactor();
	const btVector3& invLocal = body.getInvInertiaDiagLocal();
	const btMatrix3x3& basis = body.getCenterOfMassTransform().getBasis();
	// the weighted and stiff metrics: a body pressed against something the projection does not see takes a small
	// share of the correction (contactScale); M itself (the velocities, the end of the position stage) is M
	const double contact = (island.rotationWeight != 1 || island.stiffMetric) ? b.contactScale : 1;
	const double invMass = contact * body.getInvMass() / (1 + body.getInvMass() * massRef);
	Eigen::Vector3d invInertiaLocal;
	Eigen::Matrix3d sr;  // S R
	for (int i = 0; i < 3; ++i)
	{
		b.invMass[i] = invMass * body.getLinearFactor()[i];
		invInertiaLocal[i] = contact * invLocal[i] / ((1 + invLocal[i] * inertiaRef) * island.rotationWeight);
		for (int j = 0; j < 3; ++j) sr(i, j) = double(af[i]) * double(basis[i][j]);
	}
	b.invInertia.noalias() = sr * invInertiaLocal.asDiagonal() * sr.transpose();
}
}  // namespace

void loadInverseMasses(Island& island)
{
	for (IslandBody& b : island.bodies) loadInverseMass(b, island);
	island.inverseMassesStale = false;
}

void findReferenceMass(Island& island)
{
	island.referenceMass = island.referenceInertia = 0;
	for (const IslandBody& b : island.bodies)
	{
		const btRigidBody& body = *b.rigid;
		if (body.getInvMass() > 0) island.referenceMass = (std::max)(island.referenceMass, 1.0 / body.getInvMass());
		const btVector3& invLocal = body.getInvInertiaDiagLocal();
		for (int i = 0; i < 3; ++i)
			if (invLocal[i] > 0) island.referenceInertia = (std::max)(island.referenceInertia, 1.0 / invLocal[i]);
	}
}

namespace
{
// A body's pose during the iterations: its transform and its interpolation transform (what the world hands to its
// motion state). Bullet's own world inverse inertia is refreshed once, when the projection is done
// (finishPositions); the iterations use loadInverseMass's, reloaded when next needed (Island::inverseMassesStale:
// a metric switch right after a move would otherwise load them twice).
void setPose(IslandBody& b, const btTransform& t)
{
	b.rigid->setWorldTransform(t);
	b.rigid->setInterpolationWorldTransform(t);
}
}  // namespace

void saveTransforms(Island& island)
{
	for (IslandBody& b : island.bodies) b.saved = b.rigid->getCenterOfMassTransform();
}

void restoreTransforms(Island& island)
{
	for (IslandBody& b : island.bodies) setPose(b, b.saved);
	island.inverseMassesStale = true;
}

void finishPositions(Island& island)
{
	for (IslandBody& b : island.bodies) b.rigid->updateInertiaTensor();
}

// Applies step × the deltas as a position correction; returns the largest |Δx|∞ or |Δθ|∞ (m or rad).
double movePositions(Island& island, double step)
{
	double largest = 0;
	for (IslandBody& b : island.bodies)
	{
		const Eigen::Matrix<double, 6, 1> move = step * b.delta;
		largest = (std::max)(largest, move.cwiseAbs().maxCoeff());
		btTransform t = b.rigid->getCenterOfMassTransform();
		t.setOrigin(t.getOrigin() + btVector3(btScalar(move[0]), btScalar(move[1]), btScalar(move[2])));
		// q ← normalize(q + ½ Δθ ⊗ q) (Q1 over a unit time: the world-frame rotation Δθ)
		btQuaternion q = t.getRotation();
		const btQuaternion dtheta(static_cast<btScalar>(move[3]), static_cast<btScalar>(move[4]),
								  static_cast<btScalar>(move[5]), 0);
		q += (dtheta * q) * btScalar(0.5);
		q.normalize();
		t.setRotation(q);
		setPose(b, t);
	}
	island.inverseMassesStale = true;
	return largest;
}

void changeVelocities(Island& island)
{
	for (IslandBody& b : island.bodies)
	{
		btRigidBody& body = *b.rigid;
		const btVector3 v = body.getLinearVelocity() +
							btVector3(btScalar(b.delta[0]), btScalar(b.delta[1]), btScalar(b.delta[2]));
		const btVector3 w = body.getAngularVelocity() +
							btVector3(btScalar(b.delta[3]), btScalar(b.delta[4]), btScalar(b.delta[5]));
		body.setLinearVelocity(v);
		body.setAngularVelocity(w);
		body.setInterpolationLinearVelocity(v);
		body.setInterpolationAngularVelocity(w);
	}
}

}  // namespace stabilizer
}  // namespace quathinge
