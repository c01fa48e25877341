// The swing and twist limits of a btConeTwistConstraint as limit rows of the projection (projectConeTwistLimits, with
// projectLimits and its pivot's point rows: projectPointConstraints, PointRows.h), in the coordinates Bullet's cone twist limits itself
// (calcAngleInfo2): the relative rotation of frame A in frame B, split into a swing (the shortest arc taking B's x
// axis to A's) and a twist about x. docs/MATH.md, "Cone-twist limits".
//
// Swing: with v = R_FBᵀ x_A (A's x axis in frame B), its angle θ = atan2(ρ, v_x), ρ = √(v_y² + v_z²), against the
// elliptical cone's bound in that direction, L = ρ / √(v_y²/s₁² + v_z²/s₂²) (computeConeLimitInfo: swingSpan1 bounds
// the swing about z, swingSpan2 about y): the variable θ − L, whose stop is 0 (only the upper one acts). Twist: the
// angle τ of the twist about x, wrapped into (−π, π], between −twistSpan and twistSpan.
// Both are functions of the relative rotation alone, so their rows are angular: d/dt of either is g · (ω_B − ω_A).
// A cone twist's softness makes Bullet push back from softness × span on; the projection acts only past the span
// itself (the soft band stays Bullet's). A cone twist with a motor enabled (whose solver then ignores the limits) or
// swing spans under its fix threshold (Bullet then treats it as a hinge or weld of its own kind) gets no swing row;
// a twist span of π or more, or negative (Bullet: none), no twist row.
#ifndef QUATHINGE_STABILIZER_CONE_TWIST_ROWS_H
#define QUATHINGE_STABILIZER_CONE_TWIST_ROWS_H

#include "BulletDynamics/ConstraintSolver/btConeTwistConstraint.h"
#include "LinearMath/btTransform.h"

namespace quathinge
{
namespace stabilizer
{
/// Which of a cone twist's limits are rows, as Bullet acts on them now.
struct ConeLimits
{
	bool swing = false, twist = false;
	btScalar span1 = 0, span2 = 0, twistSpan = 0;  // rad
};

inline ConeLimits coneLimits(const btConeTwistConstraint& cone)
{
	ConeLimits k;
	k.span1 = cone.getSwingSpan1();
	k.span2 = cone.getSwingSpan2();
	k.twistSpan = cone.getTwistSpan();
	if (cone.isMotorEnabled()) return k;
	const btScalar fix = const_cast<btConeTwistConstraint&>(cone).getFixThresh();
	k.swing = k.span1 >= fix && k.span2 >= fix && (k.span1 < SIMD_PI || k.span2 < SIMD_PI);
	k.twist = k.twistSpan >= 0 && k.twistSpan < SIMD_PI;
	return k;
}

/// The swing variable θ − L at the given transforms, and its gradient g (d/dt = g · (ω_B − ω_A)).
inline btScalar coneSwingVariable(const btConeTwistConstraint& cone, const ConeLimits& k, const btTransform& transA,
								  const btTransform& transB, btVector3& g)
{
	const btMatrix3x3 basisB = transB.getBasis() * cone.getBFrame().getBasis();
	const btVector3 xA = transA.getBasis() * cone.getAFrame().getBasis().getColumn(0);
	const btVector3 v = basisB.transpose() * xA;
	const btScalar rho = btSqrt(v.y() * v.y() + v.z() * v.z());
	const btScalar theta = btAtan2(rho, v.x());
	if (rho < SIMD_EPSILON)  // no swing (or a full turn over): no direction to take the bound or the gradient in
	{
		g.setZero();
		return theta - btMin(k.span1, k.span2);
	}
	const btScalar i1 = 1 / (k.span1 * k.span1), i2 = 1 / (k.span2 * k.span2);
	const btScalar n = btSqrt(v.y() * v.y() * i1 + v.z() * v.z() * i2);
	const btScalar bound = rho / n;
	// d(θ − L)/dv (|v| = 1: dθ/dv_x = −ρ, dθ/dv_y = v_x v_y / ρ, …; L is of degree 0 in (v_y, v_z))
	const btScalar n3 = n * n * n;
	const btVector3 dv(-rho, v.x() * v.y() / rho - (v.y() / (rho * n) - rho * v.y() * i1 / n3),
					   v.x() * v.z() / rho - (v.z() / (rho * n) - rho * v.z() * i2 / n3));
	// v̇ = R_FBᵀ ((ω_A − ω_B) × x_A), so d/dt = (ω_A − ω_B) · (x_A × R_FB dv)
	g = -xA.cross(basisB * dv);
	return theta - bound;
}

/// The twist τ at the given transforms, and its gradient g (d/dt = g · (ω_B − ω_A)): with x_B frame B's x axis,
/// τ̇ = (ω_A − ω_B) · (x_A + x_B) / (1 + x_A · x_B) (singular only where the swing is a half turn).
inline btScalar coneTwistVariable(const btConeTwistConstraint& cone, const btTransform& transA,
								  const btTransform& transB, btVector3& g)
{
	const btQuaternion qA = transA.getRotation() * cone.getAFrame().getRotation();
	const btQuaternion qB = transB.getRotation() * cone.getBFrame().getRotation();
	const btQuaternion qAB = qB.inverse() * qA;
	const btVector3 x(1, 0, 0);
	const btVector3 v = quatRotate(qAB, x);
	const btQuaternion cone0 = shortestArcQuat(x, v.normalized());
	const btQuaternion twist = cone0.inverse() * qAB;
	const btVector3 xA = quatRotate(qA, x), xB = quatRotate(qB, x);
	const btScalar d = 1 + xA.dot(xB);
	if (d > SIMD_EPSILON) g = -(xA + xB) / d;
	else g.setZero();
	return btNormalizeAngle(2 * btAtan2(twist.x(), twist.w()));
}
}  // namespace stabilizer
}  // namespace quathinge

#endif
