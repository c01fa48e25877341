// btQuaternionHingeConstraint's five bilateral rows as the solver gets them (HingeSolverRows.cpp calls these): the
// point and quaternion rows written in the solver's row basis (SolverRowBasis.h), and the study-only decoupled basis.
#include "quathinge/btQuaternionHingeConstraint.h"

#include "AxisRows.h"
#include "HingeAngle.h"
#include "InputChecks.h"
#include "MatrixLanes.h"
#include "QuaternionHingeRows.h"
#include "RowKinds.h"
#include "SolverRowBasis.h"
#include "WorldPointRows.h"

#include "BulletDynamics/Dynamics/btRigidBody.h"

#include <cmath>
#include <cstring>
#include <type_traits>

using namespace quathinge;

namespace
{
// Eigenvectors (columns of v) of the symmetric n×n matrix k (n ≤ 5), by cyclic Jacobi rotations (k is overwritten).
void symmetricEigenvectors(double (&k)[5][5], double (&v)[5][5], int n)
{
	for (int r = 0; r < 5; ++r)
		for (int c = 0; c < 5; ++c) v[r][c] = r == c ? 1 : 0;
	for (int sweep = 0; sweep < 50; ++sweep)
	{
		double off = 0, diag = 0;
		for (int r = 0; r < n; ++r)
		{
			diag += k[r][r] * k[r][r];
			for (int c = r + 1; c < n; ++c) off += k[r][c] * k[r][c];
		}
		if (off <= 1e-30 * diag) return;
		for (int p = 0; p < n; ++p)
			for (int q = p + 1; q < n; ++q)
			{
				if (k[p][q] == 0) continue;
				const double theta = (k[q][q] - k[p][p]) / (2 * k[p][q]);
				const double t = (theta >= 0 ? 1 : -1) / (std::fabs(theta) + std::sqrt(theta * theta + 1));
				const double c = 1 / std::sqrt(t * t + 1), s = t * c;
				for (int i = 0; i < n; ++i)  // k ← k Jᵀ... as columns p, q
				{
					const double kp = k[i][p], kq = k[i][q];
					k[i][p] = c * kp - s * kq;
					k[i][q] = s * kp + c * kq;
				}
				for (int i = 0; i < n; ++i)  // and rows p, q
				{
					const double kp = k[p][i], kq = k[q][i];
					k[p][i] = c * kp - s * kq;
					k[q][i] = s * kp + c * kq;
				}
				for (int i = 0; i < n; ++i)
				{
					const double vp = v[i][p], vq = v[i][q];
					v[i][p] = c * vp - s * vq;
					v[i][q] = s * vp + c * vq;
				}
			}
	}
}

// A body's inverse inertia as the solver sees it (its angular factor applied, as the spring's effective mass in
// fillRows), held in SIMD lanes for inverseInertiaAbout: the world tensor I⁻¹ by columns, gathered once for the
// directions a step asks about.
struct InverseInertiaLanes
{
	Lanes column0, column1, column2;
	Lanes angularFactor;
};

InverseInertiaLanes inverseInertiaLanes(const btRigidBody& body)
{
	const btMatrix3x3& tensor = body.getInvInertiaTensorWorld();
	return {columnLanes(tensor, 0), columnLanes(tensor, 1), columnLanes(tensor, 2), lanesOf(body.getAngularFactor())};
}

// The body's inverse inertia about w (world): wᵀ I⁻¹ w, with the bits of w.dot(I⁻¹ * w * angularFactor) (lane i of
// the column sum is row i of I⁻¹ dotted with w, its three products added in btVector3::dot's order, MatrixLanes.h).
btScalar inverseInertiaAbout(const InverseInertiaLanes& inertia, const Lanes& w)
{
	const Lanes turned = inertia.column0 * w[0] + inertia.column1 * w[1] + inertia.column2 * w[2];
	return dotXyz(w, turned * inertia.angularFactor);
}
}  // namespace

