// The projection does no work (docs/ENERGY.md, Q15–Q19; settings.keepEnergyAndMomentum).
//
// Ideal joints exert no power, so neither may their correction. Bullet has integrated the step (q, v) when the
// stabilizer runs; the projection moves the island to (q', v'). Per island, across that one call:
//   (Q15) E(q, v) = Σ_b ½ m_b |v_b|² + ½ ω_bᵀ I_b ω_b + V,  ΔV = −Σ_b (F_b·Δx_b + τ_b·Δθ_b)
//         (F_b, τ_b: the body's total force and torque for the step, getTotalForce/Torque: its gravity's m_b g_b and
//         the app's)
//   (Q16) T(v*) + ½h Σ F·v* = T(v) + ½h Σ F·v − ΔV + ½ΔV_r − T_r  (Σ F·v: Σ_b F_b·v_b + τ_b·ω_b)
//         Bullet's semi-implicit Euler step keeps E + ½h Σ m g·v but for the solver's leftover r (ΔV_r the potential
//         energy of its sag, T_r = ½ rᵀK⁻¹r its speed's kinetic energy; IslandProjection.cpp measures both)
// A free island (every row between two island bodies, nothing outside touching it, no restricted axes) also gets its
// linear momentum P and angular momentum L about its centre of mass back by a rigid velocity correction, which J v
// cannot see: a uniform velocity for P, its rigid spin scaled for L (Q17, Q18; L not when a constraint the stabilizer
// does not project ties it to other bodies); then only its deformation velocity (v' less its rigid motion,
// M-orthogonal to it) is scaled to T* (Q19). An island held by a fixed partner has no momentum invariant: v' is scaled as a whole. What Bullet's own
// step did (gravity, damping, motors, friction, contacts, limits, ERP, a push) is in (q, v) already: it is kept.
// Not restored: a step in which a one-sided row (a limit, a contact: their stop's work) was projected or a body touches
// something outside the island (a contact Bullet's solver works on), an island hung on a moving kinematic body (it
// does work). The guard holds the restoration back, in part or in full, on an island whose calls left, averaged, more
// energy than their goal (on that ledger alone: what the app and Bullet's step do between calls is not in it); it
// lets go as that average falls again. An island's guard history survives a rebuild of the islands (buildIslands).
#ifndef QUATHINGE_STABILIZER_ISLAND_INVARIANTS_H
#define QUATHINGE_STABILIZER_ISLAND_INVARIANTS_H

#include "StabilizerIsland.h"

#include <memory>

class btDynamicsWorld;

namespace quathinge
{
namespace stabilizer
{
/// What one restoration did (summed into btQuaternionHingeStabilizerStats).
struct InvariantResult
{
	bool momentumRestored = false;  // a free island's P and L were put back (Q17, Q18)
	bool energyRestored = false;    // the kinetic energy was set to T* (Q16, Q19)
	double scale = 1;               // the velocity scaling applied (Q19), 1 when none
};

/// Sets each island's Invariants::tied: an enabled constraint of the world that joins one of its bodies to a body
/// outside it (one the stabilizer does not project: a ragdoll's cone twist). Such an island is part of a larger free
/// system, and its own angular momentum is not put back (Q17). O(constraints).
void markTiedIslands(btDynamicsWorld& world, const IslandBodyMap& bodyOf, const Array<std::unique_ptr<Island>>& islands);

/// Records the island's energy, momentum and body positions before its projection (Island::invariants).
void recordInvariants(Island& island);

/// After the projection (result): restores what recordInvariants recorded, the energy only if restoreEnergy (the
/// velocities were projected). timeStep (s) paces the guard's average. Sets result.velocitiesRestored when it changed
/// the velocities (the rest cache replays them then).
InvariantResult restoreInvariants(Island& island, ProjectionResult& result, double timeStep, bool restoreEnergy);

/// An island hung on a fixed partner that moves (a kinematic body): its J v = 0 is not homogeneous.
bool hangsOnMovingBody(const Island& island);
}  // namespace stabilizer
}  // namespace quathinge

#endif
