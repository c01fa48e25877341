// The rows are the exact derivative of the constraint they correct (MATH.md Q4–Q10, Q12): checked against central
// finite differences of C under small body rotations (b ← exp(ε e_k) ⊗ b, Q1) and translations, over seeded random
// configurations near the hinge and far from it, in both the Q7 form and the swing-logarithm form past 90° (Q12).
#include "HingeAngle.h"
#include "QuaternionHingeRows.h"
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/RandomPoses.h"
#include "support/World.h"

#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <vector>

using namespace quathinge;
using qh_test::expRotation;
using qh_test::randomUnit;

namespace
{
// Relative error of a row entry against its central difference, per unit of max(1, |row|): 1e-6 in double, 1e-3 in
// float. The step balances truncation O(ε²·C''') against round-off O(eps/ε): ε = 1e-5 rad (or m) in double, the cube
// root of float's epsilon (≈ 4.9e-3) in float.
const double kFdRelTol = qh_test::kDouble ? 1e-6 : 1e-3;                                              // dimensionless
const btScalar kStep = qh_test::kDouble ? btScalar(1e-5) : btScalar(std::cbrt(double(FLT_EPSILON)));  // rad or m
// C is not differentiable on the switching surface φ = 90° (the Q7 form hands over to the log form, Q12) nor at the
// exact flip φ = π: configurations within 1e-3 rad of either are skipped — and in float also those whose difference
// stencil (a rotation by ±ε changes φ by at most ε) would reach across, hence max(1e-3, 2ε).
const double kSkipRad = std::max(1e-3, 2.0 * double(kStep));  // rad, in swing angle φ
// Recovering C from the solver's error term (Q10) divides by erp·fps: a few ulps of C, relative to max(1, |C|); also
// the bound on |J_A + J_B| of an axial row (exact negatives up to round-off).
const double kRecoverTol = qh_test::kDouble ? 1e-12 : 1e-5;  // dimensionless

const double kHalfPi = 1.5707963267948966;
const double kPi = 3.14159265358979323846;

// Joint frame B's world orientation for configuration i, given joint frame A's: a third near the hinge (swing up to
// 0.4 rad, twist anywhere in [−3π, 3π]), a third anywhere (uniform on SO(3)), a third at chosen swing angles close to
// the two surfaces (2·kSkipRad away) and to the hinge (swing 1e-4 rad), so the hard cases are always present.
btQuaternion configurationB(std::mt19937& rng, const btQuaternion& a, int i)
{
	std::uniform_real_distribution<double> twistDist(-3 * kPi, 3 * kPi), unit(-1, 1), dir(0, 2 * kPi);
	const btQuaternion twist(btVector3(0, 0, 1), btScalar(twistDist(rng)));
	const double swingDir = dir(rng);
	auto swingBy = [&](double phi) {
		return expRotation(btVector3(btScalar(phi * std::cos(swingDir)), btScalar(phi * std::sin(swingDir)), 0));
	};
	switch (i % 3)
	{
		case 0:
			return a * swingBy(0.4 * std::fabs(unit(rng))) * twist;
		case 1:
			return randomUnit(rng);
		default:
		{
			const double near[] = {1e-4, kHalfPi - 2 * kSkipRad, kHalfPi + 2 * kSkipRad, kPi - 2 * kSkipRad,
								   0.5 * kPi * std::fabs(unit(rng)), kHalfPi + (kPi / 2) * std::fabs(unit(rng))};
			return a * swingBy(near[(i / 3) % 6]) * twist;
		}
	}
}

// Swing angle φ between the hinge axes of two joint-frame orientations.
double swingOf(const btQuaternion& a, const btQuaternion& b) { return double(swingAngle(relativeQuaternion(a, b))); }

bool nearNonDifferentiable(double phi) { return std::fabs(phi - kHalfPi) < kSkipRad || kPi - phi < kSkipRad; }

// Near the flip C's higher derivatives grow like 1/(π − φ) (the swing axis turns fast there, Q12), so a fixed step
// would measure its own truncation error, not the rows: the step is held to a fraction of the distance to the flip.
const double kStepPerFlipDistance = 0.2;  // dimensionless (Richardson: truncation O((ε/(π − φ))⁴))
btScalar stepFor(double phi) { return btScalar(std::min(double(kStep), kStepPerFlipDistance * (kPi - phi))); }

// The central difference (f(+ε) − f(−ε))/2ε, Richardson-extrapolated from steps ε and ε/2 (error O(ε⁴) instead of
// O(ε²)), so the same tolerance holds near the flip where the step must be small.
template <class F>
double centralDifference(const F& f, double eps)
{
	const double d1 = (f(eps) - f(-eps)) / (2 * eps);
	const double d2 = (f(eps / 2) - f(-eps / 2)) / eps;
	return (4 * d2 - d1) / 3;
}

double relError(double fd, double row) { return std::fabs(fd - row) / std::max(1.0, std::fabs(row)); }

// Rows of a joint read through getInfo1/getInfo2 at the bodies' current transforms.
struct SolverRows
{
	int count = 0;
	qh_test::ScratchRows rows;  // fps = 60, erp = 0.2
	explicit SolverRows(btQuaternionHingeConstraint& joint)
	{
		btTypedConstraint::btConstraintInfo1 info1;
		joint.getInfo1(&info1);
		count = info1.m_numConstraintRows;
		joint.getInfo2(&rows.info);
	}
	// (Q10) m_constraintError = −erp·fps·C for the bilateral rows.
	btScalar value(int r) const { return rows.err(r) / (-rows.info.erp * rows.info.fps); }
};
}  // namespace

