// The projection does no work: IslandInvariants.h (docs/ENERGY.md, Q15–Q19).
#include "IslandInvariants.h"

#include "IslandRestCache.h"

#include "quathinge/btQuaternionHingeConstraint.h"

#include "BulletDynamics/Dynamics/btDynamicsWorld.h"
#include "BulletDynamics/Dynamics/btRigidBody.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace quathinge
{
namespace stabilizer
{
namespace
{
// Largest relative change of the deformation speeds in one step (Q19; dimensionless). The losses and gains it
// offsets are a few per cent per step at most (the curvature share (m d²/I)(ωh)², 1.2% per step for a bar pendulum
// at its lowest point at 60 Hz); the cap binds only where the kinetic energy is tiny: at a turning point, at rest.
const double kMaxScalePerStep = 0.1;
// The scale's cap is widened to T(v) − T_r only while the solver's leftover T_r is at most this share of T(v) (J/J).
const double kLeftoverShare = 0.5;
// Below this share of the island's energy scale the kinetic energy is not scaled (J/J): nothing to carry it.
const double kTinyKinetic = 1e-12;
// Largest relative change of a free island's rigid spin in one step (Q17; dimensionless). The position stage takes a
// share of about ½(ωh)² of the spin's angular momentum (5.6e-4 at 2 rad/s and 60 Hz); the cap binds only past ωh ≈ 0.45
// rad, where Bullet's own step is far from the motion (its per-step rotation clamp, a rotor at 1000 rad/s).
const double kMaxSpinScalePerStep = 0.1;
// The guard: the running average (time constant kGuardTime, s) of its ledger (the energy the calls left beyond their
// goal, Invariants::ledger) rises above its lowest value; the part of that rise the restoration's own work since then
// accounts for (its work over kGuardShare, at most the rise) is the guard's measure. Up to kGuardGrowth of the island's
// energy scale the restoration acts in full; from there to twice that its change of the speeds is tapered linearly
// to none (Invariants::hold). Continuous, and it recovers: held back, the restoration no longer adds, the ledger's
// average falls with the projection's own losses, and the hold is released as it falls. An island with a source (a
// drive, an outside contact, a moving partner) is not held.
const double kGuardTime = 2;
const double kGuardGrowth = 0.1;
const double kGuardShare = 0.5;

Eigen::Vector3d toEigen(const btVector3& v) { return Eigen::Vector3d(double(v.x()), double(v.y()), double(v.z())); }
btVector3 toBullet(const Eigen::Vector3d& v) { return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z())); }

// A body's mass (0 for an infinite one) and world inertia R diag(I_local) Rᵀ (an axis of infinite inertia counts 0:
// it stores no energy, and such a body makes its island not free).
double massOf(const btRigidBody& body) { return body.getInvMass() > 0 ? 1.0 / double(body.getInvMass()) : 0.0; }
Eigen::Matrix3d inertiaOf(const btRigidBody& body)
{
	const btMatrix3x3& basis = body.getCenterOfMassTransform().getBasis();
	const btVector3& invLocal = body.getInvInertiaDiagLocal();
	Eigen::Matrix3d r;
	Eigen::Vector3d local;
	for (int i = 0; i < 3; ++i)
	{
		local[i] = invLocal[i] > 0 ? 1.0 / double(invLocal[i]) : 0.0;
		for (int j = 0; j < 3; ++j) r(i, j) = double(basis[i][j]);
	}
	return r * local.asDiagonal() * r.transpose();
}
bool fullyFree(const btRigidBody& body)
{
	const btVector3& invLocal = body.getInvInertiaDiagLocal();
	return body.getInvMass() > 0 && invLocal.x() > 0 && invLocal.y() > 0 && invLocal.z() > 0 &&
		   body.getLinearFactor() == btVector3(1, 1, 1) && body.getAngularFactor() == btVector3(1, 1, 1);
}
double kineticOf(const btRigidBody& body, double mass)
{
	const Eigen::Vector3d v = toEigen(body.getLinearVelocity()), w = toEigen(body.getAngularVelocity());
	return 0.5 * (mass * v.squaredNorm() + w.dot(inertiaOf(body) * w));
}
// A body's angular momentum about `centre` (Q17's L, one body's share): r × m v + I ω, with r its centre of mass's
// offset from `centre` and I its world inertia (inertiaOf).
Eigen::Vector3d angularMomentumOf(const btRigidBody& body, double mass, const Eigen::Matrix3d& inertia,
								  const Eigen::Vector3d& r)
{
	return mass * r.cross(toEigen(body.getLinearVelocity())) + inertia * toEigen(body.getAngularVelocity());
}
// The power of the step's external force and torque on a body (Q15, W): F·v + τ·ω, with Bullet's accumulated total
// force and torque (each body's gravity, applyGravity's m g, and everything the app applied for this step; Bullet
// clears them after the step, after its actions).
double forcePowerOf(const btRigidBody& body)
{
	return double(body.getTotalForce().dot(body.getLinearVelocity())) +
		   double(body.getTotalTorque().dot(body.getAngularVelocity()));
}
// The work of that force and torque on the body's move from its start of the projection (J): F·Δx + τ·Δθ, Δθ the
// rotation vector of q q₀⁻¹ (small: 2 × its vector part, the short way round).
double forceWorkOf(const IslandBody& b)
{
	const btRigidBody& body = *b.rigid;
	btQuaternion turn = body.getOrientation() * b.startRotation.inverse();
	if (turn.w() < 0) turn = -turn;
	const btVector3 rotation = btScalar(2) * btVector3(turn.x(), turn.y(), turn.z());
	return double(body.getTotalForce().dot(body.getCenterOfMassPosition() - b.startPosition)) +
		   double(body.getTotalTorque().dot(rotation));
}
void setVelocities(btRigidBody& body, const btVector3& v, const btVector3& w)
{
	body.setLinearVelocity(v);
	body.setAngularVelocity(w);
	body.setInterpolationLinearVelocity(v);
	body.setInterpolationAngularVelocity(w);
}

// The largest scale of a held island's velocities (Q19): 1 + kMaxScalePerStep above what Bullet's step left them, less
// the solver's leftover (T(v) − T_r, when that is most of T(v)): a fast island whose velocity projection took more
// than the cap (a chain's end whipping round: (ωh)² of 20% in one step) gets it back, and an island at rest, whose
// T(v) is the leftover's, is not pushed.
double highestScale(const Island::Invariants& inv, const ProjectionResult& result, double kinetic)
{
	const double kept = inv.kinetic - result.leftoverKinetic;
	const double cap = 1 + kMaxScalePerStep;
	return kept > kLeftoverShare * inv.kinetic && kept > kinetic ? cap * std::sqrt(kept / kinetic) : cap;
}

// A held island's scale (Q19): the s in [lo, hi] whose Ẽ, f(s) = s²T + s·b (T the kinetic energy after the
// projection, b = ½h Σ F·v' the shadow term), comes closest to the goal; of equally close ones the nearest to 1. f is a
// parabola: a root in the bounds, else the bound closer in f. Near a turning point of a stiff force (an app spring:
// |b| > T) the goal can lie below every f(s), and the root of f(s) = 0 away from 0 (s = −b/T) would pump energy in;
// the closest f takes the lower bound instead, and f's closeness to the goal changes continuously with it.
double scaleForGoal(double kinetic, double b, double goal, double lo, double hi)
{
	auto miss = [&](double s) { return std::fabs(s * s * kinetic + s * b - goal); };
	double best = 1, bestMiss = SIMD_INFINITY;
	auto consider = [&](double s) {
		if (!(s >= lo && s <= hi)) return;
		const double m = miss(s);
		if (m < bestMiss || (m == bestMiss && std::fabs(s - 1) < std::fabs(best - 1))) best = s, bestMiss = m;
	};
	const double disc = b * b + 4 * kinetic * goal;
	if (disc >= 0)
		for (double sign : {1.0, -1.0}) consider((sign * std::sqrt(disc) - b) / (2 * kinetic));
	consider(lo);
	consider(hi);
	consider(std::clamp(-b / (2 * kinetic), lo, hi));  // the vertex: f's closest when the goal is below f's minimum
	return best;
}

// The guard's running average of the ledger after the step (J), and the hold it sets for the next step.
void updateGuard(Island& island, double energyAfter, double restorationWork, double timeStep)
{
	Island::Invariants& inv = island.invariants;
	inv.work += restorationWork;
	if (inv.elapsed == 0) inv.average = inv.lowest = energyAfter, inv.workAtLowest = inv.work;
	else inv.average += std::min(1.0, timeStep / kGuardTime) * (energyAfter - inv.average);
	inv.elapsed += timeStep;
	if (inv.average < inv.lowest)
	{
		inv.lowest = inv.average;
		inv.workAtLowest = inv.work;
	}
	const double rise = std::min(inv.average - inv.lowest, std::max(inv.work - inv.workAtLowest, 0.0) / kGuardShare);
	const double growth = kGuardGrowth * inv.scale;
	inv.hold = inv.source || !(growth > 0) ? 1.0 : std::clamp(2 - rise / growth, 0.0, 1.0);
	if (inv.hold < 1) forgetProjection(island);  // a kept projection restored energy with another hold
}
}  // namespace

