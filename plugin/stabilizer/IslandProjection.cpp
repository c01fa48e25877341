// Post-stabilization of one island (docs/MATH.md Q13, Q14; Cline & Pai, ICRA 2003).
//
//   (Q13) positions:  K = J M⁻¹ Jᵀ + ε s I,  K λ = −C,  Δx_b = M_b⁻¹ J_bᵀ λ  (linear: x ← x + Δx; angular:
//                     q ← normalize(q + ½ Δθ ⊗ q), Δθ a world-frame rotation), repeated until ‖C‖ is at tolerance.
//   (Q14) velocities: K λ = −J v at the projected positions,  v ← v + M⁻¹ Jᵀ λ, so that J v = 0.
// J = ∂C/∂(v_A, ω_A, v_B, ω_B) from btQuaternionHingeConstraint::computePositionRows, or PointRows.h for a point
// constraint (world frame): the same matrix maps a small displacement (Δx, Δθ) to ΔC, which is what Newton needs.
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
// (HingeAngle.h). Position stage: once α is found past a stop in this step, the row is the equation α = stop, until a
// solve's λ pulls while the joint is inside the stop (docs/MATH.md, "One-sided rows in Q13"; releasePullingLimits):
// then it is out, and back only if an accepted step crosses the stop again, for the rest of the step.
// Velocity stage: α̇ = 0 only if the stop was violated this step and α̇ still points past it (decided once, before
// the first solve); a limit row K has and the velocities leave out is taken out by solves with K's factors
// (IslandSystem.h, solveDeltasWithoutDroppedRows), not by a new factorization. A Newton step that takes a joint past
// a stop K does not have is kept unless the residual (which counts the new row) grew by more than kActiveSetGrowth.
// s = trace(K)/(active rows); ε s on the diagonal keeps K positive definite with redundant rows (closed loops); a
// padding or inactive limit row gets s on its diagonal and a zero right-hand side, so its λ is 0.
// Units: C in m (linear rows) and rad (angular, limit); λ in kg·m (linear) and kg·m²·rad (angular).
//
// This file: the two stages of one island's step and the choices between them (when to factorize, which metric).
// The pieces they use: IslandRows.h (C, J, J v and the residuals), IslandSystem.h (K, its factorization, the solves),
// IslandBodies.h (M⁻¹ in each metric, moving the bodies).
#include "IslandBodies.h"
#include "IslandContacts.h"
#include "IslandRows.h"
#include "IslandSystem.h"
#include "StabilizerIsland.h"

#include "BulletDynamics/Dynamics/btRigidBody.h"

#include <algorithm>
#include <cmath>

namespace quathinge
{
namespace stabilizer
{
namespace
{
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

// A Newton step that takes a joint past a stop (or a contact into the ground) that K did not have is kept while the
// normalized residual, which then counts the new row, grows by no more than this factor.
const btScalar kActiveSetGrowth = btScalar(4);
// Halvings of a Newton step that made ‖C‖ worse before it is undone.
const int kMaxHalvings = 2;
// Slow progress within this factor of the rounding floor (normalized residual) ends the iterations.
const btScalar kNearFloor = 4;
// Velocity solves per step: a chord solve or two, then an exact one if they stall.
const int kMaxVelocitySolves = 3;
// Rounds of taking out contact rows that pull (IslandContacts.h) after one solve, each with a factorization.
const int kMaxContactReleases = 4;

// One island's step: the position stage (Q13), then the velocity stage (Q14), sharing the factorization of K and
// what the first stage did (which metric it ended in, whether it already projected the velocities).
template <int R>
struct IslandStep
{
	BlockIsland<R>& island;
	const ProjectionSettings& settings;
	ProjectionResult result;
	// How far the bodies moved since K was factorized (m or rad); infinite: no factorization yet.
	double factorAge = SIMD_INFINITY;
	// The position stage projected the velocities with one of its factorizations (projectVelocitiesExactly).
	bool velocitiesProjected = false;
	// The factorization held is of K in the mass metric M (the velocity stage's), not the weighted one.
	bool factorInM = false;
	// JointBlock::leftover holds this step's C_r (recordLeftover).
	bool leftoverRecorded = false;
	// The contact rows taken out for the rest of the step by projectPositions' fallback: 0 none, 1 the pair slots'
	// (contacts between island bodies), 2 all.
	int contactsDropped = 0;

