// The hinges a Bullet app already has, as the stabilizer projects them (btQuaternionHingeStabilizerSettings::
// projectStockHinges, projectDofHinges): btHingeConstraint (and btHingeAccumulatedAngleConstraint, the same type) and
// the 6-dofs set up as hinges (btGeneric6DofSpring2Constraint, btGeneric6DofConstraint and btGeneric6DofSpringConstraint
// with their three linear axes locked, exactly one angular axis free or limited and the other two locked at 0, as
// Bullet's URDF importer builds a revolute joint between rigid bodies).
//
// Rows. Each is read as a pair of joint frames in A's and B's centre-of-mass frames with ẑ the hinge axis (a stock
// hinge's getAFrame/getBFrame; a 6-dof's frame offsets, their axes turned so that ẑ is the free axis, frame A's origin
// moved by the locked linear values along its axes) and gets the quaternion hinge's own rows on those frames
// (btQuaternionHingeConstraint::computeFramePositionRows: MATH.md Q2–Q10, Q12, the point rows of Q13), 5 or 2 when
// angular-only; nothing of the equations is repeated here.
//
// Limit. One row along the hinge axis, with the joint's own meaning, on a variable v continued through the step from
// its value at the step's start, v̇ = σ ∇θ·(ω_B − ω_A) (θ of Q11, σ the joint's sign):
//   stock hinge: v = wrap(σθ − c), c and h the centre and half range btAngularLimit keeps (btAngularLimit::test); the
//     stops are v = ±h; acts iff 0 ≤ h < π (low > high: h < 0, free; a range of 2π or more, h ≥ π, never acts, as
//     |v| ≤ π); σθ is btHingeConstraint::getHingeAngle on the hinge (σ its reference sign);
//   6-dof: v = btAdjustAngleToLimits(σθ, lo, hi) at the step's start (the wrapped angle on the branch of the nearer
//     stop, as the 6-dof tests it), stops lo and hi (the 6-dof's limits, which it wraps into [−π, π]); acts iff lo < hi
//     and the range is not the whole turn; σθ is the 6-dof's own angle of that axis (getAngle: its Euler angle, ±θ by
//     rotation order and axis; for the middle axis of its order within ±90°, where its asin reaches).
// Softness is stored and unused by stock, and not used here.
// Drive. A 6-dof's motor, servo or spring on its free axis (`driven`) is not projected, and the projection does not
// move that axis either: the limit slot holds the axis where Bullet's step left it (IslandRows.h), in angle and rate,
// so that the correction of a joint beside it (a weld at the wrist) does not turn the driven joint against its drive.
#ifndef QUATHINGE_STABILIZER_STOCK_HINGE_ROWS_H
#define QUATHINGE_STABILIZER_STOCK_HINGE_ROWS_H

#include "quathinge/btQuaternionHingeConstraint.h"

#include "LinearMath/btTransform.h"

class btTypedConstraint;

namespace quathinge
{
namespace stabilizer
{
/// Which hinge a constraint is to the stabilizer, besides quaternion hinges.
enum class FrameHingeKind
{
	None,
	Stock,  ///< btHingeConstraint, btHingeAccumulatedAngleConstraint
	Dof     ///< a 6-dof set up as a hinge
};

/// A stock or 6-dof hinge as read at a step's start (readFrameHinge, refreshFrameHinge).
ATTRIBUTE_ALIGNED16(struct)
FrameHinge
{
	btTransform frameA = btTransform::getIdentity();  // in A's centre-of-mass frame, ẑ the hinge axis
	btTransform frameB = btTransform::getIdentity();  // in B's
	bool angularOnly = false;
	btScalar sign = 1;            // the joint's own angle is sign·θ (Q11)
	bool limit = false;           // a limit that can act (above)
	bool driven = false;          // a 6-dof: a motor, servo or spring on the free axis (above)
	bool adjustToLimits = false;  // the step's first v: btAdjustAngleToLimits (6-dof), else wrapped about the centre
	int dofAxis = 2;              // a 6-dof: its free axis (x, y, z: 0–2)
	btScalar center = 0;          // c: v = sign·θ − c (0 for a 6-dof)
	btScalar low = 0, high = 0;   // the stops on v
};

/// The kind of `c` (None: neither, or not set up as a hinge; kinds not asked for are None), and, when not None, its
/// frames and limit into `out` (may be null: the kind alone, with its need of a limit slot in `limit`: a limit that can
/// act, or a 6-dof's drive on its free axis), and its
/// shape into `shape` (0 for a stock hinge; a 6-dof's free axis, bits 0–1, and its rotation order, bits 2–4).
FrameHingeKind readFrameHinge(const btTypedConstraint& c, bool stockHinges, bool dofHinges, FrameHinge* out,
							  bool* limit = nullptr, unsigned* shape = nullptr);

/// A 6-dof hinge's shape (readFrameHinge's) into `hinge`: its free axis and its angle's sign, what its rows keep while
/// the island stands (the stabilizer's scan keeps the shape in the island's signature, so a 6-dof whose free axis or
/// rotation order changes is built again).
void setDofHingeShape(unsigned shape, FrameHinge& hinge);

/// The frames and limit of a hinge read before (readFrameHinge or setDofHingeShape) as they are now: what the
/// joint's public API can change between steps (a stock hinge's setFrames, setLimit, setAngularOnly; a 6-dof's
/// frames, its locked linear values and its free axis's limits and drive). Read every step: a few loads and the frame product,
/// no more than comparing them with a kept copy would take.
void refreshFrameHinge(const btTypedConstraint& c, FrameHinge& hinge);

/// The hinge's rows at the given transforms (C, J as btQuaternionHingeConstraint::computePositionRows: up to 5 rows
/// of 12), and its limit variable v continued from previous, with its gradient: v̇ = gradient·(ω_B − ω_A).
int frameHingePositionRows(const FrameHinge& hinge, const btTransform& transA, const btTransform& transB, btScalar* C,
						   btScalar* jacobian, btScalar previous, btScalar& variable, btVector3& gradient);
/// The rows alone (a hinge without a limit slot).
inline int frameHingePositionRows(const FrameHinge& hinge, const btTransform& transA, const btTransform& transB,
								  btScalar* C, btScalar* jacobian)
{
	return btQuaternionHingeConstraint::computeFramePositionRows(hinge.frameA, hinge.frameB, hinge.angularOnly, transA,
																 transB, C, jacobian);
}

/// v at the given transforms as the joint `c` tests its limit (wrapped about the centre, or adjusted to the nearer
/// stop): the step's first. A 6-dof's from its angle alone (btQuaternionHingeConstraint::computeFrameAngle).
btScalar frameHingeLimitVariable(const btTypedConstraint& c, const FrameHinge& hinge, const btTransform& transA,
								 const btTransform& transB);
}  // namespace stabilizer
}  // namespace quathinge

#endif