void markTiedIslands(btDynamicsWorld& world, const IslandBodyMap& bodyOf, const Array<std::unique_ptr<Island>>& islands)
{
	bool anyFree = false;  // an island with no fixed partner (only such an island can be free: recordInvariants)
	for (const auto& island : islands)
	{
		island->invariants.tied = false;
		anyFree = anyFree || std::all_of(island->joints.begin(), island->joints.end(),
										 [](const JointSlot& js) { return js.body[0] >= 0 && js.body[1] >= 0; });
	}
	if (!anyFree) return;
	for (int i = 0; i < world.getNumConstraints(); ++i)
	{
		const btTypedConstraint& c = *world.getConstraint(i);
		if (!c.isEnabled()) continue;
		const auto a = bodyOf.find(&c.getRigidBodyA()), b = bodyOf.find(&c.getRigidBodyB());
		Island* islandA = a != bodyOf.end() ? a->second.first : nullptr;
		Island* islandB = b != bodyOf.end() ? b->second.first : nullptr;
		if (islandA == islandB) continue;  // within one island (its joint or not, an internal force), or in none
		if (islandA) islandA->invariants.tied = true;
		if (islandB) islandB->invariants.tied = true;
	}
}

bool hangsOnMovingBody(const Island& island)
{
	for (const JointSlot& js : island.joints)
		for (int s = 0; s < 2; ++s)
			if (js.body[s] < 0 && js.rigid[s] &&  // (a contact slot has no partner body: IslandContacts.h)
				(!js.rigid[s]->getLinearVelocity().fuzzyZero() || !js.rigid[s]->getAngularVelocity().fuzzyZero()))
				return true;
	return false;
}

