// The point rows of Bullet's own point constraints (btQuaternionHingeStabilizerSettings::projectPointConstraints):
// btPoint2PointConstraint and the pivot of btConeTwistConstraint (not angular-only; its swing and twist limits are not
// projected). C = p_B − p_A, the world pivots, and J the same point rows as a quaternion hinge's
// (btQuaternionHingeConstraint::computePositionRows, MATH.md Q13; both from plugin/src/WorldPointRows.h).
#ifndef QUATHINGE_STABILIZER_POINT_ROWS_H
#define QUATHINGE_STABILIZER_POINT_ROWS_H

#include "BulletDynamics/ConstraintSolver/btConeTwistConstraint.h"
#include "BulletDynamics/ConstraintSolver/btPoint2PointConstraint.h"
#include "LinearMath/btTransform.h"
#include "WorldPointRows.h"

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
	writeWorldPointRows(rA, rB, (transB.getOrigin() + rB) - (transA.getOrigin() + rA), C, jacobian);
	return 3;
}
}  // namespace stabilizer
}  // namespace quathinge

#endif
