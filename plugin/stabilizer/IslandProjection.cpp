// Post-stabilization of one island (docs/MATH.md Q13, Q14; Cline & Pai, ICRA 2003).
//
//   (Q13) positions:  K = J M⁻¹ Jᵀ + ε s I,  K λ = −C,  Δx_b = M_b⁻¹ J_bᵀ λ  (linear: x ← x + Δx; angular:
//                     q ← normalize(q + ½ Δθ ⊗ q), Δθ a world-frame rotation), repeated until ‖C‖ is at tolerance.
//   (Q14) velocities: K λ = −J v at the projected positions,  v ← v + M⁻¹ Jᵀ λ, so that J v = 0.
// J = ∂C/∂(v_A, ω_A, v_B, ω_B) from btQuaternionHingeConstraint::computePositionRows (world frame): the same matrix
// maps a small displacement (Δx, Δθ) to ΔC, which is what Newton needs.
// Metric: Q13 uses M with every inertia multiplied by the rotation weight w (settings.rotationWeight, 30 by default):
// a move Δx enters the point rows linearly, a turn Δθ through R(Δθ)·r, whose second-order term makes a step that
// swings light links (the mass metric's cheapest first-order fix on a long or heavily loaded chain) fall short.
// Q14 always uses M: once a weighted step has gained kMetricSwitchGain, the rest of the step is in M and its last
// factorization serves the velocities; otherwise they get a factorization of their own.
//
// Factorizations per step. K depends on the positions, and a chain's K is ill-conditioned (a stale K gains a factor
// of about cond(K)·(move) per solve), so a factorization is reused only while the bodies have moved less than
// kChordAge since it was made ("chord" steps: that K, the current J; they still converge to C = 0 exactly). A step:
//   - Newton 1 with K(x₀) moves the bodies by about the solver's error (~1e-3 m at 60 Hz) to x₁;
//   - if more is needed, K(x₁) is factorized, the velocities are projected with it exactly (Q14 at x₁), and Newton 2
//     is a full Newton step with it; what is left moves the bodies by ~1e-5, so further Newton steps and the
//     touch-up of the velocities at the final positions are chord solves with K(x₁);
//   - if Newton 1 was enough, K(x₁) is factorized for the velocity projection.
// Two factorizations, two or three evaluations of the rows and three solves is the usual step. A chord step that gains
// less than minimumProgress (velocities: kVelocityChordProgress) is followed by a fresh factorization. A full Newton
// step that makes ‖C‖ worse is halved (kMaxHalvings), then undone; one that gains little near the floor ends the
// loop; one that fails or gains little farther away switches the position correction to the stiff metric
// (loadInverseMass) for the rest of the step, once. The velocities are always projected with M.
// Convergence is judged per row against max(tolerance, rounding floor): a float pivot position at coordinate x is only
// resolved to about ε|x| (ε = SIMD_EPSILON), so a linear row's floor is 4ε·max(1 m, |x|) (x: its bodies'
// coordinates) and an angular row's 4ε rad. The velocities are converged when each row's |J v| is below its position
// threshold over the time step (what it would drift in the next step), or J v's own floor 4ε·(|v| + |ω|·1 m).
//
// The limit row (one slot per joint with a limit): α is the multi-turn angle, J_α = ±σ R_A t its exact gradient
// (HingeAngle.h). Position stage: once α is found past a stop in this step, the row is the equation α = stop for the
// rest of the step (an active set that only grows within a step: fewer refactorizations, no flip-flopping).
// Velocity stage: α̇ = 0 only if the stop was violated this step and α̇ still points past it (decided once, before
// the first solve).
// s = trace(K)/(active rows); ε s on the diagonal keeps K positive definite with redundant rows (closed loops); a
// padding or inactive limit row gets s on its diagonal and a zero right-hand side, so its λ is 0.
// Units: C in m (linear rows) and rad (angular, limit); λ in kg·m (linear) and kg·m²·rad (angular).
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
// Smallest pivot BlockLDLT accepts, relative to the island's scale s: far below ε s (1e-9 s by default), far above
// the rounding noise of a singular pivot in double (~1e-16 s).
const double kPivotFloor = 1e-13;
// A factorization is reused (chord steps) only while the bodies have moved less than this since it was made (m or
// rad, the largest component). A chord solve leaves a fraction of about cond(K)·(move) of the residual, and a chain's
// K is ill-conditioned (measured: ~1e3·move for 100 links), so only the small moves after a full Newton step qualify.
const double kChordAge = 1e-4;
// Velocities projected exactly a little earlier in the step need only a touch-up: a chord solve may then follow a
// larger move (it only has to gain a few times; measured ~0.5 after 1e-3 for 100 links).
const double kTouchUpAge = 1e-3;
// A velocity chord solve must gain at least this factor, else the next solve refactorizes (and is exact).
const btScalar kVelocityChordProgress = btScalar(0.5);

