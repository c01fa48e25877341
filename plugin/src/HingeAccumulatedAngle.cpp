// btQuaternionHingeAccumulatedAngleConstraint: stock's btHingeAccumulatedAngleConstraint names for the multi-turn
// angle (docs/MATH.md Q11; HingeLimitsAndDrives.cpp keeps it).
#include "quathinge/btQuaternionHingeConstraint.h"

#include "HingeAngle.h"
#include "InputChecks.h"

#include "BulletDynamics/ConstraintSolver/btHingeConstraint.h"

using namespace quathinge;

namespace
{
// Stock's btShortestAngleUpdate: a change of more than this between two updates starts the count again (rad).
const btScalar kStockUpdateTolerance = btScalar(0.3);
}  // namespace

btQuaternionHingeAccumulatedAngleConstraint::btQuaternionHingeAccumulatedAngleConstraint(
	btRigidBody& rbA, btRigidBody& rbB, const btVector3& pivotInA, const btVector3& pivotInB, const btVector3& axisInA,
	const btVector3& axisInB, bool useReferenceFrameA)
	: btQuaternionHingeConstraint(rbA, rbB, pivotInA, pivotInB, axisInA, axisInB, useReferenceFrameA)
{
	getMultiTurnAngle();  // tracked from here on, starting at the wrapped angle (stock: getHingeAngle())
}

btQuaternionHingeAccumulatedAngleConstraint::btQuaternionHingeAccumulatedAngleConstraint(
	btRigidBody& rbA, const btVector3& pivotInA, const btVector3& axisInA, bool useReferenceFrameA)
	: btQuaternionHingeConstraint(rbA, pivotInA, axisInA, useReferenceFrameA)
{
	getMultiTurnAngle();
}

btQuaternionHingeAccumulatedAngleConstraint::btQuaternionHingeAccumulatedAngleConstraint(
	btRigidBody& rbA, btRigidBody& rbB, const btTransform& rbAFrame, const btTransform& rbBFrame,
	bool useReferenceFrameA)
	: btQuaternionHingeConstraint(rbA, rbB, rbAFrame, rbBFrame, useReferenceFrameA)
{
	getMultiTurnAngle();
}

btQuaternionHingeAccumulatedAngleConstraint::btQuaternionHingeAccumulatedAngleConstraint(
	btRigidBody& rbA, const btTransform& rbAFrame, bool useReferenceFrameA)
	: btQuaternionHingeConstraint(rbA, rbAFrame, useReferenceFrameA)
{
	getMultiTurnAngle();
}

btQuaternionHingeAccumulatedAngleConstraint::btQuaternionHingeAccumulatedAngleConstraint(const btHingeConstraint& stock)
	: btQuaternionHingeConstraint(stock)
{
	// getAccumulatedHingeAngle is not const (it updates the count): reading it leaves the stock hinge as it would be
	// after its own next update.
	if (auto* counted = dynamic_cast<btHingeAccumulatedAngleConstraint*>(const_cast<btHingeConstraint*>(&stock)))
		setAccumulatedHingeAngle(counted->getAccumulatedHingeAngle());
	else
		getMultiTurnAngle();
}

void btQuaternionHingeAccumulatedAngleConstraint::setAccumulatedHingeAngle(btScalar accAngle)
{
	if (!check::angle("btQuaternionHingeAccumulatedAngleConstraint::setAccumulatedHingeAngle", "accAngle", accAngle))
		return;
	const btScalar raw = getHingeAngle();
	const btScalar toPose = wrapAngle(raw - accAngle);
	setMultiTurnAngle(btFabs(toPose) > kStockUpdateTolerance ? raw : accAngle + toPose);
}
