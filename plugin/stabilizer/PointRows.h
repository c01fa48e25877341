// The point rows of Bullet's own point constraints (btQuaternionHingeStabilizerSettings::projectPointConstraints):
// btPoint2PointConstraint and the pivot of btConeTwistConstraint (not angular-only; its swing and twist limits are not
// projected). C = p_B − p_A, the world pivots, and J the same point rows as a quaternion hinge's
// (btQuaternionHingeConstraint::computePositionRows, MATH.md Q13): row i, J_A = (−e_i, e_i × r_A), J_B = (e_i, r_B × e_i).
#ifndef QUATHINGE_STABILIZER_POINT_ROWS_H
#define QUATHINGE_STABILIZER_POINT_ROWS_H

#include "BulletDynamics/ConstraintSolver/btConeTwistConstraint.h"
#include "BulletDynamics/ConstraintSolver/btPoint2PointConstraint.h"
#include "LinearMath/btTransform.h"

namespace quathinge
{
namespace stabilizer
{
// Bullet's own type numbers name Bullet's own classes (its serializer and debug drawer cast on them the same way).
inline bool hasPointRows(const btTypedConstraint& c)
{
	if (c.getConstraintType() == POINT2POINT_CONSTRAINT_TYPE) return true;
	return c.getConstraintType() == CONETWIST_CONSTRAINT_TYPE &&
		   !static_cast<const btConeTwistConstraint&>(c).getAngularOnly();
}

/// The pivots in A's and B's centre-of-mass frames, as the constraint holds them now.
inline void pointPivots(const btTypedConstraint& c, btVector3& inA, btVector3& inB)
{
	if (c.getConstraintType() == POINT2POINT_CONSTRAINT_TYPE)
	{
		const btPoint2PointConstraint& p = static_cast<const btPoint2PointConstraint&>(c);
		inA = p.getPivotInA();
		inB = p.getPivotInB();
		return;
	}
	const btConeTwistConstraint& cone = static_cast<const btConeTwistConstraint&>(c);
	inA = cone.getAFrame().getOrigin();
	inB = cone.getBFrame().getOrigin();
}

/// C (3) and J (3 rows of 12: v_A, ω_A, v_B, ω_B) at the given transforms; returns 3.
inline int pointPositionRows(const btTypedConstraint& c, const btTransform& transA, const btTransform& transB,
							 btScalar* C, btScalar* jacobian)
{
	btVector3 inA, inB;
	pointPivots(c, inA, inB);
	const btVector3 rA = transA.getBasis() * inA, rB = transB.getBasis() * inB;
	const btVector3 error = (transB.getOrigin() + rB) - (transA.getOrigin() + rA);
	for (int row = 0; row < 3; ++row)
	{
		btVector3 e(0, 0, 0);
		e[row] = 1;
		const btVector3 angularA = e.cross(rA), angularB = rB.cross(e);
		btScalar* j = jacobian + 12 * row;
		for (int k = 0; k < 3; ++k)
		{
			j[k] = -e[k];
			j[3 + k] = angularA[k];
			j[6 + k] = e[k];
			j[9 + k] = angularB[k];
		}
		C[row] = error[row];
	}
	return 3;
}
}  // namespace stabilizer
}  // namespace quathinge

#endif