TEST(JacobianFiniteDifference, AngularRowsAreTheDerivativeOfC)
{
	// Q7/Q9 rows (and the Q12 log rows past 90°): ∂C/∂ω_B = +row, ∂C/∂ω_A = −row, by central differences, ≥ 200 configs.
	std::mt19937 rng(20261122);
	double worst = 0, worstQ7 = 0, worstLog = 0;
	int checked = 0, logForm = 0, skipped = 0;
	for (int i = 0; i < 600; ++i)
	{
		const btQuaternion a = randomUnit(rng);
		const btQuaternion b = configurationB(rng, a, i);
		if (nearNonDifferentiable(swingOf(a, b)))
		{
			++skipped;
			continue;
		}
		AngularRows rows;
		computeAngularRows(a, b, rows);
		logForm += rows.logForm;
		const double eps = stepFor(swingOf(a, b));
		double here = 0;
		for (int k = 0; k < 3; ++k)
			for (int component = 0; component < 2; ++component)
			{
				auto value = [&](const btQuaternion& qa, const btQuaternion& qb) {
					btScalar cu, cv;
					angularConstraintValue(qa, qb, cu, cv);
					return double(component == 0 ? cu : cv);
				};
				auto turn = [&](double angle) {
					btVector3 e(0, 0, 0);
					e[k] = btScalar(angle);
					return expRotation(e);
				};
				const btScalar row = (component == 0 ? rows.rowU : rows.rowV)[k];
				// body B turned by ±ε about world axis k: ∂C/∂ω_B = +row (Q7)
				const double fdB = centralDifference([&](double h) { return value(a, turn(h) * b); }, eps);
				// body A turned: ∂C/∂ω_A = −row
				const double fdA = centralDifference([&](double h) { return value(turn(h) * a, b); }, eps);
				here = std::max(here, std::max(relError(fdB, row), relError(fdA, -row)));
			}
		EXPECT_LT(here, kFdRelTol) << "configuration " << i << ", swing " << swingOf(a, b) << " rad";
		(rows.logForm ? worstLog : worstQ7) = std::max(rows.logForm ? worstLog : worstQ7, here);
		worst = std::max(worst, here);
		++checked;
	}
	std::printf(
		"[ figures  ] angular rows vs FD (step ≤ %.3g): worst relative error %.3g (Q7 form %.3g, log form %.3g) "
		"over %d configurations (%d log form, %d skipped near φ = 90° or π)\n",
		double(kStep), worst, worstQ7, worstLog, checked, logForm, skipped);
	EXPECT_GE(checked, 500);
	EXPECT_GT(logForm, 100);  // the flipped hemisphere was exercised
	EXPECT_LT(worst, kFdRelTol);
}

