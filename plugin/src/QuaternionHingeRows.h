// The quaternion two-row part: the hinge's two angular rows from the relative quaternion.
//
// Derivation (docs/MATH.md, from the seed note):
//   (Q2)  q = a* ⊗ b                      relative rotation of joint frame B in joint frame A
//   (Q4)  C_u = q_v · x̂ = 0,  C_v = q_v · ŷ = 0          (an ideal hinge has q = (cos θ/2, sin θ/2 ẑ))
//   (Q5)  q̇ = ½ Ω ⊗ q,  Ω = R_Aᵀ (ω_B − ω_A)
//   (Q7)  Ċ_u = g_u · (ω_B − ω_A),  g_u = ½ R_A (q0 x̂ + q_v × x̂)   (likewise g_v with ŷ)
//   (Q9)  rows scaled by 2: error 2C, Jacobian 2g (unit length on the hinge)
//   (Q10) Bullet drives J·v toward m_constraintError = −erp·fps·C with J = ∂C/∂v
//
// The flipped hemisphere (Q12). With s = |(q_x, q_y)| = sin(φ/2) and c = sqrt(q0² + q_z²) = cos(φ/2), φ the angle
// between the two hinge axes, the Gram determinant of the two Q7 rows is c²: the rows lose rank as φ → π, and the
// radial row (along the swing direction n = (q_x, q_y)/s) shrinks to length c while its error 2s is largest, so a
// Baumgarte bias asks for a rotation rate ∝ s/c that grows without bound near the flip and is zero at it.
// Beyond φ = 90° (c² < ½) the part therefore switches to the swing logarithm C_L = φ·n = κ·2(q_x, q_y), κ = φ/(2s):
// its rows are the exact derivative of C_L (product rule below), the radial row has unit length at every φ up to and
// including π, and its error is the swing angle itself. At the exact flip (c = 0) the radial direction is the limit
// taken along the swing axis n. Both forms agree to second order near the hinge; the switch happens only 90° off it.
//
// Glossary: a, b — world orientations of the joint frames (body orientation ⊗ frame rotation); x̂, ŷ, ẑ — joint frame
// A's axes; ẑ is the hinge axis; θ — hinge angle (Q11); φ — swing (axis misalignment) angle.
#ifndef QUATHINGE_QUATERNION_HINGE_ROWS_H
#define QUATHINGE_QUATERNION_HINGE_ROWS_H

#include "LinearMath/btMatrix3x3.h"
#include "LinearMath/btQuaternion.h"
#include "LinearMath/btVector3.h"
#include "MatrixLanes.h"

namespace quathinge
{
/// The two angular rows in world coordinates. Body B's Jacobian row is +rowU / +rowV, body A's is −rowU / −rowV.
struct AngularRows
{
	btVector3 rowU;   ///< ∂C_u/∂ω_B (world), Q7 scaled per Q9 (or ∂C_L,u/∂ω_B in the flipped hemisphere)
	btVector3 rowV;   ///< ∂C_v/∂ω_B (world)
	btScalar errorU;  ///< C_u: 2 q_v·x̂ (Q4, Q9), or φ n·x̂ when flipped
	btScalar errorV;  ///< C_v
	bool logForm;     ///< the swing-logarithm form was used (axes more than 90° apart)
};

/// The Q12 switch, shared by the rows and the axial row direction (HingeAngle.h): the two hinge axes are more than
/// 90° apart, c² = q0² + q_z² = cos²(φ/2) < ½.
inline bool beyondQuarterTurn(const btQuaternion& q) { return q.w() * q.w() + q.z() * q.z() < btScalar(0.5); }

/// (Q2) q = a* ⊗ b.
inline btQuaternion relativeQuaternion(const btQuaternion& a, const btQuaternion& b) { return a.inverse() * b; }

/// The log form's rows in joint frame A and their errors (Q12), given hu, hv (rowsInFrameA); out of line: asked only
/// for a joint more than 90° off its axis.
void logFormRowsInFrameA(const btQuaternion& q, const btVector3& hu, const btVector3& hv, btVector3& gu, btVector3& gv,
						 btScalar& cu, btScalar& cv);

/// Rows in joint frame A, and errors, for the relative quaternion q. Inline, as computeAngularRowsFromAxes below:
/// the solver asks for them at every step.
inline void rowsInFrameA(const btQuaternion& q, btVector3& gu, btVector3& gv, btScalar& cu, btScalar& cv, bool& logForm)
{
	const btScalar w = q.w(), x = q.x(), y = q.y(), z = q.z();
	// (Q7) q0 x̂ + q_v × x̂ and q0 ŷ + q_v × ŷ; with the Q9 factor 2 the ½ of Q7 cancels.
	const btVector3 hu(w, z, -y);
	const btVector3 hv(-z, w, x);
	logForm = beyondQuarterTurn(q);  // the swing-logarithm form past 90° (above, Q12)
	if (!logForm)
	{
		gu = hu;  // (Q7, Q9)
		gv = hv;
		cu = btScalar(2) * x;  // (Q4, Q9)
		cv = btScalar(2) * y;
		return;
	}
	logFormRowsInFrameA(q, hu, hv, gu, gv, cu, cv);
}

/// The constraint value the rows are the derivative of (for finite-difference tests): C (Q4, Q9) or C_L.
void angularConstraintValue(const btQuaternion& a, const btQuaternion& b, btScalar& cu, btScalar& cv);

/// Both rows and their errors for joint-frame orientations a (A) and b (B).
void computeAngularRows(const btQuaternion& a, const btQuaternion& b, AngularRows& out);

/// The same from joint frame A's world basis R_A and the relative quaternion q = a* ⊗ b (the solver's path: one
/// matrix-to-quaternion conversion per joint).
void computeAngularRows(const btMatrix3x3& frameAInWorld, const btQuaternion& q, AngularRows& out);

/// The same from frame A's axes in world (the rows of R_Aᵀ, as the joint keeps them): the same bits.
inline void computeAngularRowsFromAxes(const btMatrix3x3& axesA, const btQuaternion& q, AngularRows& out)
{
	btVector3 gu, gv;
	rowsInFrameA(q, gu, gv, out.errorU, out.errorV, out.logForm);
	// (Q7) g = R_A (…), R_A's columns being frame A's axes (MatrixLanes.h: the products of btMatrix3x3 * btVector3).
	storeLanes(out.rowU, timesTransposed(axesA, gu));
	storeLanes(out.rowV, timesTransposed(axesA, gv));
}

/// Swing angle φ ∈ [0, π] between the two hinge axes (the misalignment the two rows remove).
btScalar swingAngle(const btQuaternion& q);

}  // namespace quathinge

#endif