	IslandStep(BlockIsland<R>& i, const ProjectionSettings& s) : island(i), settings(s)
	{
		island.stiffMetric = false;
		island.rotationWeight = settings.positions ? settings.rotationWeight : 1;
		findReferenceMass(island);
		loadInverseMasses(island);
		for (JointSlot& js : island.joints)
		{
			js.limitTouched = 0;
			js.limitReleased = false;
			js.limitActive = js.limitActiveInFactor = false;  // js.angleReference: readAngleReferences
			js.contactTouched = js.contactReleased = js.contactReleasedTwice = js.contactActiveInFactor = 0;
			js.contactFloorSet = false;
		}
	}

	bool factorize()
	{
		factorInM = false;
		if (!refactorize(island, settings.regularization, result)) return false;
		factorAge = 0;
		factorInM = positionMetricIsM();
		return true;
	}
	// Switches the position correction to the stiff metric (loadInverseMass) for the rest of the step; false if it is
	// on already.
	bool useStiffMetric()
	{
		if (island.stiffMetric) return false;
		island.stiffMetric = true;
		loadInverseMasses(island);
		++result.metricSwitches;
		return true;
	}
	// The position stage works in M itself (its factorization can serve the velocities too).
	bool positionMetricIsM() const { return !island.stiffMetric && island.rotationWeight == 1; }
	// Back to M (the velocity projection's metric, Q14); the current factorization is of the other metric.
	void useMassMetric()
	{
		island.stiffMetric = false;
		island.rotationWeight = 1;
		loadInverseMasses(island);
		factorAge = SIMD_INFINITY;
	}
	// Q14 with the factorization just made (exact): J v = 0 at the current positions. Limit rows of K that the
	// velocities leave out (a stop no longer pushed into) are taken out by solves (solveVelocityDeltas); when that
	// cannot be done, nothing is projected here and the velocity stage does it.
	void projectVelocitiesExactly()
	{
		const VelocityResidual vres = evaluateVelocities(island, true, settings.timeStep);
		result.velocityResidualBefore = result.velocityResidualAfter = vres.max;
		if (vres.normalized <= 1)
		{
			velocitiesProjected = true;
			return;
		}
		if (!solveVelocityDeltas(island, vres.limitsChanged, result)) return;
		// a contact row that would hold its body down (λ < 0) is the velocity stage's to take out (its K differs)
		if (pullingContact()) return;
		velocitiesProjected = true;
		changeVelocities(island);
	}

	// keepEnergyAndMomentum (IslandInvariants.h, docs/ENERGY.md Q16): the solver's leftover in C at the step's start.
	// With C(x₀) ≈ h r + ½h² vᵀ∇²C v and J(x₀) v ≈ r + h vᵀ∇²C v (r the solver's velocity residual, C closed by the last
	// call), the curvature's part is h J(x₀) v − C(x₀) and the leftover's C_r = h r = 2 C(x₀) − h J(x₀) v. Before the
	// first Newton step (C and J are the start's).
	void recordLeftover()
	{
		const double h = settings.timeStep;
		for (size_t j = 0; j < island.joints.size(); ++j)
		{
			const JointSlot& js = island.joints[j];
			Eigen::Matrix<double, 12, 1> u = Eigen::Matrix<double, 12, 1>::Zero();
			for (int side = 0; side < 2; ++side)
			{
				const btRigidBody* body = js.body[side] >= 0 ? island.bodies[js.body[side]].rigid : js.rigid[side];
				if (!body) continue;
				const btVector3& v = body->getLinearVelocity();
				const btVector3& w = body->getAngularVelocity();
				u.segment<3>(6 * side) << double(v.x()), double(v.y()), double(v.z());
				u.segment<3>(6 * side + 3) << double(w.x()), double(w.y()), double(w.z());
			}
			JointBlock<R>& jb = island.blocks[j];
			jb.leftover = 2 * jb.c - h * (jb.jacobian * u);
		}
		leftoverRecorded = true;
	}

