// The forces a Bullet app applies, on small chains (tests/test_stabilizer_forces.cpp; docs/ENERGY.md, "Under an
// app's forces"): a push, an app spring, gravity switched, damping, a kinematic driver, a motor burst, a free tumbling
// chain, heavy tips. Each scene runs with the stabilizer's defaults (quaternion hinges), with bare quaternion hinges,
// or with stock btHingeConstraint and no stabilizer (the 1 kHz reference), and records its energy at every step.
#ifndef QUATHINGE_TESTS_FORCE_SCENES_H
#define QUATHINGE_TESTS_FORCE_SCENES_H

#include "support/StabilizerScene.h"

#include <functional>
#include <vector>

namespace qh_test
{
enum class ForceKind
{
	Stabilized,             // quaternion hinges and btQuaternionHingeStabilizer with its defaults
	StabilizedInvalidated,  // the same, the app calling invalidateStructure() before every step
	Bare,                   // quaternion hinges alone
	Stock                   // btHingeConstraint alone (stock Bullet)
};

/// A chain of `links` boxes 0.5 m long, 0.1 m square, 1 kg (the last `lastMass`), the first hinged to `anchor` (a
/// static or kinematic body at (0, 10, 0)), or free (no anchor) in zero gravity.
struct ForceChain
{
	int links = 3;
	double lastMass = 1;
	bool hanging = false;    // along −y from the pivot (at rest), else along +x (released horizontally)
	bool planar = false;     // every axis z, else alternating z and (hanging: x; horizontal: y)
	bool free = false;       // no anchor, zero gravity
	bool kinematic = false;  // the anchor is a kinematic body the scene moves
	double damping = 0;      // linear and angular damping of every link
	double gravity = 10;     // m/s² along −y
	bool gyroscopic = true;  // Bullet's implicit gyroscopic step on every link (its default), else the flag cleared
};

/// One run's record: the energy after every step (J; kinetic + gravity's potential above the chain's lowest reach,
/// with the gravity then, + the app spring's), the largest pivot separation (m) and the angular momentum drift.
struct ForceRecord
{
	std::vector<double> energy;
	double hz = 60;
	double maxSeparation = 0;   // m (quaternion hinges)
	double angularDrift = 0;    // max |L − L₀| / |L₀| (a free chain)
	double linearMomentum = 0;  // max |P − P₀| (kg·m/s, a free chain)
	double guardTrip = -1;      // s: the end of the first step whose stabilizer guarded an island (−1: none)
	bool finite = true;
	/// The mean energy over [t0, t1) s.
	double mean(double t0, double t1) const;
};

/// What the scene does before each step (t: the step's start, s): forces, gravity, the driver. `links` the chain's
/// bodies, `anchor` its anchor (null when free).
struct ForceHooks
{
	std::function<void(StabilizerScene&, const std::vector<btRigidBody*>& links, btRigidBody* anchor,
					   std::vector<btTypedConstraint*>& joints, double t, double h)>
		before;
	/// Energy not in the chain's kinetic and gravity terms (an app spring's potential), J.
	std::function<double(const std::vector<btRigidBody*>& links)> extraEnergy;
	/// Sets the free chain's initial velocities.
	std::function<void(const std::vector<btRigidBody*>& links)> start;
};

ForceRecord runForceChain(const ForceChain& chain, const ForceHooks& hooks, ForceKind kind, double hz, double seconds);

/// A body's kinetic energy (J).
double kineticEnergy(const btRigidBody& b);
}  // namespace qh_test

#endif