// A Newton step in the weighted metric that reduces the normalized residual by this factor or more ends the weighted
// part of the step (measured on ragdolls on the ground: 1e4 → ~10 in one step; 20% fewer factorizations; a
// 1:10000 load gains less per step and keeps the weight, which it needs).
const btScalar kMetricSwitchGain = btScalar(0.01);

// Halvings of a Newton step that made ‖C‖ worse before it is undone.
const int kMaxHalvings = 2;
// Slow progress within this factor of the rounding floor (normalized residual) ends the iterations.
const btScalar kNearFloor = 4;
// Velocity solves per step: a chord solve or two, then an exact one if they stall.
const int kMaxVelocitySolves = 3;

btScalar maxAbs(const btVector3& v) { return btMax(btFabs(v.x()), btMax(btFabs(v.y()), btFabs(v.z()))); }

// M⁻¹ of a body in double: m⁻¹ times the linear factor, and S R diag(I_local⁻¹) Rᵀ S (S the angular factor, R the
// body's basis) formed here rather than taken from getInvInertiaTensorWorld: that float product is not exactly
// symmetric, and its 1e-7 asymmetry makes a redundant K (closed loops) indefinite far above the regularization.
// The position correction's metric has every inertia multiplied by the rotation weight w (island.rotationWeight;
// 1 in the velocity stage): I⁻¹ → I⁻¹/w. With the island's stiff metric on (see projectIsland), it uses
// (M + M_ref)⁻¹ as well: every body made as heavy as the island's heaviest (m_ref, I_ref), so a correction no longer
// prefers swinging light bodies a long way (m⁻¹ → m⁻¹/(1 + m⁻¹ m_ref), the same per inertia axis; an infinite mass
// stays infinite).
void loadInverseMass(IslandBody& b, const Island& island)
{
	const btRigidBody& body = *b.rigid;
	const double massRef = island.stiffMetric ? island.referenceMass : 0;
	const double inertiaRef = island.stiffMetric ? island.referenceInertia : 0;
	const btVector3& af = body.getAngularFactor();
	const btVector3& invLocal = body.getInvInertiaDiagLocal();
	const btMatrix3x3& basis = body.getCenterOfMassTransform().getBasis();
	const double invMass = body.getInvMass() / (1 + body.getInvMass() * massRef);
	Eigen::Vector3d invInertiaLocal;
	Eigen::Matrix3d sr;  // S R
	for (int i = 0; i < 3; ++i)
	{
		b.invMass[i] = invMass * body.getLinearFactor()[i];
		invInertiaLocal[i] = invLocal[i] / ((1 + invLocal[i] * inertiaRef) * island.rotationWeight);
		for (int j = 0; j < 3; ++j) sr(i, j) = double(af[i]) * double(basis[i][j]);
	}
	b.invInertia.noalias() = sr * invInertiaLocal.asDiagonal() * sr.transpose();
}

void loadInverseMasses(Island& island)
{
	for (IslandBody& b : island.bodies) loadInverseMass(b, island);
}

// The heaviest body's mass and largest principal inertia: the stiff metric's reference.
void findReferenceMass(Island& island)
{
	island.referenceMass = island.referenceInertia = 0;
	for (const IslandBody& b : island.bodies)
	{
		const btRigidBody& body = *b.rigid;
		if (body.getInvMass() > 0) island.referenceMass = std::max(island.referenceMass, 1.0 / body.getInvMass());
		const btVector3& invLocal = body.getInvInertiaDiagLocal();
		for (int i = 0; i < 3; ++i)
			if (invLocal[i] > 0) island.referenceInertia = std::max(island.referenceInertia, 1.0 / invLocal[i]);
	}
}

