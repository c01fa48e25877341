// The rows of a 6-dof whose three angles are locked at 0 (btQuaternionHingeStabilizerSettings::
// projectLockedConstraints): a slider (a btGeneric6DofSpring2Constraint, btGeneric6DofConstraint or
// btGeneric6DofSpringConstraint with one or two linear axes free, as pybullet and the URDF scenes build a prismatic
// joint; a btSliderConstraint with its turn locked at 0, Bullet's default) or a weld (all six locked;
// btFixedConstraint). Both 6-dof families and the slider mean the same by a lock (PointRows.h). docs/MATH.md, "Locked
// 6-dofs in the projection".
//
// With frame A's axes e_i (world, R_FA's columns), its pivot p_A, frame B's pivot p_B, d = p_B − p_A and the locked
// values o_i (Bullet: low == high), one row per locked linear axis i, in axis order:
//   C_i = e_i·d − o_i,   J_i = (−e_i, e_i × (p_B − x_A) | e_i, r_B × e_i)
// (v_A, ω_A | v_B, ω_B; x_A body A's centre of mass, r_B = p_B − x_B): e_i turns with body A, so ω_A enters through
// ė_i·d = ω_A·(e_i × d) as well as through A's arm. Then three angular rows from the relative rotation of the frames,
// q = a* ⊗ b (a, b their world orientations, w ≥ 0 taken), C = 2 q_v (frame A's coordinates; the rotation vector to
// first order), and since q̇ = ½ (0, u) ⊗ q with u = R_FAᵀ (ω_B − ω_A),
//   d(2 q_v)/dt = (w I − [q_v]×) u,   J = (0, −G | 0, G),   G = (w I − [q_v]×) R_FAᵀ.
// Both are the exact derivatives of their C (tests/test_stabilizer_locked.cpp checks them against finite differences),
// so Newton converges on them as on the hinge's rows. The linear part is not ±I (it turns with body A): the assembly
// and the deltas take the general product for these slots, as for contact slots (IslandSystem.h).
#ifndef QUATHINGE_STABILIZER_LOCKED_ROWS_H
#define QUATHINGE_STABILIZER_LOCKED_ROWS_H

#include "PointRows.h"

#include "LinearMath/btQuaternion.h"
#include "LinearMath/btTransform.h"

namespace quathinge
{
namespace stabilizer
{
/// A 6-dof whose three angles are locked at 0 (`locks`: its dofLocks): a slider or a weld.
inline bool hasLockedRows(const DofLocks& locks) { return locks.isDof && locks.anglesLockedAtZero; }

/// Its locked linear axes as bits (bit i: axis i of frame A).
inline unsigned lockedLinearAxes(const DofLocks& locks)
{
	return (locks.linear[0] ? 1u : 0u) | (locks.linear[1] ? 2u : 0u) | (locks.linear[2] ? 4u : 0u);
}

/// C and J (rows of 12: v_A, ω_A, v_B, ω_B) at the given transforms: the locked linear axes' rows, then the three
/// angular rows. Returns the number of rows (3 to 6).
inline int lockedPositionRows(const btTypedConstraint& c, const btTransform& transA, const btTransform& transB,
							  btScalar* C, btScalar* jacobian)
{
	const DofLocks k = dofLocks(c);
	const btTransform frameA = transA * k.frameA, frameB = transB * k.frameB;
	const btMatrix3x3& axes = frameA.getBasis();
	const btVector3 pA = frameA.getOrigin(), pB = frameB.getOrigin();
	const btVector3 d = pB - pA;
	const btVector3 armA = pB - transA.getOrigin();  // d + r_A: where B's pivot is from A's centre of mass
	const btVector3 rB = pB - transB.getOrigin();
	int row = 0;
	auto write = [&](const btVector3& linA, const btVector3& angA, const btVector3& linB, const btVector3& angB) {
		btScalar* j = jacobian + 12 * row;
		for (int n = 0; n < 3; ++n)
		{
			j[n] = linA[n];
			j[3 + n] = angA[n];
			j[6 + n] = linB[n];
			j[9 + n] = angB[n];
		}
		++row;
	};
	for (int i = 0; i < 3; ++i)
	{
		if (!k.linear[i]) continue;
		const btVector3 e = axes.getColumn(i);
		C[row] = e.dot(d) - k.offset[i];
		write(-e, e.cross(armA), e, rB.cross(e));
	}
	btQuaternion a, b;
	axes.getRotation(a);
	frameB.getBasis().getRotation(b);
	btQuaternion q = a.inverse() * b;
	if (q.getW() < 0) q = -q;
	const btScalar w = q.getW(), x = q.getX(), y = q.getY(), z = q.getZ();
	// w I − [q_v]×, by rows
	const btVector3 m[3] = {btVector3(w, z, -y), btVector3(-z, w, x), btVector3(y, -x, w)};
	const btVector3 zero(0, 0, 0);
	const btScalar v[3] = {x, y, z};
	for (int r = 0; r < 3; ++r)
	{
		const btVector3 g = axes.getColumn(0) * m[r][0] + axes.getColumn(1) * m[r][1] + axes.getColumn(2) * m[r][2];
		C[row] = 2 * v[r];
		write(zero, -g, zero, g);
	}
	return row;
}
}  // namespace stabilizer
}  // namespace quathinge

#endif
