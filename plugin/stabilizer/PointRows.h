// The point rows of Bullet's own point constraints (btQuaternionHingeStabilizerSettings::projectPointConstraints):
// btPoint2PointConstraint, the pivot of btConeTwistConstraint (not angular-only; its swing and twist limits are limit
// rows, ConeTwistRows.h) and of a 6-dof (btGeneric6DofSpring2Constraint, btGeneric6DofConstraint, btGeneric6DofSpringConstraint)
// whose three linear axes are locked (a ball built from a 6-dof, or a hinge or universal joint when
// projectDofHinges or projectLockedConstraints is off: its pivot is frame B's origin and frame A's origin moved by the
// locked values along frame A's axes, a point of body A; its angles are not projected). C = p_B − p_A, the world pivots, and J
// the same point rows as a quaternion hinge's (btQuaternionHingeConstraint::computePositionRows, MATH.md Q13; both
// from plugin/src/WorldPointRows.h). A 6-dof with its angles locked at 0 as well (a weld, btFixedConstraint) is not a
// point constraint here: its orientation matters as much (closeAttachedConstraints closes it whole, AttachedBodies.h).
#ifndef QUATHINGE_STABILIZER_POINT_ROWS_H
#define QUATHINGE_STABILIZER_POINT_ROWS_H

#include "BulletDynamics/ConstraintSolver/btConeTwistConstraint.h"
#include "BulletDynamics/ConstraintSolver/btGeneric6DofConstraint.h"
#include "BulletDynamics/ConstraintSolver/btGeneric6DofSpring2Constraint.h"
#include "BulletDynamics/ConstraintSolver/btPoint2PointConstraint.h"
#include "BulletDynamics/ConstraintSolver/btSliderConstraint.h"
#include "LinearMath/btTransform.h"
#include "WorldPointRows.h"

