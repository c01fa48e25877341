// The rows of a locked 6-dof (btQuaternionHingeStabilizerSettings::projectLockedConstraints): a
// btGeneric6DofSpring2Constraint, btGeneric6DofConstraint or btGeneric6DofSpringConstraint with any mix of locked axes
// but a free ball's (a ball with its angles limited is one). Chiefly one whose three angles are locked at 0: a slider (one or two linear axes free, as pybullet and
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
// Each limited axis (low < high: a slider's stops, a universal joint's angles) is a limit row (with projectLimits): its
// variable, a linear axis's e_i·d or a Euler angle, and that variable's exact gradient (lockedPositionRows with a
// LockedLimit; docs/MATH.md, "Limited axes of a locked 6-dof"); the first in the joint's slot, each further one in a
// slot of its own (StabilizerIsland.h, kLimitOnly).
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
/// mix of locked axes but a free ball's (its three linear axes alone: a point constraint, PointRows.h), locked angles
/// only where they are Bullet's XYZ Euler angles (a universal joint, a btHinge2Constraint, a cylindrical joint). A
/// ball whose angles are limited (as Bullet's GenericJointDemo ragdoll builds its shoulders and hips; XYZ order) is
/// held here too: its three linear rows and its angles' limit rows.
inline bool hasLockedRows(const DofLocks& locks)
{
	if (!locks.isDof) return false;
	if (locks.anglesLockedAtZero) return true;
	if (locks.anyAngle()) return locks.eulerXYZ;
	if (locks.allLinear) return locks.limited[3] || locks.limited[4] || locks.limited[5];
	return locks.anyLinear();
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

/// The locked 6-dof's limited axes (DofLocks::limited) in the order their limit rows take them: at most 6.
inline int limitedAxes(const DofLocks& locks, int* axes)
{
	int n = 0;
	for (int i = 0; i < 6; ++i)
		if (locks.limited[i]) axes[n++] = i;
	return n;
}

/// One limited axis's variable and its gradient (v_A, ω_A, v_B, ω_B; d/dt = gradient · v) for its limit row.
struct LockedLimit
{
	int axis = -1;  // DofLocks::limited's index: 0–2 linear (m), 3–5 Euler angles (rad)
	btScalar value = 0;
	btScalar gradient[12];
};

/// C and J (rows of 12: v_A, ω_A, v_B, ω_B) at the given transforms: the locked linear axes' rows, then the angular
/// rows (three from the relative rotation where all angles are locked at 0, else one per locked Euler angle). Returns
/// the number of rows (1 to 6; 0 with `rows` false: a limit row's slot alone). With `limit`, also its axis's variable
/// and gradient: a linear axis's e_i·d and its locked row's J; an Euler angle's value and exact gradient, the rows' of
/// b and of a, c without their cos b scale (d a/dt = m₀·(ω_A − ω_B) / cos b: unbounded at the gimbal, where the
/// gradient is taken as 0 and the row holds nothing).
inline int lockedPositionRows(const btTypedConstraint& c, const btTransform& transA, const btTransform& transB,
							  btScalar* C, btScalar* jacobian, LockedLimit* limit = nullptr, bool rows = true)
{
	const DofLocks k = dofLocks(c);
	const btTransform frameA = transA * k.frameA, frameB = transB * k.frameB;
	const btMatrix3x3& axes = frameA.getBasis();
	const btVector3 pA = frameA.getOrigin(), pB = frameB.getOrigin();
	const btVector3 d = pB - pA;
	const btVector3 armA = pB - transA.getOrigin();  // d + r_A: where B's pivot is from A's centre of mass
	const btVector3 rB = pB - transB.getOrigin();
	const btVector3 zero(0, 0, 0);
	auto put = [](btScalar* j, const btVector3& linA, const btVector3& angA, const btVector3& linB, const btVector3& angB) {
		for (int n = 0; n < 3; ++n)
		{
			j[n] = linA[n];
			j[3 + n] = angA[n];
			j[6 + n] = linB[n];
			j[9 + n] = angB[n];
		}
	};
	int row = 0;
	auto write = [&](const btVector3& linA, const btVector3& angA, const btVector3& linB, const btVector3& angB) {
		put(jacobian + 12 * row, linA, angA, linB, angB);
		++row;
	};
	if (limit && limit->axis < 3)
	{
		const btVector3 e = axes.getColumn(limit->axis);
		limit->value = e.dot(d);
		put(limit->gradient, -e, e.cross(armA), e, rB.cross(e));
	}
	for (int i = 0; i < 3 && rows; ++i)
	{
		if (!k.linear[i]) continue;
		const btVector3 e = axes.getColumn(i);
		C[row] = e.dot(d) - k.offset[i];
		write(-e, e.cross(armA), e, rB.cross(e));
	}
	if (k.anglesLockedAtZero && rows)
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
	const bool angularLimit = limit && limit->axis >= 3;
	if (!(rows && k.anyAngle()) && !angularLimit) return row;
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
	if (angularLimit)
	{
		const int i = limit->axis - 3;
		limit->value = angle[i];
		const btVector3 g = i == 1 ? n : cosB > SIMD_EPSILON ? (i == 0 ? m0 : m2) / cosB
															 : zero;
		put(limit->gradient, zero, g, zero, -g);
	}
	for (int i = 0; i < 3 && rows; ++i)
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