int btQuaternionHingeConstraint::fillBilateralRows(btConstraintInfo2* info, const btTransform& transA,
												   const btTransform& transB, const Pose& pose) const
{
	// pose: joint frame A's basis and both pivots in world; q = a* ⊗ b (Q2).
	const int skip = info->rowskip;
	const bool angularOnly = m_settings.angularOnly;
	const btScalar erpFps = info->erp * info->fps;
	// Per-row ERP/CFM only when some override is set (the common case writes one ERP and leaves CFM alone).
	const bool overrides = m_settings.flags != 0;
	auto errorScale = [&](int kind) { return overrides ? rowErp(kind, info->erp) * info->fps : erpFps; };
	auto rowCfmOverride = [&](int kind, int at) {
		if (overrides && (m_settings.flags & (BT_QHINGE_FLAGS_CFM_ROW0 << kind))) info->cfm[at] = m_settings.rowCfm[kind];
	};

	// Point part: C = p_B − p_A (MATH.md, "Bullet's conventions"). Along a direction e held for the step,
	// e·Ċ = e·(v_B + ω_B × r_B − v_A − ω_A × r_A), so the row is J1 = (−e, e × r_A), J2 = (e, r_B × e); error −erp·fps·e·C
	// (Q10), with e ∈ {p, t, a} (SolverRowBasis.h: a rotation of the row space that Gauss–Seidel converges on as fast
	// as on stock's rows; computePositionRows keeps world x, y, z). The solver hands rows in zeroed; every entry of a
	// row is written all the same (straight-line stores are cheaper than skipping zeros).
	// (Vectors in SIMD lanes, MatrixLanes.h: btVector3's operations lane by lane, the same bits.)
	const Lanes pivotA = lanesOf(pose.pivotA), pivotB = lanesOf(pose.pivotB);
	const Lanes rA = pivotA - lanesOf(transA.getOrigin());
	const Lanes rB = pivotB - lanesOf(transB.getOrigin());
	// The default basis (RowBasis::Radial) unless the row-basis study hook chose another (SolverRowBasis.h).
	const btScalar invMassA = m_rbA.getInvMass(), invMassB = m_rbB.getInvMass();
	RowBasis rowBasis = RowBasis(m_rowBasis);
	if (rowBasis == RowBasis::TurnedAtStatic)
		rowBasis = invMassA > btScalar(0) && invMassB > btScalar(0) ? RowBasis::Radial : RowBasis::RadialTurned;
	const Lanes hingeAxis = lanesOf(pose.axesA[2]);
	PointRowBasis basis;
	if (rowBasis == RowBasis::World)
	{
		basis.p = lanesOf(btVector3(1, 0, 0));
		basis.t = lanesOf(btVector3(0, 1, 0));
		basis.a = lanesOf(btVector3(0, 0, 1));
	}
	else if (rowBasis == RowBasis::JointFrame)
	{
		basis.p = lanesOf(pose.axesA[0]);
		basis.t = lanesOf(pose.axesA[1]);
		basis.a = hingeAxis;
	}
	else if (rowBasis == RowBasis::Heavy && invMassA > btScalar(0) && invMassB > btScalar(0))
		basis = pointRowBasis(pose.axesA, rA, rB, invMassA <= invMassB ? btScalar(1) : btScalar(0),
							  invMassA <= invMassB ? btScalar(0) : btScalar(1));  // the heavier body's arm alone
	else
		basis = pointRowBasis(pose.axesA, rA, rB, invMassA, invMassB);
	// World has no row along the hinge axis; the others' third row is the axis.
	const bool axisRow = rowBasis != RowBasis::World;
	// Only the study bases turn the quaternion rows toward p (SolverRowBasis.h: the turn is what lost on the
	// inertia-ratio pendulum).
	const bool turnQuaternionRows = rowBasis == RowBasis::RadialTurned || rowBasis == RowBasis::Heavy ||
									rowBasis == RowBasis::Decoupled || rowBasis == RowBasis::RadialTurned45 ||
									rowBasis == RowBasis::RadialTurned90;

	// Quaternion part (Q7, Q9, Q10; the log form beyond 90°, Q12): body A −g, body B +g, error −erp·fps·C, as
	// derived (only the study bases turn it within its plane so the first row lies along p, SolverRowBasis.h).
	// Written after the point rows; computed first, as the point rows take a multiple of them (below).
	AngularRows angular;
	computeAngularRowsFromAxes(pose.axesA, pose.q, angular);
	Lanes turnedU = lanesOf(angular.rowU), turnedV = lanesOf(angular.rowV);
	btScalar errorU = -errorScale(kAngularKind) * angular.errorU;
	btScalar errorV = -errorScale(kAngularKind + 1) * angular.errorV;
	if (turnQuaternionRows)
	{
		const Lanes rowU = turnedU, rowV = turnedV;
		btScalar cosPsi, sinPsi;
		quaternionRowTurn(rowU, rowV, basis.p, cosPsi, sinPsi);
		if (rowBasis == RowBasis::RadialTurned45 || rowBasis == RowBasis::RadialTurned90)
		{
			// a further turn by 45° or 90°: (c, s) ← (c cos β − s sin β, s cos β + c sin β)
			const btScalar cb = rowBasis == RowBasis::RadialTurned90 ? btScalar(0) : SIMDSQRT12;
			const btScalar sb = rowBasis == RowBasis::RadialTurned90 ? btScalar(1) : SIMDSQRT12;
			const btScalar c = cosPsi * cb - sinPsi * sb, s = sinPsi * cb + cosPsi * sb;
			cosPsi = c;
			sinPsi = s;
		}
		turnedU = rowU * cosPsi + rowV * sinPsi;
		turnedV = rowV * cosPsi - rowU * sinPsi;
		errorU = -errorScale(kAngularKind) * (cosPsi * angular.errorU + sinPsi * angular.errorV);
		errorV = -errorScale(kAngularKind + 1) * (cosPsi * angular.errorV - sinPsi * angular.errorU);
	}

	// Rows in the order point, quaternion (the default) or quaternion, point (the study hook's angularRowsFirst).
	const int pointFirstRow = m_angularRowsFirst ? 2 : 0;
	int row = pointFirstRow;
	if (!angularOnly)
	{
		// The axial parts of the lever arms (along the hinge axis a) couple a point row to the swing through the
		// bodies' inertia across the axis: a pivot 1 m along the axis from a body's centre held 0.04 m apart after 10
		// Gauss–Seidel sweeps where stock, which drops those parts, holds 2e-10 m. Shifting both arms by the same
		// δ a changes a point row by −δ (a × e)·(ω_B − ω_A), which vanishes wherever the quaternion rows hold; written
		// here as an exact row operation with them (the point row minus δ (c_u u' + c_v v') on both the Jacobian and
		// the error, c the combination of the quaternion rows nearest a × e), so the rows keep their solution set and
		// their exactness (SolverRowBasis.h: a change of row basis held for the step).
		// δ, per point row e: after the shift the arms' axial parts are α_X = axial_X − δ, and the row turns body X
		// through α_X about w = a × e, which adds α_X² i_X to the row's effective inverse mass (i_X = wᵀ I_X⁻¹ w: body
		// X's inverse inertia about w) beside the translational 1/m_A + 1/m_B. δ is stock's, the axial offsets blended
		// by inverse mass (a static side keeps its own; the dynamic side's axial arm becomes 0), wherever that keeps
		// each body's share α_X² i_X within the translational part; else the blend nearest it that does, or where none
		// does, the one that makes the larger share least (α_A² i_A = α_B² i_B). The mass blend alone gives the lever
		// to the lighter body however small its inertia: a 0.2 kg puck, 3e-4 kg·m², locked to the end of a 1 m arm
		// whose centre of mass lies on the axis took 0.29 m of the arm's 1 m (α² i = 250 against 7 kg⁻¹), the row
		// operation carried 0.29 m times the puck's angular error into the point rows, and the joints separated
		// 1.7–2.1× more than stock's (issue 16, two_joint_robot; docs/ROW_BASIS.md); now the puck keeps 0.06–0.12 m.
		// (The blend by inverse inertia, which makes the row's effective mass least, fixes that robot too but raised
		// the ragdoll's misalignment, whose mass-blended levers are within the bound: 16 seeds, 50 iterations, RMS
		// 1.16 → 1.48× stock's.)
		const Lanes c = pivotB - pivotA;
		const btScalar invMassSum = invMassA + invMassB;
		const btScalar weightA = invMassSum > btScalar(0) ? invMassB / invMassSum : btScalar(0.5);
		const btScalar axialA = dotXyz(hingeAxis, rA), axialB = dotXyz(hingeAxis, rB);
		const btScalar massBlend = axialA - (axialA - axialB) * weightA;
		const btScalar uu = dotXyz(turnedU, turnedU), uv = dotXyz(turnedU, turnedV), vv = dotXyz(turnedV, turnedV);
		const btScalar det = uu * vv - uv * uv;
		// (not for an offset at round-off level, 8 ε of the arms: a chain whose pivots lie across its axes keeps its bits)
		const btScalar roundOff = btScalar(8) * SIMD_EPSILON * (btSqrt(dotXyz(rA, rA)) + btSqrt(dotXyz(rB, rB)));
		const bool quaternionRowsIndependent = det > SIMD_EPSILON * uu * vv;
		const bool staticA = invMassA < SIMD_EPSILON, staticB = invMassB < SIMD_EPSILON;  // as stock
		// The mass blend holds for every row when it holds against each body's largest inverse inertia (|w| ≤ 1): the
		// common case, decided once here instead of per row (a margin of 1e-3 covers the rounding of the exact test).
		// δ lies between the two axial offsets, so none beyond round-off needs no shift; nor does a mass blend that
		// holds at round-off level (symmetric arms of equal bodies: δ = 0).
		auto largestInverseInertia = [](const btRigidBody& body) {
			const btVector3& d = body.getInvInertiaDiagLocal();
			const btVector3& f = body.getAngularFactor();
			return btMax(d[0], btMax(d[1], d[2])) * btMax(btFabs(f[0]), btMax(btFabs(f[1]), btFabs(f[2])));
		};
		const bool axialOffsets = quaternionRowsIndependent && (btFabs(axialA) > roundOff || btFabs(axialB) > roundOff);
		bool massBlendHolds = true;
		if (axialOffsets && !staticA && !staticB)  // a static side has no share
		{
			const btScalar alphaA = axialA - massBlend, alphaB = axialB - massBlend;
			const btScalar shareBound = btScalar(0.999) * invMassSum;
			massBlendHolds = alphaA * alphaA * largestInverseInertia(m_rbA) <= shareBound &&
							 alphaB * alphaB * largestInverseInertia(m_rbB) <= shareBound;
		}
		const bool shift = axialOffsets && (!massBlendHolds || btFabs(massBlend) > roundOff);
		// the bodies' tensors for the exact test, gathered once for both rows that ask
		InverseInertiaLanes inertiaLanesA{}, inertiaLanesB{};
		if (!massBlendHolds)
		{
			inertiaLanesA = inverseInertiaLanes(m_rbA);
			inertiaLanesB = inverseInertiaLanes(m_rbB);
		}
		auto axialShift = [&](const Lanes& w) {
			if (massBlendHolds) return massBlend;
			const btScalar inertiaA = inverseInertiaAbout(inertiaLanesA, w), inertiaB = inverseInertiaAbout(inertiaLanesB, w);
			// body X's share stays within invMassSum while |axial_X − δ| ≤ reach_X
			btScalar low = -BT_LARGE_FLOAT, high = BT_LARGE_FLOAT;
			if (inertiaA > btScalar(0))
			{
				const btScalar reach = btSqrt(invMassSum / inertiaA);
				low = axialA - reach;
				high = axialA + reach;
			}
			if (inertiaB > btScalar(0))
			{
				const btScalar reach = btSqrt(invMassSum / inertiaB);
				low = btMax(low, axialB - reach);
				high = btMin(high, axialB + reach);
			}
			if (low <= high) return btMax(low, btMin(high, massBlend));
			// no blend meets both: equal shares, |α_A| √i_A = |α_B| √i_B (both inertias are positive here)
			const btScalar rootA = btSqrt(inertiaA), rootB = btSqrt(inertiaB);
			return (axialA * rootA + axialB * rootB) / (rootA + rootB);
		};
		// A joint to a static body (a one-body hinge, a door on the world): stock takes the lever arm off the axial row
		// altogether ("to make constraint between static and dynamic objects more rigid"), and so does this: the arm's
		// part a × r lies across the axis, in the quaternion rows' span, so the axial row takes off the multiple of
		// their Jacobian that cancels its dynamic side's angular part (a door 12.3 m from its pivot, gravity along the
		// axis: its pivot sagged 0.016 m at 10 iterations, where stock's holds). Its error stays the pivot's own axial
		// offset, as stock's: taking off the quaternion rows' errors as well made the row's target "the centre where an
		// aligned joint would have it", so whatever swing Gauss–Seidel leaves at the joint became a standing pivot offset
		// of lever × swing. A thin light link between an anchor and a heavy body leaves one at every iteration count
		// (the heavy body's swing reaches the anchor only through the link's small inertia; no row basis of one joint
		// removes that): double_pendulum's anchor stood 0.052 m off (0.5 m × sin 6.3°), 2.5× stock's largest separation
		// at 250 iterations, now 1.06×; Gazebo's inertia-ratio pendulum's RMS separation 2.4 → 1.3× stock's at 50
		// (docs/ROW_BASIS.md). Both errors still go to zero together: the pivot's rate is −erp·fps times its offset plus
		// the lever times the swing rate the quaternion rows ask for, a transient that dies with the swing.
		const bool freeAxialArm = axisRow && staticA != staticB && quaternionRowsIndependent;
		// The row operation both take: the point row minus c_u, c_v times the quaternion rows (A side −u', −v', B side
		// +u', +v', and errors errorU, errorV where `error` is given: the axial shift's, not the free axial arm's), (c_u,
		// c_v) = scale × the coefficients of w's projection on (u', v'); w by value: it may be one of the arms the
		// operation changes.
		auto takeOffQuaternionRows = [&](const Lanes w, btScalar scale, Lanes& angularA, Lanes& angularB,
										 btScalar* error) {
			const btScalar wu = dotXyz(turnedU, w), wv = dotXyz(turnedV, w);
			const btScalar cu = scale * (vv * wu - uv * wv) / det, cv = scale * (uu * wv - uv * wu) / det;
			const Lanes g = turnedU * cu + turnedV * cv;
			angularA += g;
			angularB -= g;
			if (error) *error -= cu * errorU + cv * errorV;
		};
		// Point row i along e; written out for each of the three (always inlined: the tests on i fold away).
		auto pointRow = [&](int i, const Lanes& e) QUATHINGE_ALWAYS_INLINE {
			const int at = row * skip;
			Lanes angularA = crossLanes(e, rA), angularB = crossLanes(rB, e);
			btScalar error = -errorScale(kLinearKind + i) * dotXyz(e, c);
			// the arms' axial offset δ: w = a × e (a × a = 0: the axial row needs none)
			if (shift && (i < 2 || !axisRow))
			{
				const Lanes w = crossLanes(hingeAxis, e);
				const btScalar delta = axialShift(w);
				if (btFabs(delta) > roundOff) takeOffQuaternionRows(w, delta, angularA, angularB, &error);
			}
			// the axial row's whole lever on the dynamic side, J1 (A) or J2 (B): A's + g = 0, or B's − g = 0 (the
			// Jacobian only: the error stays the pivot's, above)
			if (freeAxialArm && i == 2)
				takeOffQuaternionRows(staticB ? -angularA : angularB, btScalar(1), angularA, angularB, nullptr);
			storeXyzNegatedAndAsIs(info->m_J1linearAxis + at, info->m_J2linearAxis + at, e);
			storeXyz(info->m_J1angularAxis + at, angularA);
			storeXyz(info->m_J2angularAxis + at, angularB);
			info->m_constraintError[at] = error;
			rowCfmOverride(kLinearKind + i, at);
			++row;
		};
		pointRow(0, basis.p);
		pointRow(1, basis.t);
		pointRow(2, basis.a);
	}

	if (m_angularRowsFirst) row = 0;
	const int atU = row * skip, atV = atU + skip;
	storeXyzNegatedAndAsIs(info->m_J1angularAxis + atU, info->m_J2angularAxis + atU, turnedU);
	storeXyzNegatedAndAsIs(info->m_J1angularAxis + atV, info->m_J2angularAxis + atV, turnedV);
	info->m_constraintError[atU] = errorU;
	info->m_constraintError[atV] = errorV;
	rowCfmOverride(kAngularKind, atU);
	rowCfmOverride(kAngularKind + 1, atV);
	const int rows = angularOnly ? 2 : 5;
	if (rowBasis == RowBasis::Decoupled) decoupleRows(info, rows);
	return rows;
}