	// (Q16) What the solver's leftover r did in Bullet's step, in the mass metric M with the velocity stage's
	// factorization (one solve, after it; not measured without one): Bullet's impulse fell short by δλ, the bodies got
	// δv = M⁻¹Jᵀδλ more (J δv = r; kinetic energy ½ rᵀK⁻¹r = ½ C_rᵀK⁻¹C_r / h²) and moved h δv, whose undoing
	// (Δx_r, Δθ_r) = M⁻¹JᵀK⁻¹(−C_r) takes the work −Σ (F·Δx_r + τ·Δθ_r) of the step's forces (Q15: each body's total
	// force and torque, gravity's and the app's). Uses λ and the deltas as scratch.
	void measureLeftover()
	{
		if (!leftoverRecorded || !factorInM) return;
		const double h = settings.timeStep;
		for (size_t j = 0; j < island.joints.size(); ++j) island.lambda[j] = -island.blocks[j].leftover;
		if (island.useSparse) island.sparse->template solve<R>(island.lambda.data());
		else island.block.solve(island.k, island.lambda.data());
		accumulateDeltas(island);
		double lift = 0, kinetic = 0;
		for (const IslandBody& b : island.bodies)
		{
			// the work of the step's external force and torque (gravity's and the app's: Q15) on the move Δx_r, Δθ_r
			const btVector3& f = b.rigid->getTotalForce();
			const btVector3& t = b.rigid->getTotalTorque();
			for (int k = 0; k < 3; ++k) lift -= double(f[k]) * b.delta[k] + double(t[k]) * b.delta[3 + k];
		}
		for (size_t j = 0; j < island.joints.size(); ++j)
			kinetic -= island.blocks[j].leftover.template head<R>().dot(island.lambda[j].template head<R>());
		result.leftoverLift = lift;
		result.leftoverKinetic = 0.5 * kinetic / (h * h);
	}

