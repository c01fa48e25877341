// btQuaternionHingeStabilizer's default keepEnergyAndMomentum: the projection does no work (docs/ENERGY.md, Q15–Q19).
// Independent references: the elliptic-integral period of a pendulum, the conservation of energy, linear and angular
// momentum of a free body system, and stock's own figures on the same scenes. One line of intent opens each test.
// Built when QuatHinge::Stabilizer is (QUATHINGE_HAVE_STABILIZER).
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/StabilizerScene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

using namespace qh_test;

namespace
{
const double kGravity = 10;  // m/s², StabilizerScene's

// K(k), the complete elliptic integral of the first kind: π / (2 AGM(1, √(1 − k²))) (converges quadratically).
double ellipticK(double k)
{
	double a = 1, b = std::sqrt(1 - k * k);
	for (int i = 0; i < 40 && std::fabs(a - b) > 1e-16 * a; ++i)
	{
		const double next = 0.5 * (a + b);
		b = std::sqrt(a * b);
		a = next;
	}
	return M_PI / (2 * a);
}

btQuaternionHingeStabilizerSettings stabilizerSettings(bool keep)
{
	btQuaternionHingeStabilizerSettings s;
	s.keepEnergyAndMomentum = keep;
	return s;
}

// A body's kinetic energy (J) and its gravity potential in StabilizerScene's gravity (J, zero at y = 0).
double kinetic(const btRigidBody& b)
{
	const btVector3 local = b.getCenterOfMassTransform().getBasis().transpose() * b.getAngularVelocity();
	const btVector3& inv = b.getInvInertiaDiagLocal();
	double e = 0.5 * double(b.getLinearVelocity().length2()) / double(b.getInvMass());
	for (int i = 0; i < 3; ++i) e += 0.5 * double(local[i]) * double(local[i]) / double(inv[i]);
	return e;
}

struct PendulumFigures
{
	double worstStep = 0;      // max |E − E₀| / (m g d) over the steps
	double worstSwing = 0;     // max |mean E over a swing − E₀| / (m g d) over the swings
	double periodError = 0;    // |T − T_exact| / T_exact over the first 10 periods
	double maxSeparation = 0;  // m
	int swings = 0;
};

// A 1 m bar of 1 kg (0.1 m square section) hinged at one end to the world (pivot at y = 10 m), released horizontally,
// `seconds` at `hz` (10 iterations), with the stabilizer's defaults (keepEnergyAndMomentum as asked). Period: from
// the zero crossings of the angle from the downward vertical, interpolated between steps; exact:
// 4 √(I/(m g d)) K(sin(θ₀/2)), θ₀ = 90°.
PendulumFigures swingBar(bool keep, double hz, double seconds)
{
	StabilizerScene scene;
	const double m = 1, d = 0.5, length = 1, side = 0.1;
	btRigidBody* bar = scene.box(btVector3(btScalar(length / 2), btScalar(side / 2), btScalar(side / 2)), btScalar(m),
								 btVector3(btScalar(d), 10, 0));
	scene.hingeToWorld(*bar, btVector3(btScalar(-d), 0, 0), btVector3(0, 0, 1));
	btQuaternionHingeStabilizer stabilizer(stabilizerSettings(keep));
	scene.addAction(&stabilizer);
	const double inertia = m / 12 * (length * length + side * side) + m * d * d;  // about the pivot
	const double exactPeriod = 4 * std::sqrt(inertia / (m * kGravity * d)) * ellipticK(std::sin(M_PI / 4));
	const double swingEnergy = m * kGravity * d;
	auto energy = [&] { return kinetic(*bar) + m * kGravity * double(bar->getCenterOfMassPosition().y()); };
	auto angle = [&] {
		const btVector3 c = bar->getCenterOfMassPosition();
		return std::atan2(double(c.x()), 10 - double(c.y()));
	};
	const double e0 = energy(), h = 1 / hz;
	PendulumFigures f;
	std::vector<double> crossings;
	double previousAngle = angle(), swingSum = 0;
	int swingSteps = 0;
	const int steps = int(std::lround(seconds * hz));
	for (int step = 1; step <= steps; ++step)
	{
		scene.world().stepSimulation(btScalar(h), 0, btScalar(h));
		const double a = angle(), drift = energy() - e0;
		f.worstStep = std::max(f.worstStep, std::fabs(drift) / swingEnergy);
		if ((previousAngle > 0) != (a > 0))
		{
			crossings.push_back((step - 1 + previousAngle / (previousAngle - a)) * h);
			if (crossings.size() >= 2 && swingSteps > 0)  // a whole swing since the last crossing
				f.worstSwing = std::max(f.worstSwing, std::fabs(swingSum / swingSteps) / swingEnergy), ++f.swings;
			swingSum = 0;
			swingSteps = 0;
		}
		swingSum += drift;
		++swingSteps;
		previousAngle = a;
		double separation, misalignment;
		scene.jointErrors(separation, misalignment);
		f.maxSeparation = std::max(f.maxSeparation, separation);
	}
	if (crossings.size() >= 21) f.periodError = std::fabs((crossings[20] - crossings[0]) / 10 - exactPeriod) / exactPeriod;
	else f.periodError = 1;  // fewer than 10 periods: the swing died
	return f;
}

// Drifts of a free system over a run: max over the steps of |X(t) − X(0)| / |X(0)|.
struct FreeFigures
{
	double momentum = 0, angularMomentum = 0, kineticEnergy = 0;
	double maxSeparation = 0;  // m
};

// Three links hinged end to end (axes z, y), in zero gravity, set spinning as one rigid body (ω = spinRate·(0.15, 0.25,
// 1) rad/s about their centre of mass, which moves at (0.2, 0.1, 0) m/s); 10 s at 60 Hz. Thin links: 1 m × 0.1 m × 0.1
// m; cube links: 0.5 m cubes. The spin is about no principal axis of the chain, so the hinges flex all along.
// withStabilizer false: the bare quaternion hinges (Bullet's integrator alone).
FreeFigures spinFreeChain(bool cubes, bool withStabilizer, bool keep, btScalar spinRate = 2)
{
	StabilizerScene scene;
	scene.world().setGravity(btVector3(0, 0, 0));
	const btScalar length = cubes ? btScalar(0.5) : btScalar(1), half = cubes ? btScalar(0.25) : btScalar(0.05);
	std::vector<btRigidBody*> links;
	for (int i = 0; i < 3; ++i)
	{
		btRigidBody* link = scene.box(btVector3(length / 2, half, half), 1, btVector3(length * btScalar(i), 0, 0));
		if (i > 0)
		{
			const btVector3 axis = i % 2 == 1 ? btVector3(0, 0, 1) : btVector3(0, 1, 0);
			scene.hinge(*links.back(), *link, btVector3(length / 2, 0, 0), btVector3(-length / 2, 0, 0), axis, axis);
		}
		links.push_back(link);
	}
	const btVector3 spin = spinRate * btVector3(btScalar(0.15), btScalar(0.25), 1), drift(btScalar(0.2), btScalar(0.1), 0), centre(length, 0, 0);
	for (btRigidBody* link : links)
	{
		link->setLinearVelocity(drift + spin.cross(link->getCenterOfMassPosition() - centre));
		link->setAngularVelocity(spin);
	}
	btQuaternionHingeStabilizer stabilizer;
	if (withStabilizer)
	{
		stabilizer.setSettings(stabilizerSettings(keep));
		scene.addAction(&stabilizer);
	}
	auto measure = [&](btVector3& p, btVector3& l, double& t) {
		btVector3 mx(0, 0, 0);
		p = l = btVector3(0, 0, 0);
		t = 0;
		for (btRigidBody* b : links)
		{
			p += b->getLinearVelocity() / b->getInvMass();
			mx += b->getCenterOfMassPosition() / b->getInvMass();
			t += kinetic(*b);
		}
		const btVector3 c = mx / btScalar(links.size());  // unit masses
		for (btRigidBody* b : links)
		{
			const btMatrix3x3& r = b->getCenterOfMassTransform().getBasis();
			const btVector3 local = r.transpose() * b->getAngularVelocity();
			const btVector3& inv = b->getInvInertiaDiagLocal();
			const btVector3 iw = r * btVector3(local.x() / inv.x(), local.y() / inv.y(), local.z() / inv.z());
			l += (b->getCenterOfMassPosition() - c).cross(b->getLinearVelocity() / b->getInvMass()) + iw;
		}
	};
	btVector3 p0, l0, p, l;
	double t0, t;
	measure(p0, l0, t0);
	FreeFigures f;
	for (int step = 0; step < 600; ++step)
	{
		scene.world().stepSimulation(kTimeStep, 0, kTimeStep);
		measure(p, l, t);
		f.momentum = std::max(f.momentum, double((p - p0).length() / p0.length()));
		f.angularMomentum = std::max(f.angularMomentum, double((l - l0).length() / l0.length()));
		f.kineticEnergy = std::max(f.kineticEnergy, std::fabs(t - t0) / t0);
		double separation, misalignment;
		scene.jointErrors(separation, misalignment);
		f.maxSeparation = std::max(f.maxSeparation, separation);
	}
	return f;
}
}  // namespace