#ifdef BT_DEBUG
// The linear part of every row is ±[I₃; 0] (point rows) or 0 (quaternion rows): what JointSlot::linearSign encodes.
bool hasPointStructure(const btScalar* jac, int rows, int linearRows)
{
	for (int r = 0; r < rows; ++r)
		for (int k = 0; k < 3; ++k)
		{
			const btScalar expected = (r < linearRows && r == k) ? btScalar(1) : btScalar(0);
			if (jac[12 * r + k] != -expected || jac[12 * r + 6 + k] != expected) return false;
		}
	return true;
}
#endif

struct PositionResidual
{
	btScalar linear = 0;         // ‖C‖∞ over the linear rows (m)
	btScalar angular = 0;        // over the quaternion and limit rows (rad)
	btScalar normalized = 0;     // max over rows of |C| / max(tolerance, the row's rounding floor): ≤ 1 is converged
	bool limitsChanged = false;  // some limit row's activity differs from the factorized K
	btScalar max() const { return btMax(linear, angular); }
};

// The rows of every joint at the bodies' current transforms, and ‖C‖ against tolerance and the rounding floors.
template <int R>
PositionResidual evaluatePositions(BlockIsland<R>& island, btScalar tolerance)
{
	PositionResidual res;
	const btScalar angularThreshold = btMax(tolerance, 4 * SIMD_EPSILON);
	btScalar c[5];
	btScalar jac[60];
	for (size_t j = 0; j < island.joints.size(); ++j)
	{
		JointSlot& js = island.joints[j];
		JointBlock<R>& jb = island.blocks[j];
		const btTransform& tA = js.rigid[0]->getCenterOfMassTransform();
		const btTransform& tB = js.rigid[1]->getCenterOfMassTransform();
		const int rows = js.joint->computePositionRows(tA, tB, c, jac);
		const int linearRows = rows - 2;
		btAssert(hasPointStructure(jac, rows, linearRows));
		btScalar linear = 0, angular = 0;
		for (int r = 0; r < rows; ++r)
		{
			jb.c[r] = c[r];
			for (int k = 0; k < 12; ++k) jb.jacobian(r, k) = jac[12 * r + k];
			btScalar& worst = r < linearRows ? linear : angular;
			worst = btMax(worst, btFabs(c[r]));
		}
		// The pivot's rounding floor: 4ε·max(1 m, |x|) at the larger of the two bodies' coordinates.
		const btScalar coordinate = btMax(maxAbs(tA.getOrigin()), maxAbs(tB.getOrigin()));
		const btScalar linearThreshold = btMax(tolerance, 4 * SIMD_EPSILON * btMax(btScalar(1), coordinate));
		js.linearThreshold = linearThreshold;
		js.angularThreshold = angularThreshold;
		res.linear = btMax(res.linear, linear);
		res.angular = btMax(res.angular, angular);
		res.normalized = btMax(res.normalized, btMax(linear / linearThreshold, angular / angularThreshold));
		if (!js.limitSlot) continue;
		btAssert(R == 6);  // an island with a limit slot works in 6-row blocks

		// The limit row: the multi-turn angle α continued from the step's reference, and its gradient (the joint's own
		// Q11, btQuaternionHingeConstraint::computeAngleRow).
		btVector3 g;
		js.angle = js.joint->computeAngleRow(tA, tB, js.angleReference, g);
		for (int k = 0; k < 3; ++k)
		{
			js.limitGradient[k] = 0;
			js.limitGradient[3 + k] = -g[k];
			js.limitGradient[6 + k] = 0;
			js.limitGradient[9 + k] = g[k];
		}
		if (js.limitTouched == 0)
		{
			if (js.angle < js.joint->getLowerLimit()) js.limitTouched = 1;
			else if (js.angle > js.joint->getUpperLimit()) js.limitTouched = -1;
		}
		js.limitActive = js.limitTouched != 0;
		const int r = js.bilateralRows;
		const btScalar stop = js.limitTouched > 0 ? js.joint->getLowerLimit() : js.joint->getUpperLimit();
		jb.c[r] = js.limitActive ? js.angle - stop : 0;
		if (js.limitActive) jb.jacobian.row(r) = js.limitGradient;
		else jb.jacobian.row(r).setZero();
		res.angular = btMax(res.angular, btFabs(btScalar(jb.c[r])));
		res.normalized = btMax(res.normalized, btFabs(btScalar(jb.c[r])) / angularThreshold);
		if (js.limitActive != js.limitActiveInFactor) res.limitsChanged = true;
	}
	return res;
}

