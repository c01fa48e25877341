// The rows of a locked 6-dof (btQuaternionHingeStabilizerSettings::projectLockedConstraints): a
// btGeneric6DofSpring2Constraint, btGeneric6DofConstraint or btGeneric6DofSpringConstraint with any mix of locked axes
// but a ball's. Chiefly one whose three angles are locked at 0: a slider (one or two linear axes free, as pybullet and
// the URDF scenes build a prismatic joint; a btSliderConstraint with its turn locked at 0, Bullet's default) or a weld
// (all six locked; btFixedConstraint); then one with some of its Euler angles locked: a universal joint
// (btUniversalConstraint), a btHinge2Constraint, a cylindrical joint (a btSliderConstraint free to turn). Both 6-dof
// families and the slider mean the same by a lock (PointRows.h). docs/MATH.md, "Other constraints in the same
// projection", its item on locked 6-dofs.
//
// With frame A's axes e_i (world, R_FA's columns), its pivot p_A, frame B's pivot p_B, d = p_B − p_A and the locked
// values o_i (Bullet: low == high), one row per locked linear axis i, in axis order:
//   C_i = e_i·d − o_i,   J_i = (−e_i, e_i × (p_B − x_A) | e_i, r_B × e_i)
// (v_A, ω_A | v_B, ω_B; x_A body A's centre of mass, r_B = p_B − x_B): e_i turns with body A, so ω_A enters through
// ė_i·d = ω_A·(e_i × d) as well as through A's arm. Then three angular rows from the relative rotation of the frames,
// q = a* ⊗ b (a, b their world orientations, w ≥ 0 taken), C = 2 q_v (frame A's coordinates; the rotation vector to
// first order), and since q̇ = ½ (0, u) ⊗ q with u = R_FAᵀ (ω_B − ω_A),
//   d(2 q_v)/dt = (w I − [q_v]×) u,   J = (0, −G | 0, G),   G = (w I − [q_v]×) R_FAᵀ.
// With some angles locked, one row per locked Euler angle instead, in Bullet's own angles (MATH.md, "Some angles
// locked"; lockedPositionRows below).
// All are the exact derivatives of their C (tests/test_stabilizer_locked.cpp and test_stabilizer_euler_locks.cpp check
// them against finite differences),
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
/// A 6-dof the locked rows hold (`locks`: its dofLocks): its three angles locked at 0 (a slider, a weld), or any other
/// mix of locked axes but a ball's (its three linear axes alone: a point constraint, PointRows.h), locked angles only
/// where they are Bullet's XYZ Euler angles (a universal joint, a btHinge2Constraint, a cylindrical joint).
inline bool hasLockedRows(const DofLocks& locks)
{
	if (!locks.isDof) return false;
	if (locks.anglesLockedAtZero) return true;
	if (locks.anyAngle()) return locks.eulerXYZ;
	return locks.anyLinear() && !locks.allLinear;
}

/// Its locked linear axes as bits (bit i: axis i of frame A).
inline unsigned lockedLinearAxes(const DofLocks& locks)
{
	return (locks.linear[0] ? 1u : 0u) | (locks.linear[1] ? 2u : 0u) | (locks.linear[2] ? 4u : 0u);
}

/// Its angular rows as bits (bit i: Euler angle i; all three for the angles locked at 0, held as one rotation).
inline unsigned lockedAngularAxes(const DofLocks& locks)
{
	if (locks.anglesLockedAtZero) return 7u;
	return (locks.angular[0] ? 1u : 0u) | (locks.angular[1] ? 2u : 0u) | (locks.angular[2] ? 4u : 0u);
}

/// C and J (rows of 12: v_A, ω_A, v_B, ω_B) at the given transforms: the locked linear axes' rows, then the angular
/// rows (three from the relative rotation where all angles are locked at 0, else one per locked Euler angle). Returns
/// the number of rows (1 to 6).
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
	const btVector3 zero(0, 0, 0);
	if (k.anglesLockedAtZero)
	{
		btQuaternion a, b;
		axes.getRotation(a);
		frameB.getBasis().getRotation(b);
		btQuaternion q = a.inverse() * b;
		if (q.getW() < 0) q = -q;
		const btScalar w = q.getW(), x = q.getX(), y = q.getY(), z = q.getZ();
		// w I − [q_v]×, by rows
		const btVector3 m[3] = {btVector3(w, z, -y), btVector3(-z, w, x), btVector3(y, -x, w)};
		const btScalar v[3] = {x, y, z};
		for (int r = 0; r < 3; ++r)
		{
			const btVector3 g = axes.getColumn(0) * m[r][0] + axes.getColumn(1) * m[r][1] + axes.getColumn(2) * m[r][2];
			C[row] = 2 * v[r];
			write(zero, -g, zero, g);
		}
		return row;
	}
	if (!k.anyAngle()) return row;
	// Bullet's Euler angles (a, b, c) of the frames (calculateAngleInfo) and their axes: A's z (a2), the line of nodes n,
	// B's x (b0); the rows of a and c scaled by cos b (docs/MATH.md, "Some angles locked", where they are derived).
	const btMatrix3x3& basisB = frameB.getBasis();
	const btVector3 a0 = axes.getColumn(0), a1 = axes.getColumn(1), a2 = axes.getColumn(2);
	const btVector3 b0 = basisB.getColumn(0), b1 = basisB.getColumn(1), b2 = basisB.getColumn(2);
	const btVector3 nodes = a2.cross(b0);
	const btScalar cosB = nodes.length(), sinB = a2.dot(b0);
	btVector3 n, unused;
	if (cosB > SIMD_EPSILON) n = nodes / cosB;
	else btPlaneSpace1(a2, n, unused);  // b = ±π/2: a and c are not defined, their rows' C is 0
	const btVector3 m0 = n.cross(a2), m2 = b0.cross(n);
	const btScalar angle[3] = {btAtan2(-a2.dot(b1), a2.dot(b2)), btAtan2(sinB, cosB), btAtan2(-a1.dot(b0), a0.dot(b0))};
	for (int i = 0; i < 3; ++i)
	{
		if (!k.angular[i]) continue;
		if (i == 1)
		{
			C[row] = angle[1] - k.angles[1];
			write(zero, n, zero, -n);
			continue;
		}
		const btScalar error = btNormalizeAngle(angle[i] - k.angles[i]);
		const btVector3 g = (i == 0 ? m0 : m2) - n * (error * sinB);
		C[row] = cosB * error;
		write(zero, g, zero, -g);
	}
	return row;
}
}  // namespace stabilizer
}  // namespace quathinge

#endif