void recordInvariants(Island& island)
{
	Island::Invariants& inv = island.invariants;
	double kinetic = 0, mass = 0, forcePower = 0;
	Eigen::Vector3d momentum = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
	bool free = true, source = false, touching = false;
	for (IslandBody& b : island.bodies)
	{
		const btRigidBody& body = *b.rigid;
		b.startPosition = body.getCenterOfMassPosition();
		b.startRotation = body.getOrientation();
		const double m = massOf(body);
		const Eigen::Vector3d x = toEigen(b.startPosition), v = toEigen(body.getLinearVelocity());
		kinetic += kineticOf(body, m);
		forcePower += forcePowerOf(body);
		mass += m;
		momentum += m * v;
		moment += m * x;
		free = free && fullyFree(body);
		if (b.contactScale != 1) source = touching = true;  // touching something outside the island
	}
	for (const JointSlot& js : island.joints)
	{
		if (js.body[0] < 0 || js.body[1] < 0) free = false;  // a fixed partner (or a contact slot's fixed points)
		if (js.contact >= 0) touching = true;                // a contact slot (projectContacts): its contact's work is its own
		if (js.joint && js.joint->getDriveMode() != BT_QHINGE_DRIVE_OFF) source = true;
	}
	if (hangsOnMovingBody(island)) source = true;
	inv.kinetic = kinetic;
	inv.forcePower = forcePower;
	inv.mass = mass;
	inv.momentum = momentum;
	inv.free = free && !source && mass > 0;
	inv.source = source;
	inv.touching = touching;
	const Eigen::Vector3d centre = mass > 0 ? Eigen::Vector3d(moment / mass) : Eigen::Vector3d::Zero();
	inv.angular.setZero();  // L about the centre of mass (Q17), a free island's
	if (inv.free)
		for (const IslandBody& b : island.bodies)
			inv.angular += angularMomentumOf(*b.rigid, massOf(*b.rigid), inertiaOf(*b.rigid), toEigen(b.startPosition) - centre);
	if (inv.scale == 0)  // the island's energy scale: Σ m max(|g|, 1 m/s²)(1 m + 2|x − x̄|), plus its kinetic energy
	{
		for (const IslandBody& b : island.bodies)
			inv.scale += massOf(*b.rigid) * std::max(double(b.rigid->getGravity().length()), 1.0) *
						 (1 + 2 * (toEigen(b.startPosition) - centre).norm());
		inv.scale += kinetic;
	}
}