struct VelocityResidual
{
	btScalar max = 0;            // ‖J v‖∞ (m/s, rad/s)
	btScalar normalized = 0;     // max over rows of |J v| / its threshold: ≤ 1 is converged
	bool limitsChanged = false;  // some limit row's activity differs from the factorized K
};

// J v per row (into JointBlock::jv). decideLimits: choose which limit rows take part (else keep the choice).
// A row's threshold is its position threshold over the time step (what it would drift in the next step), or the
// rounding floor of J v itself, 4ε·(|v| + |ω|·1 m) of the joint's bodies.
template <int R>
VelocityResidual evaluateVelocities(BlockIsland<R>& island, bool decideLimits, btScalar timeStep)
{
	VelocityResidual res;
	for (size_t j = 0; j < island.joints.size(); ++j)
	{
		JointSlot& js = island.joints[j];
		JointBlock<R>& jb = island.blocks[j];
		Eigen::Matrix<double, 12, 1> v;
		btScalar speed = 0;
		for (int s = 0; s < 2; ++s)
		{
			const btVector3& lin = js.rigid[s]->getLinearVelocity();
			const btVector3& ang = js.rigid[s]->getAngularVelocity();
			for (int k = 0; k < 3; ++k)
			{
				v[6 * s + k] = lin[k];
				v[6 * s + 3 + k] = ang[k];
			}
			speed = btMax(speed, maxAbs(lin) + maxAbs(ang));
		}
		if (js.limitSlot)
		{
			const int r = js.bilateralRows;
			if (decideLimits)
			{
				// α̇ = 0 only while moving further past a stop violated this step (lower: α̇ < 0, upper: α̇ > 0).
				const double rate = js.limitGradient.dot(v.transpose());
				js.limitActive = (js.limitTouched > 0 && rate < 0) || (js.limitTouched < 0 && rate > 0);
			}
			if (js.limitActive) jb.jacobian.row(r) = js.limitGradient;
			else jb.jacobian.row(r).setZero();
			if (js.limitActive != js.limitActiveInFactor) res.limitsChanged = true;
		}
		jb.jv.noalias() = jb.jacobian * v;
		const btScalar floor = 4 * SIMD_EPSILON * btMax(btScalar(1), speed);
		const int linearRows = js.bilateralRows - 2;
		for (int r = 0; r < js.rows; ++r)
		{
			const btScalar value = btFabs(btScalar(jb.jv[r]));
			const btScalar threshold = (r < linearRows ? js.linearThreshold : js.angularThreshold) / timeStep;
			res.max = btMax(res.max, value);
			res.normalized = btMax(res.normalized, value / btMax(threshold, floor));
		}
	}
	return res;
}

// M⁻¹ Jᵀ per joint side (its angular part h; the linear part is linearSign·m⁻¹), at the current J and inertias.
template <int R>
void computeDirections(BlockIsland<R>& island)
{
	for (size_t j = 0; j < island.joints.size(); ++j)
	{
		const JointSlot& js = island.joints[j];
		JointBlock<R>& jb = island.blocks[j];
		for (int s = 0; s < 2; ++s)
			if (js.body[s] >= 0)
				jb.h[s].noalias() = island.bodies[js.body[s]].invInertia *
									jb.jacobian.template block<R, 3>(0, 6 * s + 3).transpose();
	}
}