TEST(JacobianFiniteDifference, AngularValueIsQ4OnTheQ7Side)
{
	// Within 90° the value is C = 2 q_v·(x̂, ŷ) of q = a* ⊗ b (Q2, Q4, Q9), computed here independently.
	std::mt19937 rng(3);
	const double tol = qh_test::kDouble ? 1e-12 : 1e-6;  // dimensionless, a few ulps of unit-quaternion components
	for (int i = 0; i < 200; ++i)
	{
		const btQuaternion a = randomUnit(rng);
		const btQuaternion b = configurationB(rng, a, 3 * (i / 3));  // near the hinge
		btQuaternion q = a.inverse() * b;
		btScalar cu, cv;
		angularConstraintValue(a, b, cu, cv);
		EXPECT_NEAR(cu, 2 * q.x(), tol);
		EXPECT_NEAR(cv, 2 * q.y(), tol);
	}
}

TEST(JacobianFiniteDifference, AngleGradientIsTheDerivativeOfTheHingeAngle)
{
	// ∂θ/∂Ω (HingeAngle.h, used by the axial rows) against central differences of θ (Q11), ≥ 200 configurations.
	std::mt19937 rng(7);
	double worst = 0;
	int checked = 0;
	for (int i = 0; i < 450; ++i)
	{
		const btQuaternion a = randomUnit(rng);
		const btQuaternion b = configurationB(rng, a, i);
		// θ is smooth wherever the axes are not flipped; it is used (as the axial row direction) within 90°.
		if (nearNonDifferentiable(swingOf(a, b)) || swingOf(a, b) > kHalfPi) continue;
		const btQuaternion q = relativeQuaternion(a, b);
		const btVector3 gradientWorld = btMatrix3x3(a) * hingeAngleGradient(q);
		for (int k = 0; k < 3; ++k)
		{
			btVector3 e(0, 0, 0);
			e[k] = kStep;
			const btScalar tp = hingeAngle(relativeQuaternion(a, expRotation(e) * b));
			const btScalar tm = hingeAngle(relativeQuaternion(a, expRotation(-e) * b));
			const double fd = double(wrapAngle(tp - tm)) / (2 * double(kStep));
			worst = std::max(worst, relError(fd, gradientWorld[k]));
			const btScalar ap = hingeAngle(relativeQuaternion(expRotation(e) * a, b));
			const btScalar am = hingeAngle(relativeQuaternion(expRotation(-e) * a, b));
			worst = std::max(worst, relError(double(wrapAngle(ap - am)) / (2 * double(kStep)), -gradientWorld[k]));
		}
		++checked;
	}
	std::printf("[ figures  ] angle gradient vs FD: worst relative error %.3g over %d configurations\n", worst, checked);
	EXPECT_GE(checked, 200);
	EXPECT_LT(worst, kFdRelTol);
}

