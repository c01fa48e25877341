// Stock and 6-dof hinges as frame pairs with their limit meaning (StockHingeRows.h).
#include "StockHingeRows.h"

#include "quathinge/btQuaternionHingeConstraint.h"

#include "BulletDynamics/ConstraintSolver/btGeneric6DofConstraint.h"
#include "BulletDynamics/ConstraintSolver/btGeneric6DofSpring2Constraint.h"
#include "BulletDynamics/ConstraintSolver/btHingeConstraint.h"

namespace quathinge
{
namespace stabilizer
{
namespace
{
// A stock hinge keeps its limit as a centre and a half range (btAngularLimit) and its angle's sign (m_referenceSign,
// set by its constructors; setUseReferenceFrameA does not change it) private, and reports only the limit's ends
// wrapped into (−π, π], from which a range of 2π or more (never acting) cannot be told from a narrower one. They are
// read here, never written, through pointers to the members named in explicit instantiations, where access is not
// checked ([temp.explicit]): the exact meaning stock's own test gives them.
template <typename Tag, typename Tag::type Member>
struct MemberPointer
{
	friend typename Tag::type memberPointer(Tag) { return Member; }
};
struct HingeLimit
{
	using type = btAngularLimit btHingeConstraint::*;
};
struct HingeSign
{
	using type = btScalar btHingeConstraint::*;
};
struct LimitCenter
{
	using type = btScalar btAngularLimit::*;
};
HingeLimit::type memberPointer(HingeLimit);
HingeSign::type memberPointer(HingeSign);
LimitCenter::type memberPointer(LimitCenter);
template struct MemberPointer<HingeLimit, &btHingeConstraint::m_limit>;
template struct MemberPointer<HingeSign, &btHingeConstraint::m_referenceSign>;
template struct MemberPointer<LimitCenter, &btAngularLimit::m_center>;

bool readStock(const btHingeConstraint& hinge, FrameHinge* out, bool* limit)
{
	const btAngularLimit& range = hinge.*memberPointer(HingeLimit());
	const btScalar half = range.getHalfRange();
	// btAngularLimit::test: acts while |wrap(angle − c)| > h, h ≥ 0; |wrap(…)| ≤ π, so never for h ≥ π
	const bool acts = half >= 0 && half < SIMD_PI;
	if (limit) *limit = acts;
	if (!out) return true;
	out->frameA = hinge.getAFrame();
	out->frameB = hinge.getBFrame();
	out->angularOnly = const_cast<btHingeConstraint&>(hinge).getAngularOnly();
	// stock's angle atan2(ŷ_B·x̂_A, ŷ_B·ŷ_A) is −θ on the hinge, times its reference sign
	out->sign = -(hinge.*memberPointer(HingeSign()));
	out->limit = acts;
	out->adjustToLimits = false;
	out->center = range.*memberPointer(LimitCenter());
	out->low = -half;
	out->high = half;
	return true;
}

// The 6-dof's angle of axis `axis` for a relative rotation about that axis alone: +θ or −θ (btGetMatrixElem reads the
// matrix transposed in some of its Euler forms, not in others), read off its own Euler function for its order.
btScalar eulerSign(int order, int axis)
{
	btVector3 turn(0, 0, 0);
	turn[axis] = 1;
	const btMatrix3x3 rotation(btQuaternion(turn, btScalar(0.25)));
	btVector3 euler(0, 0, 0);
	switch (order)
	{
		case RO_XZY: btGeneric6DofSpring2Constraint::matrixToEulerXZY(rotation, euler); break;
		case RO_YXZ: btGeneric6DofSpring2Constraint::matrixToEulerYXZ(rotation, euler); break;
		case RO_YZX: btGeneric6DofSpring2Constraint::matrixToEulerYZX(rotation, euler); break;
		case RO_ZXY: btGeneric6DofSpring2Constraint::matrixToEulerZXY(rotation, euler); break;
		case RO_ZYX: btGeneric6DofSpring2Constraint::matrixToEulerZYX(rotation, euler); break;
		default: btGeneric6DofSpring2Constraint::matrixToEulerXYZ(rotation, euler); break;  // btGeneric6DofConstraint's
	}
	return euler[axis] < 0 ? btScalar(-1) : btScalar(1);
}

// eulerSign for every order and axis, computed once (read every step for every 6-dof hinge).
btScalar dofAngleSign(int order, int axis)
{
	struct Table
	{
		btScalar sign[RO_ZYX + 1][3];
		Table()
		{
			for (int o = RO_XYZ; o <= RO_ZYX; ++o)
				for (int a = 0; a < 3; ++a) sign[o][a] = eulerSign(o, a);
		}
	};
	static const Table table;
	return table.sign[order >= RO_XYZ && order <= RO_ZYX ? order : RO_XYZ][axis];
}

struct DofLimits
{
	btTransform frameA, frameB;
	btVector3 linearLow, linearHigh, angularLow, angularHigh;
	int order;
};

bool readDof(const btTypedConstraint& c, FrameHinge* out, bool* limit)
{
	DofLimits d;
	if (c.getConstraintType() == D6_SPRING_2_CONSTRAINT_TYPE)
	{
		// (its getters of the limits are not const)
		auto& dof = const_cast<btGeneric6DofSpring2Constraint&>(static_cast<const btGeneric6DofSpring2Constraint&>(c));
		dof.getLinearLowerLimit(d.linearLow);
		dof.getLinearUpperLimit(d.linearHigh);
		dof.getAngularLowerLimit(d.angularLow);
		dof.getAngularUpperLimit(d.angularHigh);
		d.order = dof.getRotationOrder();
		if (out)
		{
			d.frameA = dof.getFrameOffsetA();
			d.frameB = dof.getFrameOffsetB();
		}
	}
	else  // btGeneric6DofConstraint and btGeneric6DofSpringConstraint: Euler XYZ
	{
		const auto& dof = static_cast<const btGeneric6DofConstraint&>(c);
		dof.getLinearLowerLimit(d.linearLow);
		dof.getLinearUpperLimit(d.linearHigh);
		dof.getAngularLowerLimit(d.angularLow);
		dof.getAngularUpperLimit(d.angularHigh);
		d.order = RO_XYZ;
		if (out)
		{
			d.frameA = dof.getFrameOffsetA();
			d.frameB = dof.getFrameOffsetB();
		}
	}
	// three linear axes locked (low == high, Bullet's convention), one angular axis not locked, the others locked at 0
	int free = -1;
	for (int i = 0; i < 3; ++i)
	{
		if (d.linearLow[i] != d.linearHigh[i]) return false;
		if (d.angularLow[i] == d.angularHigh[i])
		{
			if (d.angularLow[i] != 0) return false;
			continue;
		}
		if (free >= 0) return false;
		free = i;
	}
	if (free < 0) return false;
	const btScalar lo = d.angularLow[free], hi = d.angularHigh[free];
	// lo > hi: free; [−π, π] (the 6-dof wraps its limits into it) holds every wrapped angle
	const bool acts = lo < hi && (lo > -SIMD_PI || hi < SIMD_PI);
	if (limit) *limit = acts;
	if (!out) return true;
	// ẑ onto the free axis: a cyclic turn of the axes (x̂, ŷ, ẑ) ← the free axis's successors, then it
	btMatrix3x3 turn;
	turn.setIdentity();
	if (free != 2)
	{
		const int next = (free + 1) % 3, last = (free + 2) % 3;
		for (int r = 0; r < 3; ++r)
		{
			turn[r][0] = r == next ? 1 : 0;
			turn[r][1] = r == last ? 1 : 0;
			turn[r][2] = r == free ? 1 : 0;
		}
	}
	// frame A's origin moved by the locked values along its axes: the pivot of A (PointRows.h, pointPivots)
	out->frameA.setOrigin(d.frameA * d.linearLow);
	out->frameA.setBasis(d.frameA.getBasis() * turn);
	out->frameB.setOrigin(d.frameB.getOrigin());
	out->frameB.setBasis(d.frameB.getBasis() * turn);
	out->angularOnly = false;
	out->sign = dofAngleSign(d.order, free);
	out->limit = acts;
	out->adjustToLimits = true;
	out->center = 0;
	out->low = lo;
	out->high = hi;
	return true;
}
}  // namespace

FrameHingeKind readFrameHinge(const btTypedConstraint& c, bool stockHinges, bool dofHinges, FrameHinge* out,
							  bool* limit)
{
	const int type = c.getConstraintType();
	if (type == HINGE_CONSTRAINT_TYPE)
		return stockHinges && readStock(static_cast<const btHingeConstraint&>(c), out, limit) ? FrameHingeKind::Stock
																							  : FrameHingeKind::None;
	if (type == D6_SPRING_2_CONSTRAINT_TYPE || type == D6_CONSTRAINT_TYPE || type == D6_SPRING_CONSTRAINT_TYPE)
		return dofHinges && readDof(c, out, limit) ? FrameHingeKind::Dof : FrameHingeKind::None;
	return FrameHingeKind::None;
}

int frameHingePositionRows(const FrameHinge& hinge, const btTransform& transA, const btTransform& transB, btScalar* C,
						   btScalar* jacobian, btScalar previous, btScalar& variable, btVector3& gradient)
{
	// v = σθ − c, so θ = σ(v + c) (σ = ±1), and v̇ = σ θ̇
	btScalar theta;
	const int rows = btQuaternionHingeConstraint::computeFramePositionRows(
		hinge.frameA, hinge.frameB, hinge.angularOnly, transA, transB, C, jacobian, hinge.sign * (previous + hinge.center),
		theta, gradient);
	variable = hinge.sign * theta - hinge.center;
	gradient *= hinge.sign;
	return rows;
}

btScalar frameHingeLimitVariable(const btTypedConstraint& c, const FrameHinge& hinge, const btTransform& transA,
								 const btTransform& transB)
{
	if (!hinge.adjustToLimits)
	{
		// a stock hinge: its own angle (btHingeConstraint::getHingeAngle, a computation that changes nothing; sign·θ
		// on the hinge, and cheaper than the rows), wrapped about the centre as btAngularLimit::test wraps it
		auto& stock = const_cast<btHingeConstraint&>(static_cast<const btHingeConstraint&>(c));
		return btNormalizeAngle(stock.getHingeAngle(transA, transB) - hinge.center);
	}
	btScalar C[5], jacobian[60], theta;
	btVector3 gradient;
	btQuaternionHingeConstraint::computeFramePositionRows(hinge.frameA, hinge.frameB, hinge.angularOnly, transA, transB,
														  C, jacobian, 0, theta, gradient);
	// θ ∈ (−π, π] continued from 0: wrapped; on the branch of the nearer stop, as the 6-dof tests it
	return btAdjustAngleToLimits(hinge.sign * theta, hinge.low, hinge.high);
}
}  // namespace stabilizer
}  // namespace quathinge