	// Some contact row in the system pulls in the last solve and would be taken out (IslandContacts.h).
	bool pullingContact() const
	{
		if (island.contacts.empty()) return false;
		for (size_t j = 0; j < island.joints.size(); ++j)
			if (island.joints[j].contact >= 0 && pullingContactRows(island, j) != 0) return true;
		return false;
	}
	// The position stage's limit rows that pull in the last solve (λ·limitTouched < 0: the row would hold its joint
	// at a stop it is inside) are taken out, until an accepted step crosses that stop again (evaluatePositions;
	// docs/MATH.md, "One-sided rows in Q13"). Only a row inside by more than the island's largest |C| over its other
	// rows (or the row's threshold): closer, the row is at its stop to within what this step moves (measured in
	// double, a chain of limited 6-dof balls: rows 1e-5 rad inside with the pose 2.4e-5 from converged, taken out,
	// were crossed again by the next step, which was undone, and the step ended at 2.1e-5).
	bool releasePullingLimits()
	{
		double margin = -1;  // m or rad; found when a row that pulls asks for it
		auto otherRowsError = [&] {
			if (margin < 0)
				for (size_t j = 0; j < island.joints.size(); ++j)
				{
					const JointSlot& js = island.joints[j];
					const int rows = js.limitSlot ? js.bilateralRows : R;  // the joint's own rows, or a contact slot's
					for (int r = 0; r < rows; ++r) margin = std::max(margin, std::fabs(island.blocks[j].c[r]));
				}
			return margin;
		};
		bool released = false;
		for (size_t j = 0; j < island.joints.size(); ++j)
		{
			JointSlot& js = island.joints[j];
			// a row taken out once and back (its stop crossed again in an accepted step) stays: no cycling
			if (!js.limitSlot || js.limitTouched == 0 || js.held || js.limitReleased) continue;
			const int r = js.bilateralRows;
			const double inside = js.limitTouched * island.blocks[j].c[r];  // how far inside its stop (m or rad)
			const btScalar threshold = js.limitLinear() ? js.linearThreshold : js.angularThreshold;
			if (js.limitTouched * island.lambda[j][r] >= 0 || inside <= std::max(double(threshold), otherRowsError()))
				continue;
			js.limitTouched = 0;
			js.limitReleased = true;
			js.limitActive = false;
			island.blocks[j].jacobian.row(r).setZero();
			island.blocks[j].c[r] = 0;
			++result.limitReleases;
			released = true;
		}
		return released;
	}
	// Puts the bodies back where the last step started (a step halved or undone), with the limit rows taken out
	// because they pulled there out again: a step that took such a row back in (it crossed the stop again) is not
	// kept, and at the restored pose the row would pull again. Other limit rows a rejected step brought in stay: the
	// next factorization has them (and the push-only test takes out those that pull; taking them out with the pose
	// failed a 6-dof hinge on aarch64, whose next step crossed the same stop again: CHANGELOG). The contact rows are
	// those of the restored pose (contactSaved): measured, a pile of RagdollDemo ragdolls with projectConeTwistLimits
	// kept its hinges to 1e-5 m only so.
	void restorePositions()
	{
		restoreTransforms(island);
		for (JointSlot& js : island.joints)
		{
			if (js.limitReleased) js.limitTouched = 0;
			js.contactTouched = js.contactSaved;
		}
	}
	// After a solve with rhs: the rows that pull are taken out and the solve repeated, until none pulls (at most
	// kMaxContactReleases times). With `limits` (the position stage), limit rows first, by solves with K's factors
	// (solveDeltasWithoutDroppedRows; a contact can pull only because a limit row that pulls holds its limb); contact
	// rows with a new factorization. `refactorized` says whether one was made. False if a factorization failed.
	bool solveAgainWithoutPullingRows(BlockVector<R> JointBlock<R>::*rhs, bool limits, bool* refactorized = nullptr)
	{
		for (int k = 0; k < kMaxContactReleases; ++k)
		{
			const bool limitsOut = limits && releasePullingLimits();
			const bool contactsOut = !limitsOut && !island.contacts.empty() && releasePullingContacts(island);
			if (!limitsOut && !contactsOut) break;
			if (!contactsOut && solveDeltasWithoutDroppedRows(island, rhs, result)) continue;
			if (refactorized) *refactorized = true;
			if (!factorize()) return false;
			solveDeltas(island, rhs, result);
		}
		return true;
	}
	// Keeps the bodies' transforms for backtracking (saveTransforms), and the contact rows in the system with them
	// (restorePositions puts both back).
	void savePositions()
	{
		saveTransforms(island);
		for (JointSlot& js : island.joints) js.contactSaved = js.contactTouched;
	}