TEST(StabilizerEnergy, ABarPendulumKeepsItsSwingEnergyAndPeriodAt60Hz)
{
	// A frictionless bar pendulum released at 90°, 60 s at 60 Hz: the projection does no work, so what is left is
	// Bullet's semi-implicit Euler, whose energy oscillates within a swing (about ±3% at 60 Hz) without drifting.
	const double kSwingTol = 0.01;   // of m g d: the energy averaged over each swing
	const double kStepTol = 0.05;    // of m g d: the energy at every step
	const double kPeriodTol = 1e-3;  // relative, the first 10 periods against the elliptic integral
	const PendulumFigures off = swingBar(false, 60, 60), on = swingBar(true, 60, 60);
	std::printf(
		"[ figures  ] bar pendulum 60 s at 60 Hz: worst swing-averaged energy %.3g (before %.3g) of m g d, worst "
		"step %.3g (before %.3g), period error %.3g (before %.3g), %d swings, max separation %.3g m\n",
		on.worstSwing, off.worstSwing, on.worstStep, off.worstStep, on.periodError, off.periodError, on.swings,
		on.maxSeparation);
	EXPECT_GE(on.swings, 60);  // it swings for the whole minute (each swing ≈ 0.93 s)
	EXPECT_LT(on.worstSwing, kSwingTol);
	EXPECT_LT(on.worstStep, kStepTol);
	EXPECT_LT(on.periodError, kPeriodTol);
	EXPECT_LT(on.maxSeparation, kSeparationTolerance);
}

