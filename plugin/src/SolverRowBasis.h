// The basis the solver's five bilateral rows are written in (a rotation of the row space: same equations).
//
// Why. Bullet's solver is projected Gauss–Seidel: it meets one row at a time, so how fast a joint converges in a fixed
// number of iterations depends on how strongly its rows are coupled through the bodies' masses, K = J M⁻¹ Jᵀ. Point
// rows along world x, y, z couple through the bodies' rotational inertia (the lever arm turns a push along one axis
// into a torque felt by the others); btHingeConstraint writes them along
//   a  — the hinge axis (frame A's and B's z blended by inverse mass),
//   p  — the radial direction from the centres of mass to the axis (blended likewise), and
//   t  — a × p,
// where the radial row has no lever arm at all and the three are nearly decoupled. Measured at 60 Hz / 10 iterations
// before this basis: a cube on a 0.5 m arm separated 2.6× more than under stock, a 3-link chain of them 3.9× more,
// and with gravity partly along a tilted hinge axis the axes drifted 0.7°–2.4° where stock keeps them within 1e-5°.
//
// What stays exact. A row-space rotation M (orthogonal, 5×5, block diagonal: 3×3 for the point part, 2×2 for the
// quaternion part) changes neither the constraint's solution set nor the rows' exactness: the rows written are
// M·J and the errors M·C, where J = ∂C/∂v is exact (MATH.md Q4–Q10, Q12). M is taken at the current pose and held
// for the step (as every solver holds its rows), so M·J is the derivative of M·C at fixed M — what the finite-difference
// test checks. The lever arms stay the true ones (stock blends them by mass, which is not a derivative of anything).
//   point part:       rows e·(v_B + ω_B × r_B − v_A − ω_A × r_A) for e ∈ {p, t, a}, error e·(p_B − p_A)
//   quaternion part:  the two Q7 rows (or their log form past 90°, Q12) turned within their plane so that the first
//                     lies along p (stock writes its two angular rows along p and t too).
// The quaternion turn uses the part's own plane: in joint frame A, row u runs along (q0, q_z)/c rotated from x̂ (Q7:
// h_u = (q0, q_z, −q_y)), so the turn (cos ψ, sin ψ) takes that direction to p's. It flips sign with q, as the rows do,
// so the rotated rows do not depend on the quaternion's sign (Q3).
#ifndef QUATHINGE_SOLVER_ROW_BASIS_H
#define QUATHINGE_SOLVER_ROW_BASIS_H

#include "LinearMath/btQuaternion.h"
#include "LinearMath/btTransform.h"
#include "LinearMath/btVector3.h"

namespace quathinge
{
/// The three point-row directions (world, orthonormal, right-handed: t = a × p).
struct PointRowBasis
{
	btVector3 p;  ///< radial: from the centres of mass toward the hinge axis
	btVector3 t;  ///< tangential: a × p
	btVector3 a;  ///< the hinge axis, blended by inverse mass as btHingeConstraint does
};

/// The basis for joint frames `frameA`, `frameB` (world) on bodies with centres of mass `comA`, `comB` and inverse
/// masses `invMassA`, `invMassB` (zero for static or kinematic bodies).
PointRowBasis pointRowBasis(const btTransform& frameA, const btTransform& frameB, const btVector3& comA,
							const btVector3& comB, btScalar invMassA, btScalar invMassB);

/// The 2×2 rotation (cos ψ, sin ψ) that turns the quaternion part's rows (u, v) into (u', v') = (c u + s v, −s u + c v)
/// with u' along p: `radialInFrameA` is p in joint frame A's coordinates, q = a* ⊗ b (Q2). Returns (1, 0) when p has
/// no component across the hinge axis.
void quaternionRowTurn(const btVector3& radialInFrameA, const btQuaternion& q, btScalar& cosPsi, btScalar& sinPsi);

}  // namespace quathinge

#endif
