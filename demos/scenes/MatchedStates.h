// Matched states: two joint kinds compared step by step from the same state, so that the comparison is of the
// rows, not of the trajectories they lead to (docs/ROW_BASIS.md, "Matched states"). A free run of each kind measures
// both at once: a chaotic scene, or one where one kind keeps more of the motion's energy, takes each kind to
// different states, and a joint's error depends on the state (how fast it whips, what load it carries).
#ifndef QUATHINGE_MATCHED_STATES_H
#define QUATHINGE_MATCHED_STATES_H

#include "JointKinds.h"
#include "SceneSpec.h"
#include "Simulation.h"

#include <functional>

namespace quathinge
{
namespace scenes
{
/// Joint errors of both kinds over a matched run (runScene's measures: JointErrorStats, Simulation.h).
struct MatchedRun
{
	JointErrorStats leader;    ///< the leading kind's free run
	JointErrorStats follower;  ///< the following kind, each step taken from the leader's state before that step
	int steps = 0;             ///< steps run (fewer than asked after a blow-up)
	bool blewUp = false;       ///< a body of either world became non-finite or far-flung (Simulation::finiteAndBounded)
	std::string skipped;       ///< why the scene could not run (then nothing else is set)
};

/// Runs the scene with `leader` for its duration (or `duration` s when > 0) at steps of dt and `iterations` solver
/// iterations. Before each step, `follower`'s world gets every body's transform and velocities from the leader's
/// (its joints' own state — Bullet's rows start from zero every step — follows from those); then both step once and
/// both joints' errors are measured. `prepare` is called with each world once it is built (the sweep sets the
/// quaternion hinge's row basis there). Throws nothing: a scene a kind cannot build is reported in `skipped`.
MatchedRun runMatched(const SceneSpec& scene, Kind leader, Kind follower, double dt, int iterations, double duration,
					  const std::function<void(btDiscreteDynamicsWorld&)>& prepare = {});
}  // namespace scenes
}  // namespace quathinge

#endif
