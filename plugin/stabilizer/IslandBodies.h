// The island's bodies as the projection sees and moves them (docs/MATH.md Q13, Q14): their inverse mass in the
// projection's metric (M, weighted, or stiff: IslandProjection.cpp), and their poses and velocities as Newton and
// the velocity projection change them.
#ifndef QUATHINGE_STABILIZER_ISLAND_BODIES_H
#define QUATHINGE_STABILIZER_ISLAND_BODIES_H

#include "StabilizerIsland.h"

namespace quathinge
{
namespace stabilizer
{
/// Loads every body's M⁻¹ in the island's current metric (IslandBody::invMass, invInertia).
void loadInverseMasses(Island& island);
/// The heaviest body's mass and largest principal inertia: the stiff metric's reference.
void findReferenceMass(Island& island);

/// Keeps every body's transform (IslandBody::saved) for backtracking; restoreTransforms puts them back.
void saveTransforms(Island& island);
void restoreTransforms(Island& island);
/// Applies step × the deltas as a position correction; returns the largest |Δx|∞ or |Δθ|∞ (m or rad).
double movePositions(Island& island, double step);
/// Refreshes Bullet's world inverse inertia of every body once the positions are final.
void finishPositions(Island& island);
/// Adds the deltas to the bodies' velocities (and their interpolation velocities).
void changeVelocities(Island& island);

}  // namespace stabilizer
}  // namespace quathinge

#endif
