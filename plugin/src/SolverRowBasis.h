// The basis the solver's five bilateral rows are written in (a rotation of the row space: same equations).
//
// Why. Bullet's solver is projected Gauss–Seidel: it meets one row at a time, so how far a joint converges in a fixed
// number of iterations depends on how strongly its rows are coupled through the bodies' masses, K = J M⁻¹ Jᵀ. Point
// rows along world x, y, z couple through the bodies' rotational inertia (the lever arm turns a push along one axis
// into a torque felt by the others); btHingeConstraint writes them along
//   p  — the radial direction from the centres of mass to the hinge axis (the arms blended by inverse mass),
//   t  — a × p, tangential, and
//   a  — the hinge axis,
// where the radial row has (almost) no lever arm and the three are nearly decoupled. Measured at 60 Hz / 10 iterations
// before this basis: a cube on a 0.5 m arm separated 2.6× more than under stock, a 3-link chain of them 3.9× more,
// and with gravity partly along a tilted hinge axis the axes drifted 0.7°–2.4° where stock keeps them within 1e-5°
// (tests/test_parity_stock.cpp holds these scenes to stock's figures).
//
// What stays exact. A row-space rotation M (orthogonal, 5×5, block diagonal: 3×3 for the point part, 2×2 for the
// quaternion part) changes neither the constraint's solution set nor the rows' exactness: the rows written are
// M·J and the errors M·C, where J = ∂C/∂v is exact (MATH.md Q4–Q10, Q12). M is taken at the current pose and held
// for the step (as every solver holds its rows), so M·J is the derivative of M·C at fixed M — what the finite-difference
// test checks. The lever arms' axial parts, which stock drops by blending the arms by mass, are taken off by a row
// operation instead (fillBilateralRows: each point row minus the multiple of the quaternion rows those parts add,
// both arms moved to stock's mass-blended axial offset, kept within a bound on each body's rotational share of the
// row; the same kind of change of row basis, not orthogonal but held for the step as M is), and a is joint frame A's
// z as it is (stock blends A's and B's axes; no blend is needed for a basis).
//   point part:       rows e·(v_B + ω_B × r_B − v_A − ω_A × r_A) for e ∈ {p, t, a}, error e·(p_B − p_A)
//   quaternion part:  the two Q7 rows (u, v) (or their log form past 90°, Q12) as derived: along joint frame A's
//                     x̂ and ŷ (to first order), fixed in body A rather than in the lever arms.
// Until issue 16 the quaternion rows were turned within their plane so that u' lay along p (stock writes its two
// angular rows along p and t): (u', v') = (c u + s v, c v − s u), (c, s) = (u·p, v·p)/|(u·p, v·p)| (RowBasis::
// RadialTurned keeps it for the sweep). The row-basis sweep (docs/ROW_BASIS.md) found that turn to be what lost to
// stock on Gazebo's inertia-ratio pendulum: a thin light link between an anchor and a heavy link, where p lies along
// the thin link and u' becomes the swing about the link's own long axis (its smallest inertia). Unturned, the
// out-of-plane angle over 3 s went from 0.821/0.366/0.341 rad to 0.114/0.036/0.012 rad at 50/100/250 iterations
// (stock 0.186/0.251/0.225); 23 of the sweep's 31 scenes moved by less than 10%.
#ifndef QUATHINGE_SOLVER_ROW_BASIS_H
#define QUATHINGE_SOLVER_ROW_BASIS_H

#include "InputChecks.h"
#include "LinearMath/btMatrix3x3.h"
#include "LinearMath/btVector3.h"
#include "MatrixLanes.h"
#include "quathinge/btQuaternionHingeConstraint.h"

