// Energy restoration for conservative islands (docs/MATH.md, "Beyond the rows", last item: projection onto the
// energy level, Hairer–Lubich–Wanner, Geometric Numerical Integration, ch. IV.4).
//
// Semi-implicit Euler with velocity-level joints loses energy (a frictionless pendulum released at 90°: about a
// quarter in 10 s at 60 Hz, stock and quaternion alike), and a lower swing has a shorter period. For an island the
// user declares conservative (btQuaternionHingeStabilizerSettings::conserveEnergy), the energy
//   E = Σ_b ½ m_b |v_b|² + ½ ω_bᵀ I_b ω_b − m_b g_b·x_b      (g_b: the body's own gravity)
// is held at the value it had when the island was first projected: after the velocity projection (Q14) every body's
// velocities are scaled by one factor s = sqrt((E_ref − V)/T). J v is linear in v, so J v = 0 stays exactly true.
// The scaling is limited to kMaxScalePerStep per step, and skipped when T or E_ref − V is not positive (at a turning
// point the kinetic energy is too small to carry the deficit: it is made up over the next steps) and when a fixed
// body the island hangs on moves (a moving kinematic body does work: not conservative).
#include "IslandInvariants.h"
#include "StabilizerIsland.h"

#include "quathinge/btQuaternionHingeConstraint.h"

#include "BulletDynamics/Dynamics/btRigidBody.h"

#include <algorithm>
#include <cmath>

namespace quathinge
{
namespace stabilizer
{
namespace
{
// Largest relative change of the speeds in one step (dimensionless). Measured on a pendulum released at 90° (60 Hz,
// 10 s; tests/test_stabilizer.cpp): RMS energy error 1.3% / 0.8% / 0.6% of m g d and period error 0.79% / 0.59% /
// 0.38% with 2% / 5% / 10%; the cap binds only near turning points, where the speeds are small.
const double kMaxScalePerStep = 0.1;

struct Energy
{
	double kinetic = 0;    // J
	double potential = 0;  // J, zero at the world origin
};

Energy islandEnergy(const Island& island)
{
	Energy e;
	for (const IslandBody& b : island.bodies)
	{
		const btRigidBody& body = *b.rigid;
		const btVector3& v = body.getLinearVelocity();
		if (body.getInvMass() > 0)
		{
			const double mass = 1.0 / double(body.getInvMass());
			e.kinetic += 0.5 * mass * double(v.length2());
			e.potential -= mass * double(body.getGravity().dot(body.getCenterOfMassPosition()));
		}
		// ½ ωᵀ I ω with I from the local principal inertias (an axis with zero inverse inertia has none to store)
		const btVector3 local = body.getCenterOfMassTransform().getBasis().transpose() * body.getAngularVelocity();
		const btVector3& invInertia = body.getInvInertiaDiagLocal();
		for (int i = 0; i < 3; ++i)
			if (invInertia[i] > 0) e.kinetic += 0.5 * double(local[i]) * double(local[i]) / double(invInertia[i]);
	}
	return e;
}

}  // namespace

double restoreEnergy(Island& island)
{
	if (island.bodies.empty() || hangsOnMovingBody(island)) return 0;
	const Energy e = islandEnergy(island);
	if (!island.energyReferenceSet)
	{
		island.energyReference = e.kinetic + e.potential;
		island.energyReferenceSet = true;
		return 0;
	}
	const double targetKinetic = island.energyReference - e.potential;
	if (!(e.kinetic > 0) || !(targetKinetic > 0)) return 0;
	const double scale = std::clamp(std::sqrt(targetKinetic / e.kinetic), 1 - kMaxScalePerStep, 1 + kMaxScalePerStep);
	const btScalar s = btScalar(scale);
	for (IslandBody& b : island.bodies)
	{
		b.rigid->setLinearVelocity(b.rigid->getLinearVelocity() * s);
		b.rigid->setAngularVelocity(b.rigid->getAngularVelocity() * s);
	}
	return std::fabs(scale - 1);
}

}  // namespace stabilizer
}  // namespace quathinge