InvariantResult restoreInvariants(Island& island, ProjectionResult& result, double timeStep, bool restoreEnergy)
{
	Island::Invariants& inv = island.invariants;
	InvariantResult out;
	if (result.iterations == 0 && result.solves == 0)  // nothing moved: the energy is the recorded one
	{
		if (restoreEnergy) updateGuard(island, inv.ledger, 0, timeStep);
		return out;
	}
	// The work of the step's forces on the projection's move (Q16: gravity's and the app's, the lift ΔV when only
	// gravity acts) and the state it left (q', v').
	double lift = 0, kinetic = 0, mass = 0, forcePower = 0;
	Eigen::Vector3d momentum = Eigen::Vector3d::Zero(), moment = Eigen::Vector3d::Zero();
	for (const IslandBody& b : island.bodies)
	{
		const btRigidBody& body = *b.rigid;
		const double m = massOf(body);
		lift -= forceWorkOf(b);
		kinetic += kineticOf(body, m);
		forcePower += forcePowerOf(body);
		mass += m;
		momentum += m * toEigen(body.getLinearVelocity());
		moment += m * toEigen(body.getCenterOfMassPosition());
	}
	const bool oneSided = result.activeLimitRows > 0 || result.contactRows > 0;  // a stop's or a contact's work
	// a contact outside the island is Bullet's solver's work (and the stop that lets a ragdoll settle): not restored
	const bool energy = restoreEnergy && !oneSided && !inv.touching && inv.hold > 0 && !hangsOnMovingBody(island);
	const double hold = energy ? inv.hold : 0;  // the guard's share of each change the restoration makes (1: all of it)
	// (Q16) Bullet's step (semi-implicit Euler: v₁ = v₀ + h(g + M⁻¹Jᵀλ/h), x₁ = x₀ + h v₁) keeps the shadow energy
	// Ẽ = E + ½h Σ m g·v exactly when its impulse closes J(x₀) v₁ = 0; the solver's leftover r changed it by
	// ½rᵀK⁻¹r − ½ΔV_r (its kinetic energy, and the potential energy its drift h r lost, half of it counted in Ẽ's
	// term). The restoration gives that back: Ẽ(q', v*) = Ẽ(q, v) + ½ΔV_r − T_r. The curvature (the step's drift off
	// the joints along their tangent, and the velocity it leaves across them) needs no term of its own: the position
	// correction's lift and the velocity stage's loss are both in Ẽ(q', v').
	const double half = 0.5 * timeStep;
	const double goal = inv.kinetic + half * inv.forcePower - lift + 0.5 * result.leftoverLift - result.leftoverKinetic;
	const double target = goal - half * forcePower;  // T* (taking Ẽ's term at v')
	double after = kinetic;                          // the kinetic energy this leaves (J)
	double afterPower = forcePower;                  // … and the forces' power then (W)
	if (inv.free)
	{
		// (Q17) the island's rigid motion: V = P/M, Ω = I_lock⁻¹ L about the centre of mass, I_lock its locked inertia
		const Eigen::Vector3d centre = moment / mass;
		Eigen::Matrix3d lock = Eigen::Matrix3d::Zero();
		Eigen::Vector3d angular = Eigen::Vector3d::Zero();
		for (const IslandBody& b : island.bodies)
		{
			const btRigidBody& body = *b.rigid;
			const double m = massOf(body);
			const Eigen::Vector3d r = toEigen(body.getCenterOfMassPosition()) - centre;
			const Eigen::Matrix3d inertia = inertiaOf(body);
			lock += inertia + m * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
			angular += angularMomentumOf(body, m, inertia, r);
		}
		const Eigen::LDLT<Eigen::Matrix3d> lockInverse(lock);
		const Eigen::Vector3d velocityNow = momentum / mass, spinNow = lockInverse.solve(angular);
		// P is put back (Q17), and L along the projection's own spin, Ω = α Ω', α = L'·L/|L'|²: the position
		// stage shortened the lever arms (L' = (1 − ½(ωh)²) L for a rigid spin), it did not turn the spin. Not through
		// I_lock⁻¹: a thin chain's I_lock is nearly singular about its long axis, and a small error of L across the
		// spin became a fast spin about that axis (docs/ENERGY.md). An island tied to bodies outside it by constraints
		// the stabilizer does not project is part of a larger free system: spinning it alone would shear them. L is put
		// back in the steps whose energy is (not in a stop's step), as far as the guard lets it (its hold).
		double alpha = 1;
		const double spinKinetic = 0.5 * angular.dot(spinNow);  // ½ L'·Ω'
		if (energy && !inv.tied && spinKinetic > kTinyKinetic * inv.scale)
		{
			// the rigid spin takes no more kinetic energy than the island has, T* less the drift's: at the pose the
			// position stage pulled in, L costs more energy than at Bullet's (a skater pulling in her arms)
			const double room = std::max(target - 0.5 * inv.momentum.squaredNorm() / mass, 0.0);
			alpha = std::min(angular.dot(inv.angular) / angular.squaredNorm(), std::sqrt(room / spinKinetic));
			alpha = 1 + hold * (std::clamp(alpha, 1 - kMaxSpinScalePerStep, 1 + kMaxSpinScalePerStep) - 1);
		}
		const Eigen::Vector3d velocity = inv.momentum / mass, spin = alpha * spinNow;
		// (Q18) the deformation d = v' − (its rigid motion) is M-orthogonal to every rigid motion: T = T_rigid + T_d
		double deformation = 0;
		for (const IslandBody& b : island.bodies)
		{
			const btRigidBody& body = *b.rigid;
			const Eigen::Vector3d r = toEigen(body.getCenterOfMassPosition()) - centre;
			const Eigen::Vector3d dv = toEigen(body.getLinearVelocity()) - velocityNow - spinNow.cross(r);
			const Eigen::Vector3d dw = toEigen(body.getAngularVelocity()) - spinNow;
			deformation += 0.5 * (massOf(body) * dv.squaredNorm() + dw.dot(inertiaOf(body) * dw));
		}
		const double rigid = 0.5 * (inv.momentum.dot(velocity) + alpha * angular.dot(spin));  // L'·Ω' scaled by α²
		// (Q19) the deformation scaled to what T* leaves it
		double s = 1;
		if (energy && deformation > kTinyKinetic * inv.scale)
			s = 1 + hold * (std::clamp(std::sqrt(std::max(target - rigid, 0.0) / deformation), 1 - kMaxScalePerStep,
									   1 + kMaxScalePerStep) -
							1);
		for (IslandBody& b : island.bodies)
		{
			btRigidBody& body = *b.rigid;
			const Eigen::Vector3d r = toEigen(body.getCenterOfMassPosition()) - centre;
			const Eigen::Vector3d dv = toEigen(body.getLinearVelocity()) - velocityNow - spinNow.cross(r);
			const Eigen::Vector3d dw = toEigen(body.getAngularVelocity()) - spinNow;
			setVelocities(body, toBullet(velocity + spin.cross(r) + s * dv), toBullet(spin + s * dw));
		}
		after = rigid + s * s * deformation;
		out.momentumRestored = true;
		out.energyRestored = s != 1;
		out.scale = s;
		result.velocitiesRestored = true;
	}
	else if (energy && kinetic > kTinyKinetic * inv.scale && kinetic > result.leftoverKinetic)
	{
		// (below the leftover's kinetic energy T_r the goal is the difference of terms larger than T(v'): an arm at
		// rest, upright, whose fall starts from that noise, is left to the projection)
		// an island held by a fixed partner: v' scaled as a whole (J v' = 0 is linear in v'), s² T(v') + s ½h Σ F·v' =
		// the goal, solved in the bounds (scaleForGoal)
		const double s =
			1 + hold * (scaleForGoal(kinetic, half * forcePower, goal, 1 - kMaxScalePerStep, highestScale(inv, result, kinetic)) - 1);
		const btScalar scale = btScalar(s);
		for (IslandBody& b : island.bodies)
			setVelocities(*b.rigid, b.rigid->getLinearVelocity() * scale, b.rigid->getAngularVelocity() * scale);
		after = s * s * kinetic;
		afterPower = s * forcePower;
		out.energyRestored = true;
		out.scale = s;
		result.velocitiesRestored = true;
	}
	// The guard's ledger: the energy this call left beyond its goal T* (Q16's Ẽ balance, every force Bullet applied
	// counted, the app's and the solver's outside the call not at all): non-zero only where a bound of the scale held.
	inv.ledger += after + half * afterPower - goal;
	if (restoreEnergy) updateGuard(island, inv.ledger, after - kinetic, timeStep);
	return out;
}

}  // namespace stabilizer
}  // namespace quathinge
