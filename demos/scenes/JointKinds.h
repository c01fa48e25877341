// Joint kinds: what a Bullet user would pick for a hinge, each built from the same scene description, and the
// measured run of a scene with one kind. A new maximal-coordinate kind (another stabilizer: a btActionInterface
// added to the world; another constraint) is one more JointFactory (JointFactory.h) and one more name here; the
// scenes do not change.
#ifndef QUATHINGE_JOINT_KINDS_H
#define QUATHINGE_JOINT_KINDS_H

#include "SceneSpec.h"

#include <functional>
#include <string>
#include <vector>

class btDiscreteDynamicsWorld;

namespace quathinge
{
namespace scenes
{
enum class Kind
{
	Stock,                 ///< btHingeConstraint
	Generic6Dof2,          ///< btGeneric6DofSpring2Constraint with 5 locked axes
	Quaternion,            ///< btQuaternionHingeConstraint
	QuaternionStabilized,  ///< btQuaternionHingeConstraint + btQuaternionHingeStabilizer
	MultiBody,             ///< btMultiBody revolute joints (Featherstone, reduced coordinates): trees only
	/// QuaternionStabilized with the stabilizer's conserveEnergy option: for conservative scenes only (not among
	/// allKinds(): the energy table of demos/make_report.sh asks for it by name)
	QuaternionStabilizedEnergy,
	/// QuaternionStabilized with keepEnergyAndMomentum off: the projection's own damping (docs/ENERGY.md, "before";
	/// not among allKinds())
	QuaternionStabilizedDamped,
	StockStabilized,         ///< btHingeConstraint + btQuaternionHingeStabilizer (no class swapped)
	Generic6Dof2Stabilized,  ///< the 6dof2 kind's joints + btQuaternionHingeStabilizer (no class swapped)
	// The peers (docs/PEERS.md): Bullet's other solvers, and btMultiBody with its default damping. Not among allKinds().
	StockMLCP,        ///< btHingeConstraint, btMLCPSolver + btDantzigSolver (a direct solve; capped: kMlcpMaxRows)
	StockNNCG,        ///< btHingeConstraint, btNNCGConstraintSolver
	QuaternionMLCP,   ///< btQuaternionHingeConstraint, btMLCPSolver + btDantzigSolver
	QuaternionNNCG,   ///< btQuaternionHingeConstraint, btNNCGConstraintSolver
	MultiBodyDamped,  ///< MultiBody with btMultiBody's default linear and angular damping (0.04)
};
std::vector<Kind> allKinds();
/// The peers a Bullet user could pick instead (docs/PEERS.md), beside allKinds(): stock and the quaternion hinge
/// under btMLCPSolver (Dantzig) and btNNCGConstraintSolver, and the damped multibody.
std::vector<Kind> peerKinds();
std::string kindName(Kind kind);
/// One line per kind, "name  what it is" (quathinge-compare --help), in the order of kindCatalog().
std::string kindsHelp();
/// Which solver a kind's world runs (Simulation.cpp).
enum class SolverChoice
{
	SequentialImpulse,  ///< btSequentialImpulseConstraintSolver (the maximal-coordinate kinds' default)
	MLCPDantzig,        ///< btMLCPSolver with btDantzigSolver; falls back to sequential impulse when Dantzig fails
	NNCG,               ///< btNNCGConstraintSolver
	MultiBody           ///< btMultiBodyConstraintSolver in a btMultiBodyDynamicsWorld
};
SolverChoice solverOf(Kind kind);
/// Dantzig's cost grows as n³ in the rows n of one solved group: the MLCP kinds refuse (skip, saying so) a scene
/// with more compared hinge rows than this (5 per hinge, 6 per slider).
constexpr int kMlcpMaxRows = 200;
/// btMultiBody's default damping (its constructor's linear and angular damping), which MultiBodyDamped keeps and
/// MultiBody sets to 0.
constexpr double kMultiBodyDefaultDamping = 0.04;
/// Throws std::invalid_argument naming the unknown kind.
Kind parseKind(const std::string& name);

struct MeasuredJoint;  // Simulation.h

struct RunSettings
{
	double dt = 1.0 / 60;   ///< s
	int iterations = 10;    ///< solver iterations
	double duration = -1;   ///< s; < 0: the scene's own
	bool reference = true;  ///< run the fine-step reference where the scene asks for one
	bool series = false;    ///< record time series
	int memoryEvery = 0;    ///< sample the process's resident memory every this many steps (soak runs); 0: never
	/// The fine-step reference from another quathinge-compare (the double-precision build's: float and double Bullet
	/// cannot live in one program): its path, and the arguments that make it build the same scene (scene name or URDF
	/// path, seed, models directory). Empty: the reference runs here, in this build's precision.
	std::string referenceExe;
	std::string sceneArgument, modelsDir;
	unsigned seed = 1;
	/// Called with the world once it is built, before the first step (the row-basis sweep sets the joints' basis
	/// there); not for the fine-step reference.
	std::function<void(btDiscreteDynamicsWorld&)> prepare;
	/// Called after every step with the measured joints (the sweep's swing-rate statistics); not for the reference.
	std::function<void(const std::vector<MeasuredJoint>&)> afterStep;
	/// A common reference trajectory (Reference.h, written by the double build's --write-reference): when set, the
	/// trajectory error is measured against it over its horizon instead of the fine-step reference.
	std::string referenceFile;
};

/// The fine-step reference trajectory: the scene with `kind` at dt/16 and 100 iterations, every body's position after
/// each of `steps` coarse steps of dt (what --dump-reference prints, one line per coarse step).
std::vector<std::vector<btVector3>> fineStepReference(const SceneSpec& scene, Kind kind, double dt, int steps);

struct SeriesPoint
{
	double t, separation, misalignmentDeg, energy;
};

/// A run "blows up" at the first step where a body's state is not finite, a body's centre of mass is farther than
/// kRunawayDistance from the origin or faster than kRunawaySpeed, or the total energy (kinetic + gravitational) exceeds
/// its start by more than kRunawayEnergyGain times the scene's energy scale. The energy scale (also the unit of
/// Metrics::energyDrift) is Σ m·max(|g|, kEnergyScaleGravity)·max(extent, 1 m) over the dynamic bodies (the potential
/// energy they could exchange across the scene; extent: the largest distance between two bodies at the start) plus
/// the initial kinetic energy. No drive, contact, spin or flipped start in the library gains more than 3× it
/// (maxEnergyGain in the report), so 10× is a runaway: joints spinning ever faster while they stay on their manifold
/// (undamped btMultiBody at 60 Hz on chain30 and the 1:100 load: docs/PEERS.md).
constexpr double kRunawayEnergyGain = 10;   ///< × energy scale
constexpr double kEnergyScaleGravity = 10;  ///< m/s², the least gravity the energy scale assumes
constexpr double kRunawaySpeed = 1e4;       ///< m/s, a body's centre of mass
constexpr double kRunawayDistance = 1e3;    ///< m from the origin

struct Metrics
{
	std::string scene, kind;
	double dt = 0;
	int iterations = 0;
	std::string skipped;            ///< why this scene × kind did not run (empty when it ran)
	double maxSeparation = 0;       ///< m, over joints and steps
	double rmsSeparation = 0;       ///< m
	double maxMisalignmentDeg = 0;  ///< degrees
	double rmsMisalignmentDeg = 0;  ///< degrees
	/// m, the prismatic joints' (SceneSpec::sliders: not compared, built alike by the maximal-coordinate kinds) largest
	/// distance off their slide line over joints and steps; −1 when the scene has none
	double maxSliderSeparation = -1;
	double energyDrift = -1;      ///< max |E − E₀| / energy scale; −1 when the scene is not conservative
	double trajectoryError = -1;  ///< m (fine-step reference) or relative (period); −1 when none
	std::string reference;        ///< which reference trajectoryError uses
	double recoveryTime = -1;     ///< s after which every joint's misalignment stays below 1°; −1 if never
	double limitViolation = -1;   ///< rad, worst excursion past a limit (θ from the frames); −1: no limits
	/// rad: Gazebo's out-of-plane angle, the largest |pitch| or |yaw| (ZYX Euler angles of a body's world
	/// orientation) over bodies and steps, for scenes that ask for it (SceneSpec::outOfPlaneBound); −1 otherwise
	double maxOutOfPlaneRad = -1;
	double finalTheta = 0;  ///< rad, the first joint's continuous θ at the end (from the frames)
	/// max (E − E₀) / energy scale over the run, every scene (drives and contacts included): what the runaway test reads
	double maxEnergyGain = 0;
	bool blewUp = false;          ///< non-finite or far-flung state, or a runaway (kRunawayEnergyGain)
	double blowUpTime = -1;       ///< s
	double wallPerSimSecond = 0;  ///< s of wall time per simulated second (the scene alone, no reference)
	double cpuPerSimSecond = 0;   ///< s of this thread's CPU time per simulated second (immune to other load)
	double rowsPerStep = 0;       ///< solver rows of the compared joints, mean per step
	int steps = 0;
	long rssFirstKb = -1;    ///< resident memory at the first sample (kB), soak runs
	long rssLastKb = -1;     ///< resident memory at the last sample (kB)
	int mlcpFallbacks = -1;  ///< btMLCPSolver::getNumFallbacks() at the end (MLCP kinds), else −1
	/// m, RunSettings::referenceFile's horizon: the largest RMS over bodies of |position − reference| at its samples
	double referenceError = -1;
	double referenceHorizon = -1;  ///< s
	std::vector<SeriesPoint> series;
};

/// Runs `scene` with `kind`. Never throws for a scene that cannot run with a kind: Metrics::skipped says why.
Metrics runScene(const SceneSpec& scene, Kind kind, const RunSettings& settings);

}  // namespace scenes
}  // namespace quathinge

#endif
