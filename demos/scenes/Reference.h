// The common reference trajectory of a scene (docs/PEERS.md): one run that every kind's trajectory error is measured
// against, made in double precision (the double build's quathinge-compare --write-reference) at a step so small that
// halving it changes the trajectory by less than the figures report, and judged only over a horizon shorter than the
// time in which two references started 1e-9 apart grow kDivergenceThreshold apart (chaos, not error, beyond it).
// For trees the reference is btMultiBody (reduced coordinates: no joint drift) without damping; for loops a
// maximal-coordinate kind at many iterations (kLoopReferenceKind). The float runs read it from the file
// (RunSettings::referenceFile).
#ifndef QUATHINGE_REFERENCE_H
#define QUATHINGE_REFERENCE_H

#include "JointKinds.h"
#include "SceneSpec.h"

#include <string>
#include <vector>

namespace quathinge
{
namespace scenes
{
/// Two references are "diverged" once their bodies' positions are this far apart (m, RMS over bodies): a 1e-9 start
/// grown a thousandfold.
constexpr double kDivergenceThreshold = 1e-6;
/// The rotation (rad) of the whole start state about the first joint's axis that starts the second reference apart.
constexpr double kDivergenceKick = 1e-9;
/// The reference's own step (s) and solver iterations (limits, motors, loop closures), and its sample interval (s):
/// every kind at 60, 120, 240 and 480 Hz lands on it.
constexpr double kReferenceStep = 1.0 / 15360;
constexpr int kReferenceIterations = 100;
constexpr double kReferenceSample = 1.0 / 60;
/// The reference's joint-rate clamp (rad/s, btMultiBody::setMaxCoordinateVelocity): lifted from btMultiBody's 100.
constexpr double kReferenceMaxCoordinateVelocity = 1e6;
/// The horizon also ends before the reference and its half-step run are this far apart (m, RMS over bodies): beyond
/// it the reference is not converged at the figures' digits.
constexpr double kHalvingTolerance = 1e-4;
/// The reference of a scene with a loop (no reduced-coordinate tree): the stock hinge at kReferenceIterations.
constexpr Kind kLoopReferenceKind = Kind::Stock;

struct ReferenceTrajectory
{
	std::string scene, kind, precision;
	double step = 0;  ///< s
	int iterations = 0;
	double sampleDt = 0;                       ///< s between samples; sample k (from 1) is at k·sampleDt
	double horizon = 0;                        ///< s over which the trajectory error is judged
	double halvingChange = -1;                 ///< m: the largest distance over the horizon between this run and one at step/2
	double divergenceTime = -1;                ///< s when the kicked run is kDivergenceThreshold away; −1: not within the run
	double halvingTime = -1;                   ///< s when the half-step run is kHalvingTolerance away; −1: not within the run
	std::vector<std::vector<double>> samples;  ///< per sample: x y z of every body, in scene order
};

/// The reference kind of a scene: MultiBody for a tree it can build (no loop, no misaligned start, no file), else
/// kLoopReferenceKind.
Kind referenceKindOf(const SceneSpec& scene);
/// The scene with its whole start state (poses, velocities, joint pivots and axes) turned by `radians` about its
/// first joint's axis through its pivot; gravity unturned. Joints stay assembled.
SceneSpec kickedScene(const SceneSpec& scene, double radians);
/// Runs `scene` with `kind` (multibody: kReferenceMaxCoordinateVelocity) at `step` and `iterations` for `duration` s, sampling every body's position every
/// `sampleDt` (an integer number of steps). Throws std::runtime_error when the kind cannot build the scene.
ReferenceTrajectory recordTrajectory(const SceneSpec& scene, Kind kind, double step, int iterations, double sampleDt,
									 double duration);
/// The largest RMS over bodies of the distance between a and b over their first `samples` samples (m).
double trajectoryDistance(const std::vector<std::vector<double>>& a, const std::vector<std::vector<double>>& b,
						  size_t samples);
/// The reference of a scene over `duration` s (≤ 0: the scene's): its reference kind at `step` and step/2, combined by
/// Richardson extrapolation (2 r(step/2) − r(step): the integrators are first order); the same from step/2 and step/4
/// (halvingChange); and a run at step/2 kicked by kDivergenceKick (divergenceTime). The horizon ends at the last sample
/// before the kicked run is kDivergenceThreshold from its twin or the half-step reference kHalvingTolerance away.
ReferenceTrajectory makeReference(const SceneSpec& scene, double step = kReferenceStep, double duration = -1);
void writeReference(const ReferenceTrajectory& reference, const std::string& path);
/// Throws std::runtime_error naming the file when it cannot be read.
ReferenceTrajectory readReference(const std::string& path);

}  // namespace scenes
}  // namespace quathinge

#endif
