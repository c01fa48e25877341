// The rows are the exact derivative of the constraint they correct (MATH.md Q4–Q10, Q12): checked against central
// finite differences of C under small body rotations and translations, over randomized configurations.
#include "HingeAngle.h"
#include "QuaternionHingeRows.h"
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/World.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace quathinge;
using qh_test::expRotation;

namespace
{
// Relative error of a row entry against its finite difference, scaled by max(1, |row|): 1e-6 in double, 1e-3 in float
// (central differences with step h have truncation O(h²) and round-off O(ε/h): h = 1e-5 in double, 3e-3 in float).
const double kFdRelTol = qh_test::kDouble ? 1e-6 : 1e-3;
const btScalar kStep = qh_test::kDouble ? btScalar(1e-5) : btScalar(3e-3);
// C is not differentiable on the 90° switching surface (c² = ½) nor at the exact flip (c = 0): configurations closer
// than this (in c²) to either are skipped.
const double kSkipNearSurface = 1e-2;

btQuaternion randomUnit(std::mt19937& rng)
{
	std::normal_distribution<double> n(0, 1);
	btQuaternion q(btScalar(n(rng)), btScalar(n(rng)), btScalar(n(rng)), btScalar(n(rng)));
	return q.normalized();
}

// Half of the configurations near the hinge manifold (small swing), half anywhere.
btQuaternion randomB(std::mt19937& rng, const btQuaternion& a, int i)
{
	if (i % 2) return randomUnit(rng);
	std::uniform_real_distribution<double> u(-3.2, 3.2), small(-0.3, 0.3);
	const btQuaternion twist(btVector3(0, 0, 1), btScalar(u(rng)));
	const btQuaternion swing = expRotation(btVector3(btScalar(small(rng)), btScalar(small(rng)), 0));
	return a * swing * twist;
}

bool nearSurface(const btQuaternion& a, const btQuaternion& b)
{
	const btQuaternion q = relativeQuaternion(a, b);
	const double c2 = double(q.w()) * q.w() + double(q.z()) * q.z();
	return std::fabs(c2 - 0.5) < kSkipNearSurface || c2 < kSkipNearSurface;
}

double relError(double fd, double row) { return std::fabs(fd - row) / std::max(1.0, std::fabs(row)); }
}  // namespace

TEST(JacobianFiniteDifference, AngularRowsAreTheDerivativeOfC)
{
	// Q7/Q9 rows (and the Q12 log-form rows past 90°) against central differences of C over 400 configurations.
	std::mt19937 rng(20261122);
	double worst = 0;
	int checked = 0, logForm = 0;
	for (int i = 0; i < 400; ++i)
	{
		const btQuaternion a = randomUnit(rng);
		const btQuaternion b = randomB(rng, a, i);
		if (nearSurface(a, b)) continue;
		AngularRows rows;
		computeAngularRows(a, b, rows);
		logForm += rows.logForm;
		for (int k = 0; k < 3; ++k)
		{
			btVector3 e(0, 0, 0);
			e[k] = kStep;
			btScalar up, vp, um, vm;
			// body B turned by ±h about world axis k: ∂C/∂ω_B = +row
			angularConstraintValue(a, expRotation(e) * b, up, vp);
			angularConstraintValue(a, expRotation(-e) * b, um, vm);
			worst = std::max(worst, relError((up - um) / (2 * kStep), rows.rowU[k]));
			worst = std::max(worst, relError((vp - vm) / (2 * kStep), rows.rowV[k]));
			// body A turned: ∂C/∂ω_A = −row
			angularConstraintValue(expRotation(e) * a, b, up, vp);
			angularConstraintValue(expRotation(-e) * a, b, um, vm);
			worst = std::max(worst, relError((up - um) / (2 * kStep), -rows.rowU[k]));
			worst = std::max(worst, relError((vp - vm) / (2 * kStep), -rows.rowV[k]));
		}
		++checked;
	}
	std::printf("[ figures  ] angular rows vs FD: worst relative error %.3g over %d configurations (%d log form)\n",
				worst, checked, logForm);
	EXPECT_GT(checked, 300);
	EXPECT_GT(logForm, 50);  // the flipped hemisphere was exercised
	EXPECT_LT(worst, kFdRelTol);
}

TEST(JacobianFiniteDifference, AngleGradientIsTheDerivativeOfTheHingeAngle)
{
	// The axial rows use ∂θ/∂Ω (HingeAngle.h); check it against central differences of θ (Q11).
	std::mt19937 rng(7);
	double worst = 0;
	for (int i = 0; i < 300; ++i)
	{
		const btQuaternion a = randomUnit(rng);
		const btQuaternion b = randomB(rng, a, i);
		if (nearSurface(a, b)) continue;
		const btQuaternion q = relativeQuaternion(a, b);
		const btVector3 gradientWorld = btMatrix3x3(a) * hingeAngleGradient(q);
		for (int k = 0; k < 3; ++k)
		{
			btVector3 e(0, 0, 0);
			e[k] = kStep;
			const btScalar tp = hingeAngle(relativeQuaternion(a, expRotation(e) * b));
			const btScalar tm = hingeAngle(relativeQuaternion(a, expRotation(-e) * b));
			const double fd = double(wrapAngle(tp - tm)) / (2 * kStep);
			worst = std::max(worst, relError(fd, gradientWorld[k]) / std::max(1.0, double(gradientWorld.length())));
		}
	}
	std::printf("[ figures  ] angle gradient vs FD: worst relative error %.3g\n", worst);
	EXPECT_LT(worst, kFdRelTol);
}