// K = J M⁻¹ Jᵀ + regularization into island.k (the directions must be current). Returns the scale s.
// Per pair of joint sides on body b: J_i M_b⁻¹ J_jᵀ = σ_i σ_j diag(m_b⁻¹) (top-left 3×3) + A_i h_j.
template <int R>
double assemble(BlockIsland<R>& island, double regularization)
{
	constexpr int kStorage = BlockShape<R>::kStorageRows;
	double trace = 0;
	int activeRows = 0;
	for (size_t j = 0; j < island.joints.size(); ++j)
	{
		const JointSlot& js = island.joints[j];
		const JointBlock<R>& jb = island.blocks[j];
		Block<R>& d = island.k.diag[j];
		d.setZero();
		for (int s = 0; s < 2; ++s)
		{
			if (js.body[s] < 0) continue;
			// whole storage columns (their storage rows are zero in J): vectorized
			d.noalias() += jb.jacobian.template block<kStorage, 3>(0, 6 * s + 3) * jb.h[s];
			if (js.linearSign[s] != 0) d.template topLeftCorner<3, 3>().diagonal() += island.bodies[js.body[s]].invMass;
		}
		for (int r = 0; r < js.bilateralRows; ++r) trace += d(r, r);
		activeRows += js.bilateralRows;
		if (js.limitSlot && js.limitActive)
		{
			trace += d(js.bilateralRows, js.bilateralRows);
			++activeRows;
		}
	}
	for (Block<R>& b : island.k.lower) b.setZero();
	for (const Coupling& c : island.couplings)
	{
		const JointSlot& ji = island.joints[c.i];
		const JointSlot& jj = island.joints[c.j];
		Block<R>& b = island.k.lower[c.block];
		b.noalias() +=
			island.blocks[c.i].jacobian.template block<kStorage, 3>(0, 6 * c.sideI + 3) * island.blocks[c.j].h[c.sideJ];
		const double sign = ji.linearSign[c.sideI] * jj.linearSign[c.sideJ];
		if (sign != 0)
			b.template topLeftCorner<3, 3>().diagonal() += sign * island.bodies[ji.body[c.sideI]].invMass;
	}
	// ε s on active rows; s on padding and inactive limit rows (their J rows are zero).
	const double scale = (activeRows > 0 && trace > 0) ? trace / activeRows : 1.0;
	for (size_t j = 0; j < island.joints.size(); ++j)
	{
		JointSlot& js = island.joints[j];
		Block<R>& d = island.k.diag[j];
		const int activeEnd = js.bilateralRows + ((js.limitSlot && js.limitActive) ? 1 : 0);
		for (int r = 0; r < R; ++r) d(r, r) = r < activeEnd ? d(r, r) + regularization * scale : scale;
		js.limitActiveInFactor = js.limitActive;
	}
	return scale;
}

// Assembles and factorizes K at the current state. False if the factorization failed.
template <int R>
bool refactorize(BlockIsland<R>& island, double regularization, ProjectionResult& result)
{
	computeDirections(island);
	const double scale = assemble(island, regularization);
	++result.factorizations;
	if (island.useSparse)
	{
		if (island.sparse->factorize(island.k)) return true;
		++result.numericalIssues;
		return false;
	}
	result.numericalIssues += island.block.factorize(island.k, kPivotFloor * scale);
	return true;
}

// λ = K⁻¹(−r) with the current factors, r = C (the position stage) or J v (the velocity stage), then
// Δ_b = Σ M_b⁻¹ J_bᵀ λ per body (into IslandBody::delta).
template <int R>
void solveDeltas(BlockIsland<R>& island, BlockVector<R> JointBlock<R>::*rhs, ProjectionResult& result)
{
	for (size_t j = 0; j < island.joints.size(); ++j) island.lambda[j] = -(island.blocks[j].*rhs);
	if (island.useSparse) island.sparse->template solve<R>(island.lambda.data());
	else island.block.solve(island.k, island.lambda.data());
	++result.solves;
	for (IslandBody& b : island.bodies) b.delta.setZero();
	for (size_t j = 0; j < island.joints.size(); ++j)
	{
		const JointSlot& js = island.joints[j];
		const JointBlock<R>& jb = island.blocks[j];
		const BlockVector<R>& lambda = island.lambda[j];
		for (int s = 0; s < 2; ++s)
		{
			if (js.body[s] < 0) continue;
			IslandBody& b = island.bodies[js.body[s]];
			if (js.linearSign[s] != 0) b.delta.head<3>() += js.linearSign[s] * b.invMass.cwiseProduct(lambda.template head<3>());
			b.delta.tail<3>().noalias() += jb.h[s] * lambda.template head<R>();
		}
	}
}

void saveTransforms(Island& island)
{
	for (IslandBody& b : island.bodies) b.saved = b.rigid->getCenterOfMassTransform();
}

// A body's pose during the iterations: its transform and its interpolation transform (what the world hands to its
// motion state). Bullet's own world inverse inertia is refreshed once, when the projection is done
// (finishPositions); the iterations use loadInverseMass's.
void setPose(IslandBody& b, const Island& island, const btTransform& t)
{
	b.rigid->setWorldTransform(t);
	b.rigid->setInterpolationWorldTransform(t);
	loadInverseMass(b, island);
}