TEST(StabilizerEnergy, ABarPendulumKeepsItsEnergyAtEveryStepAt240Hz)
{
	// The same bar at 240 Hz: the integrator's own oscillation shrinks with the step, and so must the error.
	const double kStepTol = 0.01;  // of m g d, at every step
	const PendulumFigures on = swingBar(true, 240, 60);
	std::printf("[ figures  ] bar pendulum 60 s at 240 Hz: worst step %.3g of m g d, worst swing %.3g, period error %.3g\n",
				on.worstStep, on.worstSwing, on.periodError);
	EXPECT_LT(on.worstStep, kStepTol);
	EXPECT_LT(on.maxSeparation, kSeparationTolerance);
}

TEST(StabilizerEnergy, AFreeSpinningChainKeepsItsMomentum)
{
	// Ideal hinges exert internal forces only: a free chain's linear and angular momentum and its kinetic energy are
	// the projection's to keep (put back every step, Q17–Q19). What is left is Bullet's own step, which the bare
	// quaternion hinges (no stabilizer) measure on the same chain: the stabilized chain may drift by at most that
	// plus a small excess. Without the restoration the position stage alone takes 0.28–0.31 of L in 10 s.
	const double kMomentumTol = 1e-4;            // relative linear momentum drift
	const double kAngularMomentumExcess = 1e-3;  // relative angular momentum drift above the bare joints'
	const double kKineticEnergyExcess = 0.01;    // relative kinetic energy drift above the bare joints'
	// ω_z = 2 rad/s (ωh = 0.033 rad at 60 Hz, the position stage's loss ½(ωh)² = 5.6e-4 of L per step), and three
	// times that (ωh = 0.1 rad), where the bare joints lose a quarter of L
	for (const btScalar spinRate : {btScalar(2), btScalar(6)})
		for (const bool cubes : {false, true})
		{
			const FreeFigures bare = spinFreeChain(cubes, false, false, spinRate);
			const FreeFigures off = spinFreeChain(cubes, true, false, spinRate);
			const FreeFigures on = spinFreeChain(cubes, true, true, spinRate);
			std::printf(
				"[ figures  ] free chain of 3 %s links at %g rad/s, 10 s: momentum drift %.3g (before %.3g, bare %.3g), "
				"angular momentum %.3g (before %.3g, bare %.3g), kinetic energy %.3g (before %.3g, bare %.3g), max "
				"separation %.3g m (bare %.3g m)\n",
				cubes ? "cube" : "thin", double(spinRate), on.momentum, off.momentum, bare.momentum, on.angularMomentum,
				off.angularMomentum, bare.angularMomentum, on.kineticEnergy, off.kineticEnergy, bare.kineticEnergy,
				on.maxSeparation, bare.maxSeparation);
			EXPECT_LT(on.momentum, kMomentumTol);
			EXPECT_LT(on.angularMomentum, bare.angularMomentum + kAngularMomentumExcess);
			EXPECT_LT(on.kineticEnergy, bare.kineticEnergy + kKineticEnergyExcess);
			EXPECT_LT(on.maxSeparation, kSeparationTolerance);
		}
}

#endif  // QUATHINGE_HAVE_STABILIZER