namespace
{
// The solver's rows are T·J with errors T·C, T a change of row basis taken at the pose (SolverRowBasis.h and
// fillBilateralRows): an orthogonal 3×3 rotation of the point rows (their directions, read from J2's linear part), an
// orthogonal 2×2 turn of the quaternion rows (identified against the independent Q7/Q12 rows at the same pose), and a
// multiple of the quaternion rows taken off each point row (the lever arms' axial parts; identified from J2's
// angular part against r_B × e, which the test computes from the pose). Decoded undoes each and reads C and J back.
struct DecodedRows
{
	int n = 0;
	double c[5] = {};          // C, unrotated (point: p_B − p_A along world x, y, z; quaternion: Q4/Q9 or Q12, in the
							   // independent computation's quaternion sign)
	btVector3 jac[4][5];       // per row: linA, angA, linB, angB, unrotated
	double orthogonality = 0;  // max |MᵀM − I| over both blocks
	btVector3 angularRowB[2];  // the independent rows (to align the quaternion sign between poses, Q3)
	double independentC[2];    // the independent Q4/Q12 value at the same pose
};

DecodedRows decode(btQuaternionHingeConstraint& joint, bool angularOnly, const btQuaternion& jointA, const btQuaternion& jointB)
{
	SolverRows solver(joint);
	DecodedRows d;
	d.n = solver.count;
	const qh_test::ScratchRows& r = solver.rows;
	auto rowOf = [&](int kind, int row) {
		switch (kind)
		{
			case 0: return r.linA(row);
			case 1: return r.angA(row);
			case 2: return r.linB(row);
			default: return r.angB(row);
		}
	};
	int first = 0;
	if (!angularOnly)
	{
		// The quaternion rows taken off point row i: J2ang_i = r_B × e_i − Σ_k κ_ik g_k, g_k the quaternion rows'
		// J2 angular part; κ by least squares, then row_i + Σ_k κ_ik row_k and value_i + Σ_k κ_ik value_k.
		const btTransform& tb = joint.getRigidBodyB().getCenterOfMassTransform();
		const btVector3 rB = tb * joint.getBFrame().getOrigin() - tb.getOrigin();
		const btVector3 g[2] = {r.angB(3), r.angB(4)};
		const double gg00 = g[0].dot(g[0]), gg01 = g[0].dot(g[1]), gg11 = g[1].dot(g[1]);
		const double gdet = gg00 * gg11 - gg01 * gg01;
		double pointValue[3];
		btVector3 pointRow[3][4];
		for (int i = 0; i < 3; ++i)
		{
			const btVector3 residual = rB.cross(r.linB(i)) - r.angB(i);
			const double q0 = g[0].dot(residual), q1 = g[1].dot(residual);
			const double k0 = gdet > 0 ? (gg11 * q0 - gg01 * q1) / gdet : 0, k1 = gdet > 0 ? (gg00 * q1 - gg01 * q0) / gdet : 0;
			// (a joint to a static body takes the quaternion rows' Jacobian off its axial row but not their errors: that
			// row's error is the pivot's own axial offset, fillBilateralRows)
			const bool freeAxialArm = i == 2 && (joint.getRigidBodyA().getInvMass() == 0) != (joint.getRigidBodyB().getInvMass() == 0);
			pointValue[i] = double(solver.value(i)) + (freeAxialArm ? 0 : k0 * double(solver.value(3)) + k1 * double(solver.value(4)));
			for (int kind = 0; kind < 4; ++kind)
				pointRow[i][kind] = rowOf(kind, i) + btScalar(k0) * rowOf(kind, 3) + btScalar(k1) * rowOf(kind, 4);
		}
		// M_point: rows e_i (J2 linear = e_i). C = Σ_i e_i (e_i·C), J likewise.
		btVector3 e[3] = {r.linB(0), r.linB(1), r.linB(2)};
		for (int i = 0; i < 3; ++i)
			for (int j = 0; j < 3; ++j)
				d.orthogonality = std::max(d.orthogonality, std::fabs(double(e[i].dot(e[j])) - (i == j ? 1 : 0)));
		for (int world = 0; world < 3; ++world)
		{
			double ci = 0;
			for (int i = 0; i < 3; ++i) ci += double(e[i][world]) * pointValue[i];
			d.c[world] = ci;
			for (int kind = 0; kind < 4; ++kind)
			{
				btVector3 sum(0, 0, 0);
				for (int i = 0; i < 3; ++i) sum += e[i][world] * pointRow[i][kind];
				d.jac[kind][world] = sum;
			}
		}
		first = 3;
	}
	// M_quat from G = M R, R = the independent rows (2×3), G = the solver's body-B angular rows: M = G Rᵀ (R Rᵀ)⁻¹.
	AngularRows independent;
	computeAngularRows(jointA, jointB, independent);
	const btVector3 R[2] = {independent.rowU, independent.rowV};
	const btVector3 G[2] = {r.angB(first), r.angB(first + 1)};
	const double a = R[0].dot(R[0]), b = R[0].dot(R[1]), c = R[1].dot(R[1]), det = a * c - b * b;
	double M[2][2];
	for (int i = 0; i < 2; ++i)
	{
		const double g0 = G[i].dot(R[0]), g1 = G[i].dot(R[1]);
		M[i][0] = (g0 * c - g1 * b) / det;
		M[i][1] = (g1 * a - g0 * b) / det;
	}
	for (int i = 0; i < 2; ++i)
		for (int j = 0; j < 2; ++j)
			d.orthogonality = std::max(d.orthogonality, std::fabs(M[0][i] * M[0][j] + M[1][i] * M[1][j] - (i == j ? 1 : 0)));
	for (int j = 0; j < 2; ++j)  // Mᵀ undoes M (orthogonal; checked above)
	{
		d.c[first + j] = M[0][j] * double(solver.value(first)) + M[1][j] * double(solver.value(first + 1));
		for (int kind = 0; kind < 4; ++kind)
			d.jac[kind][first + j] = btScalar(M[0][j]) * rowOf(kind, first) + btScalar(M[1][j]) * rowOf(kind, first + 1);
	}
	d.angularRowB[0] = independent.rowU;
	d.angularRowB[1] = independent.rowV;
	d.independentC[0] = independent.errorU;
	d.independentC[1] = independent.errorV;
	return d;
}
}  // namespace

