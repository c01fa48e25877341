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

// eulerSign for every order and axis, computed once (read whenever a 6-dof hinge's island is built).
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

// A drive on a rotational axis: a motor (velocity or, 6dof2, servo) or a 6dof2 spring.
inline bool drives(const btRotationalLimitMotor& m) { return m.m_enableMotor; }
inline bool drives(const btRotationalLimitMotor2& m) { return m.m_enableMotor || m.m_enableSpring; }

// The 6-dof's members this reads, through its public accessors (the limits' getters copy into vectors and are not
// const; the motors are its own members): the same for both classes, which share no base with them.
template <typename Dof>
struct DofView
{
	Dof& dof;
	const btTransform& frameA() const { return dof.getFrameOffsetA(); }
	const btTransform& frameB() const { return dof.getFrameOffsetB(); }
	const btVector3& linearLow() const { return dof.getTranslationalLimitMotor()->m_lowerLimit; }
	const btVector3& linearHigh() const { return dof.getTranslationalLimitMotor()->m_upperLimit; }
	btScalar angularLow(int i) const { return dof.getRotationalLimitMotor(i)->m_loLimit; }
	btScalar angularHigh(int i) const { return dof.getRotationalLimitMotor(i)->m_hiLimit; }
	bool driven(int i) const { return drives(*dof.getRotationalLimitMotor(i)); }
};

// lo > hi: free; [−π, π] (the 6-dof wraps its limits into it) holds every wrapped angle
inline bool dofLimitActs(btScalar lo, btScalar hi) { return lo < hi && (lo > -SIMD_PI || hi < SIMD_PI); }

// The free axis of a 6-dof set up as a hinge (three linear axes locked, low == high, Bullet's convention; one
// angular axis not locked, the others locked at 0), or −1.
template <typename View>
int dofFreeAxis(const View& d)
{
	int free = -1;
	for (int i = 0; i < 3; ++i)
	{
		if (d.linearLow()[i] != d.linearHigh()[i]) return -1;
		const btScalar lo = d.angularLow(i), hi = d.angularHigh(i);
		if (lo == hi)
		{
			if (lo != 0) return -1;
			continue;
		}
		if (free >= 0) return -1;
		free = i;
	}
	return free;
}

// What can change between steps without changing the hinge's shape: the frames (ẑ turned onto the free axis) and
// the free axis's limits.
template <typename View>
void readDofFrames(const View& d, FrameHinge& out)
{
	const int free = out.dofAxis;
	const btTransform& a = d.frameA();
	const btTransform& b = d.frameB();
	// frame A's origin moved by the locked values along its axes: the pivot of A (PointRows.h, pointPivots)
	out.frameA.setOrigin(a * d.linearLow());
	out.frameB.setOrigin(b.getOrigin());
	// ẑ onto the free axis: a cyclic turn of the axes (x̂, ŷ, ẑ) ← the free axis's successors, then it (columns)
	static const int kNext[3] = {1, 2, 0};
	const int next = kNext[free], last = kNext[next];
	const btMatrix3x3& ba = a.getBasis();
	const btMatrix3x3& bb = b.getBasis();
	out.frameA.getBasis().setValue(ba[0][next], ba[0][last], ba[0][free], ba[1][next], ba[1][last], ba[1][free],
								   ba[2][next], ba[2][last], ba[2][free]);
	out.frameB.getBasis().setValue(bb[0][next], bb[0][last], bb[0][free], bb[1][next], bb[1][last], bb[1][free],
								   bb[2][next], bb[2][last], bb[2][free]);
	const btScalar lo = d.angularLow(free), hi = d.angularHigh(free);
	out.limit = dofLimitActs(lo, hi);
	out.driven = d.driven(free);
	out.low = lo;
	out.high = hi;
}

// The 6-dof's kind with its shape; with `out`, all of the FrameHinge.
template <typename View>
bool readDof(const View& d, int order, FrameHinge* out, bool* limit, unsigned* shape)
{
	const int free = dofFreeAxis(d);
	if (free < 0) return false;
	if (limit) *limit = dofLimitActs(d.angularLow(free), d.angularHigh(free)) || d.driven(free);
	const unsigned kept = unsigned(free) | unsigned(order) << 2;
	if (shape) *shape = kept;
	if (!out) return true;
	setDofHingeShape(kept, *out);
	readDofFrames(d, *out);
	return true;
}

template <typename Dof>
DofView<Dof> viewOf(const btTypedConstraint& c)
{
	// (its accessors of the limit motors are not const; nothing is written through them)
	return DofView<Dof>{const_cast<Dof&>(static_cast<const Dof&>(c))};
}
}  // namespace

FrameHingeKind readFrameHinge(const btTypedConstraint& c, bool stockHinges, bool dofHinges, FrameHinge* out,
							  bool* limit, unsigned* shape)
{
	const int type = c.getConstraintType();
	if (type == HINGE_CONSTRAINT_TYPE)
	{
		if (shape) *shape = 0;
		return stockHinges && readStock(static_cast<const btHingeConstraint&>(c), out, limit) ? FrameHingeKind::Stock
																							  : FrameHingeKind::None;
	}
	if (!dofHinges) return FrameHingeKind::None;
	if (type == D6_SPRING_2_CONSTRAINT_TYPE)
	{
		const auto d = viewOf<btGeneric6DofSpring2Constraint>(c);
		return readDof(d, d.dof.getRotationOrder(), out, limit, shape) ? FrameHingeKind::Dof : FrameHingeKind::None;
	}
	if (type == D6_CONSTRAINT_TYPE || type == D6_SPRING_CONSTRAINT_TYPE)  // Euler XYZ
		return readDof(viewOf<btGeneric6DofConstraint>(c), RO_XYZ, out, limit, shape) ? FrameHingeKind::Dof
																					  : FrameHingeKind::None;
	return FrameHingeKind::None;
}

void setDofHingeShape(unsigned shape, FrameHinge& hinge)
{
	hinge.dofAxis = int(shape & 3);
	hinge.sign = dofAngleSign(int(shape >> 2), hinge.dofAxis);
	hinge.angularOnly = false;
	hinge.adjustToLimits = true;
	hinge.center = 0;
}

void refreshFrameHinge(const btTypedConstraint& c, FrameHinge& hinge)
{
	const int type = c.getConstraintType();
	if (type == HINGE_CONSTRAINT_TYPE)
		readStock(static_cast<const btHingeConstraint&>(c), &hinge, nullptr);
	else if (type == D6_SPRING_2_CONSTRAINT_TYPE)
		readDofFrames(viewOf<btGeneric6DofSpring2Constraint>(c), hinge);
	else
		readDofFrames(viewOf<btGeneric6DofConstraint>(c), hinge);
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
	// θ ∈ (−π, π] (the rows' angle continued from 0, without the rows): wrapped; on the branch of the nearer stop, as
	// the 6-dof tests it
	const btScalar theta = btQuaternionHingeConstraint::computeFrameAngle(hinge.frameA, hinge.frameB, transA, transB);
	return btAdjustAngleToLimits(hinge.sign * theta, hinge.low, hinge.high);
}
}  // namespace stabilizer
}  // namespace quathinge