namespace quathinge
{
namespace stabilizer
{
/// A 6-dof as its limits lock it now: btGeneric6DofSpring2Constraint (btFixedConstraint is one, Bullet 2.83 on), and
/// btGeneric6DofConstraint and its btGeneric6DofSpringConstraint. Both measure a locked linear axis i as frame A's
/// axis i · (p_B − p_A) (calculateLinearInfo, whichever frame the older one's rows are built along) and lock an angle
/// with low == high, so a weld, a slider or a ball means the same in either. A btSliderConstraint reads as the 6-dof
/// slider it is (sliderLocks). Its limited axes (low < high) are limit rows of the locked 6-dofs (LockedRows.h).
struct DofLocks
{
	bool isDof = false;                       // the constraint is one of those 6-dofs, or a btSliderConstraint
	bool linear[3] = {false, false, false};   // linear axis i locked: low == high (Bullet's convention), at offset[i]
	btVector3 offset{0, 0, 0};                // the locked values along frame A's axes (m)
	bool allLinear = false;                   // all three linear axes locked
	bool angular[3] = {false, false, false};  // angle i locked (low == high) at angles[i]
	btVector3 angles{0, 0, 0};                // the locked angles (rad), Bullet's Euler angles (getAngle; LockedRows.h)
	bool anglesLockedAtZero = false;          // all three angles locked at 0
	bool eulerXYZ = false;                    // its angles are Bullet's XYZ Euler angles (every 6-dof but a
											  // btGeneric6DofSpring2Constraint in another rotation order)
	// axis i limited (low < high; Bullet's convention, low > high is free): linear 0–2 along frame A's axes (m), angular
	// 3–5 Bullet's Euler angles (rad; only where eulerXYZ and not every angle locked at 0), between low[i] and high[i]
	bool limited[6] = {false, false, false, false, false, false};
	btScalar low[6] = {0, 0, 0, 0, 0, 0}, high[6] = {0, 0, 0, 0, 0, 0};
	btTransform frameA, frameB;  // in A's and B's centre-of-mass frames
	bool anyAngle() const { return angular[0] || angular[1] || angular[2]; }
	bool anyLinear() const { return linear[0] || linear[1] || linear[2]; }
};

namespace detail
{
inline bool eulerXYZ(const btGeneric6DofConstraint&) { return true; }
inline bool eulerXYZ(btGeneric6DofSpring2Constraint& dof) { return dof.getRotationOrder() == RO_XYZ; }

// (Bullet's getters of btGeneric6DofSpring2Constraint's limits are not const; btGeneric6DofConstraint's are)
template <class Dof>
DofLocks readDofLocks(Dof& dof)
{
	DofLocks k;
	btVector3 linearLow, linearHigh, angularLow, angularHigh;
	dof.getLinearLowerLimit(linearLow);
	dof.getLinearUpperLimit(linearHigh);
	dof.getAngularLowerLimit(angularLow);
	dof.getAngularUpperLimit(angularHigh);
	k.isDof = true;
	k.eulerXYZ = eulerXYZ(dof);
	k.frameA = dof.getFrameOffsetA();
	k.frameB = dof.getFrameOffsetB();
	k.allLinear = k.anglesLockedAtZero = true;
	for (int i = 0; i < 3; ++i)
	{
		k.linear[i] = linearLow[i] == linearHigh[i];
		if (k.linear[i]) k.offset[i] = linearLow[i];
		k.allLinear = k.allLinear && k.linear[i];
		k.angular[i] = angularLow[i] == angularHigh[i];
		if (k.angular[i]) k.angles[i] = angularLow[i];
		k.anglesLockedAtZero = k.anglesLockedAtZero && angularLow[i] == 0 && angularHigh[i] == 0;
		k.limited[i] = linearLow[i] < linearHigh[i];
		k.low[i] = linearLow[i];
		k.high[i] = linearHigh[i];
		k.limited[3 + i] = k.eulerXYZ && angularLow[i] < angularHigh[i];
		k.low[3 + i] = angularLow[i];
		k.high[3 + i] = angularHigh[i];
	}
	return k;
}

// A btSliderConstraint as the same locks: it slides along frame A's x and always holds B's frame origin on that line
// (calculateTransforms: its depths along frame A's axes, y and z held at 0) and the two frames' x axes together (the
// Euler angles y and z at 0); the turn about x is locked where its angular limits are equal, the slide where its
// linear ones are (testLinLimits). Without useLinearReferenceFrameA it measures the slide from B's origin to A's, so
// that locked value's sign turns; its turn, getAngularPos, is B's about A's x, minus the 6-dof's Euler angle x
// (LockedRows.h), so the locked turn's sign turns always. Bullet's default slider locks the turn at 0: a 6-dof slider;
// one free to turn about its axis is a cylindrical joint.
inline DofLocks sliderLocks(btSliderConstraint& slider)
{
	DofLocks k;
	k.isDof = true;
	k.eulerXYZ = true;
	k.frameA = slider.getFrameOffsetA();
	k.frameB = slider.getFrameOffsetB();
	const bool referenceA = slider.getUseLinearReferenceFrameA();
	k.linear[1] = k.linear[2] = true;
	k.linear[0] = slider.getLowerLinLimit() == slider.getUpperLinLimit();
	if (k.linear[0]) k.offset[0] = referenceA ? slider.getLowerLinLimit() : -slider.getLowerLinLimit();
	k.allLinear = k.linear[0];
	k.angular[1] = k.angular[2] = true;
	k.angular[0] = slider.getLowerAngLimit() == slider.getUpperAngLimit();
	if (k.angular[0]) k.angles[0] = -slider.getLowerAngLimit();
	k.anglesLockedAtZero = slider.getLowerAngLimit() == 0 && slider.getUpperAngLimit() == 0;
	// its limits in the same coordinates: the slide's sign turns without useLinearReferenceFrameA, the turn's always
	k.limited[0] = slider.getLowerLinLimit() < slider.getUpperLinLimit();
	k.low[0] = referenceA ? slider.getLowerLinLimit() : -slider.getUpperLinLimit();
	k.high[0] = referenceA ? slider.getUpperLinLimit() : -slider.getLowerLinLimit();
	k.limited[3] = slider.getLowerAngLimit() < slider.getUpperAngLimit();
	k.low[3] = -slider.getUpperAngLimit();
	k.high[3] = -slider.getLowerAngLimit();
	return k;
}
}  // namespace detail

// Bullet's own type numbers name Bullet's own classes (its serializer and debug drawer cast on them the same way).
inline DofLocks dofLocks(const btTypedConstraint& c)
{
	switch (c.getConstraintType())
	{
		case D6_SPRING_2_CONSTRAINT_TYPE:
		case FIXED_CONSTRAINT_TYPE:
			return detail::readDofLocks(
				const_cast<btGeneric6DofSpring2Constraint&>(static_cast<const btGeneric6DofSpring2Constraint&>(c)));
		case D6_CONSTRAINT_TYPE:
		case D6_SPRING_CONSTRAINT_TYPE:
			return detail::readDofLocks(static_cast<const btGeneric6DofConstraint&>(c));
		case SLIDER_CONSTRAINT_TYPE:
			return detail::sliderLocks(const_cast<btSliderConstraint&>(static_cast<const btSliderConstraint&>(c)));
		default:
			return DofLocks();
	}
}

/// A point constraint the projection takes; `locks`: dofLocks(c), which each caller reads for its own use too. A 6-dof
/// with its linear axes locked and some angle locked too is also a point here, but its locked rows (LockedRows.h) hold
/// it whole and are taken first where that option is on.
inline bool hasPointRows(const btTypedConstraint& c, const DofLocks& locks)
{
	if (c.getConstraintType() == POINT2POINT_CONSTRAINT_TYPE) return true;
	if (c.getConstraintType() == CONETWIST_CONSTRAINT_TYPE)
		return !static_cast<const btConeTwistConstraint&>(c).getAngularOnly();
	return locks.allLinear && !locks.anglesLockedAtZero;
}

/// The pivots in A's and B's centre-of-mass frames, as the constraint holds them now (a constraint hasPointRows takes).
inline void pointPivots(const btTypedConstraint& c, btVector3& inA, btVector3& inB)
{
	if (c.getConstraintType() == POINT2POINT_CONSTRAINT_TYPE)
	{
		const btPoint2PointConstraint& p = static_cast<const btPoint2PointConstraint&>(c);
		inA = p.getPivotInA();
		inB = p.getPivotInB();
		return;
	}
	if (c.getConstraintType() == CONETWIST_CONSTRAINT_TYPE)
	{
		const btConeTwistConstraint& cone = static_cast<const btConeTwistConstraint&>(c);
		inA = cone.getAFrame().getOrigin();
		inB = cone.getBFrame().getOrigin();
		return;
	}
	// a 6-dof with its linear axes locked: p_B − p_A = R_FA · offset, so A's pivot is frame A's origin moved by it
	const DofLocks k = dofLocks(c);
	inA = k.frameA * k.offset;
	inB = k.frameB.getOrigin();
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