TEST(JacobianFiniteDifference, JointRowsThroughGetInfo2MatchFiniteDifferences)
{
	// Through the public class: C recovered from m_constraintError = −erp·fps·C (Q10) at the base pose and at every
	// perturbed pose (getInfo1/getInfo2 each time), with the solver's row-space rotation undone (decode above); each
	// row's J1/J2 against central differences of C under translations and rotations of A and B; C itself against
	// p_B − p_A and the independent Q4 value; the rotation orthogonal.
	std::mt19937 rng(11);
	std::uniform_real_distribution<double> u(-1, 1);
	btBoxShape shape(btVector3(btScalar(0.1), btScalar(0.5), btScalar(0.1)));
	double worst = 0, worstValue = 0, worstOrthogonality = 0;
	int checked = 0;
	for (int trial = 0; trial < 240; ++trial)
	{
		// unequal masses, so the blended axis and radial direction (SolverRowBasis.h) are not symmetric
		btRigidBody a(1, nullptr, &shape, btVector3(1, 1, 1)), b(btScalar(trial % 3 == 0 ? 0 : 2.5), nullptr, &shape, btVector3(1, 1, 1));
		// every fifth joint has its pivots at the centres of mass: no radial direction, the basis falls back to frame A's
		const btScalar armScale = trial % 5 == 4 ? btScalar(0) : btScalar(1);
		const btTransform frameA(randomUnit(rng), armScale * btVector3(btScalar(u(rng)), btScalar(u(rng)), btScalar(u(rng))));
		const btTransform frameB(randomUnit(rng), armScale * btVector3(btScalar(u(rng)), btScalar(u(rng)), btScalar(u(rng))));
		const btTransform poseA(randomUnit(rng), btVector3(btScalar(u(rng)), btScalar(u(rng)), btScalar(u(rng))));
		const btQuaternion fbWorld = configurationB(rng, poseA.getRotation() * frameA.getRotation(), trial);
		const btTransform poseB(fbWorld * frameB.getRotation().inverse(),
								btVector3(btScalar(u(rng)), btScalar(u(rng)), btScalar(u(rng))));
		a.setCenterOfMassTransform(poseA);
		b.setCenterOfMassTransform(poseB);
		const bool angularOnly = trial % 4 == 3;
		btQuaternionHingeConstraint joint(a, b, frameA, frameB, trial % 2 == 0);
		joint.setAngularOnly(angularOnly);
		const btTransform& fA = joint.getAFrame();
		const btTransform& fB = joint.getBFrame();
		auto jointA = [&](const btTransform& ta) { return (ta * fA).getRotation(); };
		auto jointB = [&](const btTransform& tb) { return (tb * fB).getRotation(); };
		if (nearNonDifferentiable(swingOf(jointA(poseA), jointB(poseB)))) continue;

		// The rows and the value at the base pose.
		const DecodedRows base = decode(joint, angularOnly, jointA(poseA), jointB(poseB));
		const int n = angularOnly ? 2 : 5;
		ASSERT_EQ(base.n, n);
		worstOrthogonality = std::max(worstOrthogonality, base.orthogonality);
		std::vector<double> expected;
		if (!angularOnly)
		{
			const btVector3 c = poseB * fB.getOrigin() - poseA * fA.getOrigin();  // C = p_B − p_A
			for (int i = 0; i < 3; ++i) expected.push_back(c[i]);
		}
		AngularRows independent;
		computeAngularRows(jointA(poseA), jointB(poseB), independent);
		expected.push_back(independent.errorU);
		expected.push_back(independent.errorV);
		for (int r = 0; r < n; ++r) worstValue = std::max(worstValue, relError(base.c[r], expected[size_t(r)]));

		// C at a perturbed pose, read back through the solver interface.
		auto valueAt = [&](const btTransform& ta, const btTransform& tb, std::vector<double>& c) {
			a.setCenterOfMassTransform(ta);
			b.setCenterOfMassTransform(tb);
			const DecodedRows rows = decode(joint, angularOnly, jointA(ta), jointB(tb));
			c.resize(size_t(n));
			for (int r = 0; r < n; ++r)
			{
				// the same quaternion sign (Q3) between the perturbed and the base pose, by the independent rows
				// The quaternion rows' C comes from the independent computation at the perturbed pose: undoing the
				// solver's 2×2 turn there would need M identified at every pose, whose float round-off (≈ 1e-6, times
				// |C| ≤ π, over ε ≈ 5e-3) would swamp the check. The solver's own C is checked at the base pose
				// (C = Mᵀ(M C) against the same value), so the chain is closed.
				const int j = r - (n - 2);
				const bool flipped = j >= 0 && rows.angularRowB[j].dot(base.angularRowB[j]) < 0;
				c[size_t(r)] = (flipped ? -1 : 1) * (j >= 0 ? rows.independentC[j] : rows.c[r]);
			}
		};
		// Each row's J against the central difference of C (Richardson-extrapolated, step held off the flip).
		const double eps = stepFor(swingOf(jointA(poseA), jointB(poseB)));
		auto fdCheck = [&](const std::function<void(double, btTransform&, btTransform&)>& perturb, int kind, int k) {
			std::vector<double> c[4];
			const double hs[4] = {eps, -eps, eps / 2, -eps / 2};
			for (int i = 0; i < 4; ++i)
			{
				btTransform ta = poseA, tb = poseB;
				perturb(hs[i], ta, tb);
				valueAt(ta, tb, c[i]);
			}
			for (int r = 0; r < n; ++r)
			{
				const size_t i = size_t(r);
				const double d1 = (c[0][i] - c[1][i]) / (2 * eps), d2 = (c[2][i] - c[3][i]) / eps;
				worst = std::max(worst, relError((4 * d2 - d1) / 3, base.jac[kind][r][k]));
			}
		};
		for (int k = 0; k < 3; ++k)
		{
			auto along = [k](double h) {
				btVector3 e(0, 0, 0);
				e[k] = btScalar(h);
				return e;
			};
			// translations of A, then B
			fdCheck([&](double h, btTransform& ta, btTransform&) { ta.setOrigin(ta.getOrigin() + along(h)); }, 0, k);
			fdCheck([&](double h, btTransform&, btTransform& tb) { tb.setOrigin(tb.getOrigin() + along(h)); }, 2, k);
			// rotations about each body's centre of mass, q ← exp(ε e_k) ⊗ q (Q1)
			fdCheck([&](double h, btTransform& ta, btTransform&) { ta.setRotation(expRotation(along(h)) * poseA.getRotation()); }, 1, k);
			fdCheck([&](double h, btTransform&, btTransform& tb) { tb.setRotation(expRotation(along(h)) * poseB.getRotation()); }, 3, k);
		}
		++checked;
	}
	std::printf(
		"[ figures  ] joint rows (getInfo2) vs FD: worst relative error %.3g over %d joints; C recovered from "
		"the error term vs p_B − p_A and Q4: %.3g; row-space rotation orthogonal to %.3g\n",
		worst, checked, worstValue, worstOrthogonality);
	EXPECT_GE(checked, 200);
	EXPECT_LT(worst, kFdRelTol);
	EXPECT_LT(worstValue, kRecoverTol);
	EXPECT_LT(worstOrthogonality, kRecoverTol);
}