TEST(JacobianFiniteDifference, JointRowsThroughGetInfo2MatchFiniteDifferences)
{
	// Through the public class: C recovered from m_constraintError = −erp·fps·C (Q10) and each row's Jacobian
	// against central differences of C under translations and rotations of both bodies.
	std::mt19937 rng(11);
	std::uniform_real_distribution<double> u(-1, 1);
	btBoxShape shape(btVector3(btScalar(0.1), btScalar(0.5), btScalar(0.1)));
	double worst = 0;
	for (int trial = 0; trial < 40; ++trial)
	{
		btRigidBody a(1, nullptr, &shape, btVector3(1, 1, 1)), b(1, nullptr, &shape, btVector3(1, 1, 1));
		const btTransform poseA(randomUnit(rng), btVector3(btScalar(u(rng)), btScalar(u(rng)), btScalar(u(rng))));
		const btTransform poseB(randomB(rng, poseA.getRotation(), trial),
								btVector3(btScalar(u(rng)), btScalar(u(rng)), btScalar(u(rng))));
		a.setWorldTransform(poseA);
		b.setWorldTransform(poseB);
		btQuaternionHingeConstraint joint(a, b, btVector3(0, btScalar(0.5), 0), btVector3(0, btScalar(-0.5), 0),
										  btVector3(0, 0, 1), btVector3(0, 0, 1));
		btTransform fA = joint.getAFrame(), fB = joint.getBFrame();
		if (nearSurface(poseA.getRotation() * fA.getRotation(), poseB.getRotation() * fB.getRotation())) continue;
		btTypedConstraint::btConstraintInfo1 info1;
		joint.getInfo1(&info1);
		ASSERT_EQ(info1.m_numConstraintRows, 5);
		qh_test::ScratchRows rows;
		joint.getInfo2(&rows.info);
		const btScalar scale = -rows.info.erp * rows.info.fps;
		auto valueAt = [&](const btTransform& ta, const btTransform& tb, btScalar* c) {
			btScalar jac[60];
			joint.computePositionRows(ta, tb, c, jac);
		};
		btScalar c0[5];
		valueAt(poseA, poseB, c0);
		for (int r = 0; r < 5; ++r) EXPECT_NEAR(rows.err(r) / scale, c0[r], 1e-5 * std::max(1.0, std::fabs(double(c0[r]))));
		for (int k = 0; k < 3; ++k)
		{
			btVector3 e(0, 0, 0);
			e[k] = kStep;
			btScalar cp[5], cm[5];
			// translations
			valueAt(btTransform(poseA.getBasis(), poseA.getOrigin() + e), poseB, cp);
			valueAt(btTransform(poseA.getBasis(), poseA.getOrigin() - e), poseB, cm);
			for (int r = 0; r < 5; ++r) worst = std::max(worst, relError((cp[r] - cm[r]) / (2 * kStep), rows.linA(r)[k]));
			valueAt(poseA, btTransform(poseB.getBasis(), poseB.getOrigin() + e), cp);
			valueAt(poseA, btTransform(poseB.getBasis(), poseB.getOrigin() - e), cm);
			for (int r = 0; r < 5; ++r) worst = std::max(worst, relError((cp[r] - cm[r]) / (2 * kStep), rows.linB(r)[k]));
			// rotations about each body's centre of mass
			valueAt(btTransform(expRotation(e) * poseA.getRotation(), poseA.getOrigin()), poseB, cp);
			valueAt(btTransform(expRotation(-e) * poseA.getRotation(), poseA.getOrigin()), poseB, cm);
			for (int r = 0; r < 5; ++r) worst = std::max(worst, relError((cp[r] - cm[r]) / (2 * kStep), rows.angA(r)[k]));
			valueAt(poseA, btTransform(expRotation(e) * poseB.getRotation(), poseB.getOrigin()), cp);
			valueAt(poseA, btTransform(expRotation(-e) * poseB.getRotation(), poseB.getOrigin()), cm);
			for (int r = 0; r < 5; ++r) worst = std::max(worst, relError((cp[r] - cm[r]) / (2 * kStep), rows.angB(r)[k]));
		}
	}
	std::printf("[ figures  ] joint rows (getInfo2) vs FD: worst relative error %.3g\n", worst);
	EXPECT_LT(worst, kFdRelTol);
}
