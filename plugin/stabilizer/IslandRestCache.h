// An island at rest gets the last step's projection back (issue 15, "leave out").
//
// The projection (Q13, Q14: IslandProjection.cpp) is a deterministic function of what it reads: the island bodies'
// poses, velocities, masses, inertias, linear/angular factors, gravity and contact flags, the fixed partners' poses and
// velocities, each joint's frames, flags, limit and multi-turn angle, the step and the stabilizer's settings. A chain
// hanging still under Bullet's solver reaches a fixed point to the bit: the solver, which does not warm-start joint
// rows, lets it sag by the same amount every step (measured on 50 chains of 10 links at 60 Hz: 9.8e-4 m and 5.9e-2 m/s,
// every step), and the projection lifts it back to the same state. A chain folded against its stops (or a body
// hanging at a slider's stop) reaches a cycle of a few states instead: Bullet's stop rows and the projection go round
// them to the bit (measured: two states on x86-64 Linux and aarch64, six under MinGW-w64, where one of two such
// chains rests and the other bounces on its stops at 0.14 m/s; the bare world there reaches a fixed point). So the
// last kRestStates (8) projections are kept: when every one of those inputs equals, bit for bit, what the projection
// read at the start of one of the last 8 steps, its result is that step's: it is applied as the projection applied
// it (the same poses, the same inertia refresh, the same velocities) without a factorization, a row or a solve.
// Exact by construction — nothing is approximated and nothing that moves, however slowly, is held (any changed bit runs
// the projection). The check reads about 30 numbers per body and per joint; nothing is allocated after the
// island's first step.
#ifndef QUATHINGE_STABILIZER_ISLAND_REST_CACHE_H
#define QUATHINGE_STABILIZER_ISLAND_REST_CACHE_H

#include "StabilizerIsland.h"

namespace quathinge
{
namespace stabilizer
{
/// If `island` starts this step exactly as it started one of the last kRestStates steps, applies that projection's
/// result to its bodies, sets `result` to it (its work counters zero) and returns true. Else keeps this step's inputs
/// (in place of the oldest kept) for rememberProjection and returns false. The joints' angle references must be
/// this step's (readAngleReferences).
bool replayIfAtRest(Island& island, btScalar timeStep, ProjectionResult& result);
/// After a projection of `island` (replayIfAtRest returned false): keeps its result for the next kRestStates steps.
void rememberProjection(Island& island, const ProjectionResult& result);
/// Forgets every island's kept result (the settings changed).
void forgetProjection(Island& island);
}  // namespace stabilizer
}  // namespace quathinge

#endif