TEST(JacobianFiniteDifference, AxialRowsAreTheDerivativeOfTheUserAngle)
{
	// With a motor, friction and a locked limit on (8 rows), each axial row is ∂α/∂(v, ω) for α = getHingeAngle()
	// (σθ, Q11) within 90° of assembly, and lies along the hinge axis (no linear part) everywhere.
	std::mt19937 rng(5);
	std::uniform_real_distribution<double> u(-1, 1);
	btBoxShape shape(btVector3(btScalar(0.1), btScalar(0.5), btScalar(0.1)));
	double worst = 0;
	int checked = 0;
	for (int trial = 0; trial < 200; ++trial)
	{
		btRigidBody a(1, nullptr, &shape, btVector3(1, 1, 1)), b(1, nullptr, &shape, btVector3(1, 1, 1));
		const btTransform frameA(randomUnit(rng), btVector3(0, btScalar(0.5), 0));
		const btTransform frameB(randomUnit(rng), btVector3(0, btScalar(-0.5), 0));
		const btTransform poseA(randomUnit(rng), btVector3(btScalar(u(rng)), btScalar(u(rng)), btScalar(u(rng))));
		const btQuaternion fbWorld = configurationB(rng, poseA.getRotation() * frameA.getRotation(), 3 * trial);
		const btTransform poseB(fbWorld * frameB.getRotation().inverse(), btVector3(0, 0, 0));
		a.setCenterOfMassTransform(poseA);
		b.setCenterOfMassTransform(poseB);
		btQuaternionHingeConstraint joint(a, b, frameA, frameB, trial % 2 == 0);
		if (nearNonDifferentiable(swingOf((poseA * frameA).getRotation(), (poseB * frameB).getRotation()))) continue;
		joint.enableAngularMotor(true, 1, 1);
		joint.setMaxFrictionTorque(1);
		const btScalar angle = joint.getHingeAngle();
		joint.setLimit(angle, angle);  // locked: the limit row is on at any angle
		SolverRows base(joint);
		ASSERT_EQ(base.count, 8);
		auto angleAt = [&](const btTransform& ta, const btTransform& tb) {
			return double(joint.getHingeAngle(ta, tb));
		};
		for (int r = 5; r < 8; ++r)
		{
			EXPECT_EQ(base.rows.linA(r).length(), 0) << r;
			EXPECT_EQ(base.rows.linB(r).length(), 0) << r;
			EXPECT_NEAR((base.rows.angA(r) + base.rows.angB(r)).length(), 0, kRecoverTol) << r;  // J_A = −J_B
			for (int k = 0; k < 3; ++k)
			{
				btVector3 e(0, 0, 0);
				e[k] = kStep;
				const double fdB = std::remainder(angleAt(poseA, btTransform(expRotation(e) * poseB.getRotation())) -
													  angleAt(poseA, btTransform(expRotation(-e) * poseB.getRotation())),
												  2 * kPi) /
								   (2 * double(kStep));
				worst = std::max(worst, relError(fdB, base.rows.angB(r)[k]));
			}
		}
		++checked;
	}
	std::printf("[ figures  ] axial rows vs FD of getHingeAngle: worst relative error %.3g over %d joints\n", worst,
				checked);
	EXPECT_GE(checked, 100);
	EXPECT_LT(worst, kFdRelTol);
}