namespace quathinge
{
/// The bases the bilateral rows can be written in (docs/ROW_BASIS.md compares them). Every one is a change of the
/// rows' basis held for the step: the same constraint, converged on differently by Gauss–Seidel.
enum class RowBasis : int
{
	Radial = 0,        ///< the default: p, t, a (pointRowBasis below), quaternion rows as derived
	World = 1,         ///< point rows along world x, y, z; quaternion rows as derived (u, v)
	Heavy = 2,         ///< p, t, a from the heavier dynamic body's arm alone (as RadialTurned when one side is static),
					   ///< quaternion rows turned toward that p
	Decoupled = 3,     ///< the five rows turned into the eigenvectors of the joint's own K = J M⁻¹ Jᵀ (5×5 diagonal)
	JointFrame = 4,    ///< point rows along joint frame A's x, y, z; quaternion rows as derived (u ≈ x̂, v ≈ ŷ)
	RadialTurned = 5,  ///< the default before issue 16: Radial with the quaternion rows turned so u' lies along p
	/// per joint: RadialTurned where one side is static, Radial between two dynamic bodies
	TurnedAtStatic = 6,
	RadialTurned45 = 7,  ///< as RadialTurned, then turned 45° further in their plane (u' halfway between p and a × p)
	RadialTurned90 = 8,  ///< as RadialTurned, then turned 90° further (u' along a × p)
	Count = 9
};
inline const char* rowBasisName(RowBasis basis)
{
	switch (basis)
	{
		case RowBasis::Radial: return "radial";
		case RowBasis::World: return "world";
		case RowBasis::Heavy: return "heavy";
		case RowBasis::Decoupled: return "decoupled";
		case RowBasis::JointFrame: return "jointframe";
		case RowBasis::RadialTurned: return "radial-turned";
		case RowBasis::TurnedAtStatic: return "turned-at-static";
		case RowBasis::RadialTurned45: return "radial-turned45";
		case RowBasis::RadialTurned90: return "radial-turned90";
		case RowBasis::Count: break;
	}
	return "?";
}

/// The in-tree hook that sets a joint's row basis and order (the sweep, demos/sweep, and tests). Not public API: the
/// basis is the library's choice of how to present one constraint to the solver, not a setting of the joint, so it is
/// neither in btQuaternionHingeSettings nor serialized. Refuses a value outside RowBasis as the setters refuse
/// theirs (InputChecks.h: thrown, or reported and false returned) and then changes nothing.
struct SolverRowBasisAccess
{
	static bool set(btQuaternionHingeConstraint& joint, RowBasis basis, bool angularRowsFirst)
	{
		const int value = int(basis);
		if (value < 0 || value >= int(RowBasis::Count))
			return check::fail("quathinge::SolverRowBasisAccess::set", "basis", "is not a RowBasis", btScalar(value));
		joint.m_rowBasis = value;
		joint.m_angularRowsFirst = angularRowsFirst;
		return true;
	}
	static RowBasis basis(const btQuaternionHingeConstraint& joint) { return RowBasis(joint.m_rowBasis); }
	static bool angularRowsFirst(const btQuaternionHingeConstraint& joint) { return joint.m_angularRowsFirst; }
};
/// The three point-row directions (world, orthonormal, right-handed: t = a × p, p = t × a), as SIMD lanes
/// (MatrixLanes.h: the same operations as btVector3's, so the same bits).
struct PointRowBasis
{
	Lanes p;  ///< radial: from the centres of mass toward the hinge axis
	Lanes t;  ///< tangential: a × p
	Lanes a;  ///< the hinge axis: joint frame A's z
};

/// The basis for joint frame A's axes in world `axesA` (the rows of R_Aᵀ), lever arms `armA`, `armB` (pivot − centre of mass, world) and
/// inverse masses `invMassA`, `invMassB` (zero for static or kinematic bodies).
inline PointRowBasis pointRowBasis(const btMatrix3x3& axesA, const Lanes& armA, const Lanes& armB, btScalar invMassA,
								   btScalar invMassB)
{
	// Weights as btHingeConstraint's: the lighter side's arm counts more (a static side: only the dynamic side's).
	const btScalar invMassSum = invMassA + invMassB;
	const btScalar weightA = invMassSum > btScalar(0) ? invMassB / invMassSum : btScalar(0.5);
	PointRowBasis basis;
	basis.a = lanesOf(axesA[2]);
	// t = a × radial needs no projection of the arms across the axis: the cross product drops their axial parts.
	basis.t = crossLanes(basis.a, armB * weightA + armA * (btScalar(1) - weightA));
	const btScalar length2 = dotXyz(basis.t, basis.t);
	if (length2 > SIMD_EPSILON)
	{
		basis.t *= btScalar(1) / btSqrt(length2);
		basis.p = crossLanes(basis.t, basis.a);  // orthonormal to round-off however short the radial part was
	}
	else
	{
		// Pivot on the axis through the centres of mass: any direction across the axis decouples as well; frame A's x
		// and y turn with the joint, so warm starting stays meaningful.
		basis.p = lanesOf(axesA[0]);
		basis.t = lanesOf(axesA[1]);
	}
	return basis;
}

/// The turn (c, s) of the quaternion part's rows u, v (world) that puts u' = c u + s v along p's part in their plane;
/// (1, 0) when p has no part there (RowBasis::RadialTurned, Heavy, Decoupled).
inline void quaternionRowTurn(const Lanes& u, const Lanes& v, const Lanes& p, btScalar& c, btScalar& s)
{
	const btScalar up = dotXyz(u, p), vp = dotXyz(v, p);
	const btScalar n2 = up * up + vp * vp;
	if (n2 > SIMD_EPSILON)
	{
		const btScalar inv = btScalar(1) / btSqrt(n2);
		c = up * inv;
		s = vp * inv;
	}
	else
	{
		c = 1;
		s = 0;
	}
}

}  // namespace quathinge

#endif