	// (Q13) Newton on C = 0, ending in M with the bodies' inertia refreshed.
	void projectPositions()
	{
		PositionResidual res = evaluatePositions(island, settings.tolerance);
		result.residualBefore = res.max();
		if (settings.positions)
		{
			bool chordStalled = false;
			// Newton steps that grew the active set and were kept (below) are not counted against maxIterations, up to
			// maxIterations of them: a row enters at most twice a step (limits: after a release; contacts: back below
			// their start depth), and a landing's rows can take every counted iteration (measured on aarch64: a pile of
			// RagdollDemo ragdolls ended a step at maxIterations with its joints 2.1e-5 m apart).
			int growthSteps = 0;
			while (res.normalized > 1 && result.iterations - growthSteps < settings.maxIterations)
			{
				const bool factorNow = chordStalled || factorAge > kChordAge || res.limitsChanged;
				if (factorNow)
				{
					if (!factorize()) break;
					if (settings.measureLeftover && result.iterations == 0) recordLeftover();
					chordStalled = false;
					// After the first Newton step the bodies only move by the small rest of the correction: project the
					// velocities now, with this factorization, and only touch them up at the final positions below
					// (one factorization fewer than projecting them there from scratch). Not in another metric than M.
					if (settings.velocities && !velocitiesProjected && result.iterations > 0 && positionMetricIsM())
						projectVelocitiesExactly();
				}
				else
					computeDirections(island);  // chord step: the factorized K, the current J
				solveDeltas(island, &JointBlock<R>::c, result);
				if (!solveAgainWithoutPullingRows(&JointBlock<R>::c, true)) break;
				savePositions();
				const PositionResidual start = res;
				double step = 1;
				factorAge += movePositions(island, step);
				++result.iterations;
				res = evaluatePositions(island, settings.tolerance);
				// The step took a joint past a stop that K did not have (the active set grew): the residual now counts
				// that new row, so it is no measure of the step (a correct step measured "worse" here was halved, undone
				// and retried in the stiff metric, and could end the loop unconverged). Keep it; the next iteration
				// factorizes with the row. A row enters at most twice within a step (once more after it pulled and was
				// taken out), and such steps are not counted against maxIterations (growthSteps). Not a step that made
				// ‖C‖ grow by more than kActiveSetGrowth: a correct step adds about its own length at the new stop,
				// while one that grows it more has left the linearization behind (a ragdoll's contact rows
				// with a nearly singular K, double: a first step from 0.09 to 22 m; kept, Newton then converged to a pose
				// with a leg 0.56 m into the ground); it is halved and undone as any step that makes ‖C‖ worse.
				if (res.limitsChanged && res.normalized <= kActiveSetGrowth * start.normalized)
				{
					if (growthSteps < settings.maxIterations) ++growthSteps;
					continue;
				}
				// Backtracking: a step that makes ‖C‖ worse (far from the solution in a nearly singular pose, e.g. a taut
				// chain, the linearization overshoots) is halved, at most kMaxHalvings times, else undone.
				for (int halving = 0; res.normalized >= start.normalized && halving < kMaxHalvings; ++halving)
				{
					step *= 0.5;
					restorePositions();
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
					restorePositions();
					res = evaluatePositions(island, settings.tolerance);  // the rows at the restored positions
					// No step along this Newton direction helps. The mass metric's direction can be the culprit (a
					// nearly straight chain of light links under a heavy load: bending them is cheap to first order and
					// useless to second); retry once with the stiff metric, else leave the positions as they were.
					if (factorNow && !useStiffMetric())
					{
						// Neither metric helps. With contact rows in the system they are the likely cause: up to four
						// points of a pair, each held as an equation, whose depths no rigid move meets (measured: a
						// ragdoll's first step 0.09 → 22 m). First the contacts between island bodies (a pair slot
						// closes a loop, and a limb 8 cm into another behind joints at their stops cannot be met:
						// measured, λ ~1e6 and a first step of 117 m), then, if that does not help either, all: the
						// joints alone, as without projectContacts.
						if (contactsDropped == 0 && releaseContactSlots(island, ContactSlots::Pairs))
							contactsDropped = 1;
						else if (contactsDropped < 2 && releaseContactSlots(island, ContactSlots::All))
							contactsDropped = 2;
						else
							break;
						res = evaluatePositions(island, settings.tolerance);
					}
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
		{
			if (js.limitTouched != 0) ++result.activeLimitRows;
			for (unsigned rows = js.contactTouched; rows != 0; rows &= rows - 1) ++result.contactRows;
		}
	}

	// (Q14) J v = 0 at the final positions.
	void projectVelocities()
	{
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
			// The last solve allowed uses a fresh factorization if none was made here. Limit rows that K has and the
			// velocities leave out are taken out by solves with its factors (solveVelocityDeltas).
			bool factorNow = chordStalled || factorAge > (velocitiesProjected ? kTouchUpAge : kChordAge) ||
							 (solve == kMaxVelocitySolves - 1 && !factorizedHere);
			if (!factorNow)
			{
				computeDirections(island);
				factorNow = !solveVelocityDeltas(island, vres.limitsChanged, result);
			}
			if (factorNow)
			{
				if (!factorize()) break;
				factorizedHere = true;
				solveDeltas(island, &JointBlock<R>::jv, result);
			}
			bool refactorized = false;
			if (!solveAgainWithoutPullingRows(&JointBlock<R>::jv, false, &refactorized)) break;
			if (refactorized) factorNow = factorizedHere = true;
			changeVelocities(island);
			const btScalar previous = vres.normalized;
			vres = evaluateVelocities(island, false, settings.timeStep);
			result.velocityResidualAfter = vres.max;
			chordStalled = vres.normalized > kVelocityChordProgress * previous;
			if (factorNow && chordStalled) break;  // a fresh factorization that gains little: what is left is rounding
		}
	}
};

template <int R>
ProjectionResult projectBlocks(BlockIsland<R>& island, const ProjectionSettings& settings)
{
	IslandStep<R> step(island, settings);
	step.projectPositions();
	if (settings.velocities) step.projectVelocities();
	if (settings.measureLeftover) step.measureLeftover();
	return step.result;
}
}  // namespace

void readAngleReferences(Island& island)
{
	for (JointSlot& js : island.joints)
	{
		if (js.frameHinge)
		{
			// its frames and limit as they are now (the kind, a 6-dof's shape and the limit's ability to act are in the
			// signature)
			refreshFrameHinge(*js.frameHinge, js.hinge);
			if (!js.limitSlot) continue;
			const btTransform& tA = js.rigid[0]->getCenterOfMassTransform();
			js.angleReference = frameHingeLimitVariable(*js.frameHinge, js.hinge, tA, js.rigid[1]->getCenterOfMassTransform());
			js.held = js.hinge.driven;
			// a slot for a drive alone: stops that are never met
			js.lowerStop = js.hinge.limit ? js.hinge.low : -SIMD_INFINITY;
			js.upperStop = js.hinge.limit ? js.hinge.high : SIMD_INFINITY;
			continue;
		}
		if (!js.limitSlot) continue;
		if (js.locked)  // a locked 6-dof's limited axis (LockedRows.h): its stops (never held; its variable comes with its rows)
		{
			const DofLocks k = dofLocks(*js.locked);
			js.angleReference = 0;
			js.lowerStop = k.low[js.limitAxis];
			js.upperStop = k.high[js.limitAxis];
			continue;
		}
		if (js.point)  // a cone twist's swing or twist (ConeTwistRows.h): its stops
		{
			// (a cone's limit row is never held, so nothing reads a reference: its variable comes with its rows)
			const ConeLimits k = coneLimits(*static_cast<const btConeTwistConstraint*>(js.point));
			js.angleReference = 0;
			js.lowerStop = js.limitOnly ? -k.twistSpan : -SIMD_INFINITY;
			js.upperStop = js.limitOnly ? k.twistSpan : 0;
			continue;
		}
		js.angleReference = js.joint->getMultiTurnAngle();
		js.lowerStop = js.joint->getLowerLimit();
		js.upperStop = js.joint->getUpperLimit();
	}
}

ProjectionResult projectIsland(Island& island, const ProjectionSettings& settings)
{
	if (island.blockRows == 5) return projectBlocks(static_cast<BlockIsland<5>&>(island), settings);
	return projectBlocks(static_cast<BlockIsland<6>&>(island), settings);
}

}  // namespace stabilizer
}  // namespace quathinge