TEST(JacobianFiniteDifference, PositionRowsForStabilizersAreTheDerivativeOfTheirValues)
{
	// computePositionRows (the post-stabilizer's C and J, unrotated, world axes): C against p_B − p_A and the
	// independent Q4/Q12 value, J against central differences of that C (Richardson), over seeded random poses.
	std::mt19937 rng(29);
	std::uniform_real_distribution<double> u(-1, 1);
	btBoxShape shape(btVector3(btScalar(0.1), btScalar(0.5), btScalar(0.1)));
	double worst = 0, worstValue = 0;
	int checked = 0;
	for (int trial = 0; trial < 120; ++trial)
	{
		btRigidBody a(1, nullptr, &shape, btVector3(1, 1, 1)), b(1, nullptr, &shape, btVector3(1, 1, 1));
		const btTransform frameA(randomUnit(rng), btVector3(btScalar(u(rng)), btScalar(u(rng)), btScalar(u(rng))));
		const btTransform frameB(randomUnit(rng), btVector3(btScalar(u(rng)), btScalar(u(rng)), btScalar(u(rng))));
		const btTransform poseA(randomUnit(rng), btVector3(btScalar(u(rng)), btScalar(u(rng)), btScalar(u(rng))));
		const btQuaternion fbWorld = configurationB(rng, poseA.getRotation() * frameA.getRotation(), trial);
		const btTransform poseB(fbWorld * frameB.getRotation().inverse(),
								btVector3(btScalar(u(rng)), btScalar(u(rng)), btScalar(u(rng))));
		btQuaternionHingeConstraint joint(a, b, frameA, frameB, trial % 2 == 0);
		const bool angularOnly = trial % 4 == 3;
		joint.setAngularOnly(angularOnly);
		const btTransform& fA = joint.getAFrame();
		const btTransform& fB = joint.getBFrame();
		const btQuaternion qa = (poseA * fA).getRotation(), qb = (poseB * fB).getRotation();
		if (nearNonDifferentiable(swingOf(qa, qb))) continue;
		btScalar c0[5], jac[60];
		const int n = joint.computePositionRows(poseA, poseB, c0, jac);
		ASSERT_EQ(n, angularOnly ? 2 : 5);
		// the value
		std::vector<double> expected;
		if (!angularOnly)
		{
			const btVector3 c = poseB * fB.getOrigin() - poseA * fA.getOrigin();
			for (int i = 0; i < 3; ++i) expected.push_back(c[i]);
		}
		AngularRows independent;
		computeAngularRows(qa, qb, independent);
		// the same equation up to the quaternion's sign (Q3), aligned by the rows' direction
		const double sign = independent.rowU.dot(btVector3(jac[12 * (n - 2) + 9], jac[12 * (n - 2) + 10], jac[12 * (n - 2) + 11])) < 0 ? -1 : 1;
		expected.push_back(sign * independent.errorU);
		expected.push_back(sign * independent.errorV);
		for (int r = 0; r < n; ++r) worstValue = std::max(worstValue, relError(c0[r], expected[size_t(r)]));
		// the derivative, per coordinate of (v_A, ω_A, v_B, ω_B)
		const double eps = stepFor(swingOf(qa, qb));
		for (int col = 0; col < 12; ++col)
		{
			auto value = [&](double h, int r) {
				btTransform ta = poseA, tb = poseB;
				btTransform& t = col < 6 ? ta : tb;
				btVector3 d(0, 0, 0);
				d[col % 3] = btScalar(h);
				if (col % 6 < 3) t.setOrigin(t.getOrigin() + d);
				else t.setRotation(expRotation(d) * t.getRotation());
				btScalar c[5], j[60];
				joint.computePositionRows(ta, tb, c, j);
				// Q3: keep the base pose's sign of the quaternion rows
				const btVector3 gB(j[12 * (n - 2) + 9], j[12 * (n - 2) + 10], j[12 * (n - 2) + 11]);
				const btVector3 gBase(jac[12 * (n - 2) + 9], jac[12 * (n - 2) + 10], jac[12 * (n - 2) + 11]);
				const double flip = (r >= n - 2 && gB.dot(gBase) < 0) ? -1 : 1;
				return flip * double(c[r]);
			};
			for (int r = 0; r < n; ++r)
			{
				const double fd = centralDifference([&](double h) { return value(h, r); }, eps);
				worst = std::max(worst, relError(fd, jac[12 * r + col]));
			}
		}
		++checked;
	}
	std::printf(
		"[ figures  ] position rows (computePositionRows) vs FD: worst relative error %.3g over %d joints; C vs "
		"p_B − p_A and Q4: %.3g\n",
		worst, checked, worstValue);
	EXPECT_GE(checked, 100);
	EXPECT_LT(worst, kFdRelTol);
	EXPECT_LT(worstValue, kRecoverTol);
}