void btQuaternionHingeConstraint::decoupleRows(btConstraintInfo2* info, int rows) const
{
	// RowBasis::Decoupled (study only): the joint's rows J_i, errors b_i replaced by Σ_i V_ik J_i, Σ_i V_ik b_i with
	// V the eigenvectors of the joint's own K = J M⁻¹ Jᵀ (an orthogonal change of the rows' basis: the same solution
	// set; the joint's block of K becomes diagonal). Per-row CFM overrides are not carried over.
	const int skip = info->rowskip;
	double k[5][5], v[5][5], j[5][12], b[5];
	const btMatrix3x3& inertiaA = m_rbA.getInvInertiaTensorWorld();
	const btMatrix3x3& inertiaB = m_rbB.getInvInertiaTensorWorld();
	btVector3 linA[5], angA[5], linB[5], angB[5], angAI[5], angBI[5];
	for (int r = 0; r < rows; ++r)
	{
		const int at = r * skip;
		linA[r].setValue(info->m_J1linearAxis[at], info->m_J1linearAxis[at + 1], info->m_J1linearAxis[at + 2]);
		angA[r].setValue(info->m_J1angularAxis[at], info->m_J1angularAxis[at + 1], info->m_J1angularAxis[at + 2]);
		linB[r].setValue(info->m_J2linearAxis[at], info->m_J2linearAxis[at + 1], info->m_J2linearAxis[at + 2]);
		angB[r].setValue(info->m_J2angularAxis[at], info->m_J2angularAxis[at + 1], info->m_J2angularAxis[at + 2]);
		angAI[r] = inertiaA * angA[r];
		angBI[r] = inertiaB * angB[r];
		for (int c = 0; c < 3; ++c)
		{
			j[r][c] = linA[r][c];
			j[r][3 + c] = angA[r][c];
			j[r][6 + c] = linB[r][c];
			j[r][9 + c] = angB[r][c];
		}
		b[r] = info->m_constraintError[at];
	}
	for (int r = 0; r < rows; ++r)
		for (int c = 0; c < rows; ++c)
			k[r][c] = double(m_rbA.getInvMass() * linA[r].dot(linA[c]) + angA[r].dot(angAI[c]) +
							 m_rbB.getInvMass() * linB[r].dot(linB[c]) + angB[r].dot(angBI[c]));
	symmetricEigenvectors(k, v, rows);
	for (int col = 0; col < rows; ++col)
	{
		const int at = col * skip;
		double out[12] = {0}, error = 0;
		for (int r = 0; r < rows; ++r)
		{
			for (int c = 0; c < 12; ++c) out[c] += v[r][col] * j[r][c];
			error += v[r][col] * b[r];
		}
		for (int c = 0; c < 3; ++c)
		{
			info->m_J1linearAxis[at + c] = btScalar(out[c]);
			info->m_J1angularAxis[at + c] = btScalar(out[3 + c]);
			info->m_J2linearAxis[at + c] = btScalar(out[6 + c]);
			info->m_J2angularAxis[at + c] = btScalar(out[9 + c]);
		}
		info->m_constraintError[at] = btScalar(error);
	}
}