void restoreTransforms(Island& island)
{
	for (IslandBody& b : island.bodies) setPose(b, island, b.saved);
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
		largest = std::max(largest, move.cwiseAbs().maxCoeff());
		btTransform t = b.rigid->getCenterOfMassTransform();
		t.setOrigin(t.getOrigin() + btVector3(btScalar(move[0]), btScalar(move[1]), btScalar(move[2])));
		// q ← normalize(q + ½ Δθ ⊗ q) (Q1 over a unit time: the world-frame rotation Δθ)
		btQuaternion q = t.getRotation();
		const btQuaternion dtheta(static_cast<btScalar>(move[3]), static_cast<btScalar>(move[4]),
								  static_cast<btScalar>(move[5]), 0);
		q += (dtheta * q) * btScalar(0.5);
		q.normalize();
		t.setRotation(q);
		setPose(b, island, t);
	}
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

}  // namespace

namespace
{
template <int R>
ProjectionResult projectBlocks(BlockIsland<R>& island, const ProjectionSettings& settings)
{
	ProjectionResult result;
	island.stiffMetric = false;
	island.rotationWeight = settings.positions ? settings.rotationWeight : 1;
	findReferenceMass(island);
	loadInverseMasses(island);
	for (JointSlot& js : island.joints)
	{
		js.limitTouched = 0;
		js.limitActive = js.limitActiveInFactor = false;
		if (js.limitSlot) js.angleReference = js.joint->getMultiTurnAngle();
	}

	// How far the bodies moved since K was factorized (m or rad); infinite: no factorization yet.
	double factorAge = SIMD_INFINITY;
	auto factorize = [&]() {
		if (!refactorize(island, settings.regularization, result)) return false;
		factorAge = 0;
		return true;
	};
	// Switches the position correction to the stiff metric (loadInverseMass) for the rest of the step; false if it is
	// on already.
	auto useStiffMetric = [&]() {
		if (island.stiffMetric) return false;
		island.stiffMetric = true;
		loadInverseMasses(island);
		++result.metricSwitches;
		return true;
	};
	// The position stage works in M itself (its factorization can serve the velocities too).
	auto positionMetricIsM = [&]() { return !island.stiffMetric && island.rotationWeight == 1; };
	// Back to M (the velocity projection's metric, Q14); the current factorization is of the other metric.
	auto useMassMetric = [&]() {
		island.stiffMetric = false;
		island.rotationWeight = 1;
		loadInverseMasses(island);
		factorAge = SIMD_INFINITY;
	};
	auto anyLimitTouched = [&]() {
		for (const JointSlot& js : island.joints)
			if (js.limitTouched != 0) return true;
		return false;
	};
	// Q14 with the factorization just made (exact): J v = 0 at the current positions.
	bool velocitiesProjected = false;
	auto projectVelocitiesExactly = [&]() {
		const VelocityResidual vres = evaluateVelocities(island, true, settings.timeStep);
		result.velocityResidualBefore = result.velocityResidualAfter = vres.max;
		velocitiesProjected = true;
		if (vres.normalized <= 1) return;
		solveDeltas(island, &JointBlock<R>::jv, result);
		changeVelocities(island);
	};

	PositionResidual res = evaluatePositions(island, settings.tolerance);
	result.residualBefore = res.max();
	if (settings.positions)
	{
		bool chordStalled = false;
		while (res.normalized > 1 && result.iterations < settings.maxIterations)
		{
			const bool factorNow = chordStalled || factorAge > kChordAge || res.limitsChanged;
			if (factorNow)
			{
				if (!factorize()) break;
				chordStalled = false;
				// After the first Newton step the bodies only move by the small rest of the correction: project the
				// velocities now, with this factorization, and only touch them up at the final positions below
				// (one factorization fewer than projecting them there from scratch). Not with a limit row in play:
				// its velocity rule would change K's rows; not in another metric than M.
				if (settings.velocities && !velocitiesProjected && result.iterations > 0 && !anyLimitTouched() &&
					positionMetricIsM())
					projectVelocitiesExactly();
			}
			else
				computeDirections(island);  // chord step: the factorized K, the current J
			solveDeltas(island, &JointBlock<R>::c, result);
			saveTransforms(island);
			const PositionResidual start = res;
			double step = 1;
			factorAge += movePositions(island, step);
			++result.iterations;
			res = evaluatePositions(island, settings.tolerance);
			// Backtracking: a step that makes ‖C‖ worse (far from the solution in a nearly singular pose, e.g. a taut
			// chain, the linearization overshoots) is halved, at most kMaxHalvings times, else undone.
			for (int halving = 0; res.normalized >= start.normalized && halving < kMaxHalvings; ++halving)
			{
				step *= 0.5;
				restoreTransforms(island);
				movePositions(island, step);
				res = evaluatePositions(island, settings.tolerance);
				++result.backtracks;
			}
			// A weighted step that gained kMetricSwitchGain or more has brought the pose close to the manifold, where
			// Newton converges quadratically in any metric: the rest of the step works in M, whose factorization
			// then serves the velocities as well (one factorization fewer).
			if (island.rotationWeight != 1 && !island.stiffMetric && res.normalized <= kMetricSwitchGain * start.normalized)
				useMassMetric();
			if (res.normalized >= start.normalized)
			{
				restoreTransforms(island);
				res = evaluatePositions(island, settings.tolerance);  // the rows at the restored positions
				// No step along this Newton direction helps. The mass metric's direction can be the culprit (a
				// nearly straight chain of light links under a heavy load: bending them is cheap to first order and
				// useless to second); retry once with the stiff metric, else leave the positions as they were.
				if (factorNow && !useStiffMetric()) break;
				chordStalled = true;
				continue;
			}
			if (res.normalized > settings.minimumProgress * start.normalized)
			{
				// Slow progress: near the rounding floor more iterations cannot help; farther away a full Newton
				// step that gains little is the nearly singular case above (switch metric); with an old
				// factorization, a fresh one will help.
				if (factorNow && res.normalized <= kNearFloor) break;
				if (factorNow) useStiffMetric();
				chordStalled = true;
			}
		}
	}
	if (!positionMetricIsM()) useMassMetric();  // the velocities in M (Q14 must conserve momentum)
	if (result.iterations > 0) finishPositions(island);
	result.residualAfter = res.max();
	for (const JointSlot& js : island.joints)
		if (js.limitTouched != 0) ++result.activeLimitRows;

	if (!settings.velocities) return result;
	VelocityResidual vres = evaluateVelocities(island, !velocitiesProjected, settings.timeStep);
	if (!velocitiesProjected) result.velocityResidualBefore = vres.max;
	result.velocityResidualAfter = vres.max;
	// J v = 0 at the final positions: chord solves while the factorization is recent, or to touch up velocities
	// already projected a small move ago; else (or when they stall) a fresh factorization. A solve with a fresh
	// factorization is exact up to the regularization (a relative ε·cond(K) of J v, ~1e-6 on a chain of ten in
	// double), which the next solve with the same factors removes (iterative refinement: the positions do not move).
	bool chordStalled = false, factorizedHere = false;
	for (int solve = 0; solve < kMaxVelocitySolves && vres.normalized > 1; ++solve)
	{
		// The last solve allowed uses a fresh factorization if none was made here.
		const bool factorNow = chordStalled || factorAge > (velocitiesProjected ? kTouchUpAge : kChordAge) ||
							   vres.limitsChanged || (solve == kMaxVelocitySolves - 1 && !factorizedHere);
		if (factorNow)
		{
			if (!factorize()) break;
			factorizedHere = true;
		}
		else
			computeDirections(island);
		solveDeltas(island, &JointBlock<R>::jv, result);
		changeVelocities(island);
		const btScalar previous = vres.normalized;
		vres = evaluateVelocities(island, false, settings.timeStep);
		result.velocityResidualAfter = vres.max;
		chordStalled = vres.normalized > kVelocityChordProgress * previous;
		if (factorNow && chordStalled) break;  // a fresh factorization that gains little: what is left is rounding
	}
	return result;
}
}  // namespace

ProjectionResult projectIsland(Island& island, const ProjectionSettings& settings)
{
	if (island.blockRows == 5) return projectBlocks(static_cast<BlockIsland<5>&>(island), settings);
	return projectBlocks(static_cast<BlockIsland<6>&>(island), settings);
}

}  // namespace stabilizer
}  // namespace quathinge
