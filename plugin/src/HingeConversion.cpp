// Upgrading existing apps and .bullet files: the quaternion hinge equivalent to a stock btHingeConstraint, and the
// replacement of every stock hinge in a world.
#include "quathinge/btQuaternionHingeConstraint.h"

#include "BulletDynamics/ConstraintSolver/btHingeConstraint.h"
#include "BulletDynamics/Dynamics/btDynamicsWorld.h"
#include "BulletDynamics/Dynamics/btRigidBody.h"

namespace
{
// btHingeConstraint's getters are partly non-const; reading them does not change it.
btHingeConstraint& mutableStock(const btHingeConstraint& stock) { return const_cast<btHingeConstraint&>(stock); }

bool bodyRefersTo(btRigidBody& body, const btTypedConstraint* constraint)
{
	for (int i = 0; i < body.getNumConstraintRefs(); ++i)
		if (body.getConstraintRef(i) == constraint) return true;
	return false;
}
}  // namespace

btQuaternionHingeConstraint::btQuaternionHingeConstraint(const btHingeConstraint& stock)
	: btQuaternionHingeConstraint(mutableStock(stock).getRigidBodyA(), mutableStock(stock).getRigidBodyB(),
								  stock.getAFrame(), stock.getBFrame(), stock.getUseReferenceFrameA())
{
	btHingeConstraint& s = mutableStock(stock);
	setAngularOnly(s.getAngularOnly());
	setUseFrameOffset(s.getUseFrameOffset());
	if (stock.hasLimit())
	{
		// Stock keeps a centre and a half range and reports both ends wrapped into (−π, π]; a range across ±π then
		// comes back with high < low and is unwrapped here.
		btScalar low = stock.getLowerLimit(), high = stock.getUpperLimit();
		// (ends that wrap to the same angle with a range: a whole number of turns, which never acts in stock; one turn
		// never acts here either)
		if (high <= low) high += SIMD_2_PI;
		setLimit(low, high, stock.getLimitSoftness(), stock.getLimitBiasFactor(), stock.getLimitRelaxationFactor());
	}
	else if (stock.getLowerLimit() == stock.getUpperLimit())
	{
		// stock locks the joint when the half range is exactly 0 (btAngularLimit::test uses halfRange ≥ 0)
		setLimit(stock.getLowerLimit(), stock.getUpperLimit(), stock.getLimitSoftness(), stock.getLimitBiasFactor(),
				 stock.getLimitRelaxationFactor());
	}
	// btHingeConstraint leaves its motor's velocity and impulse uninitialized until a motor call sets them, so they
	// are read only when its motor is on (reading them otherwise copied stray memory: a denormal negative impulse
	// that setMaxMotorImpulse rightly refused).
	if (s.getEnableAngularMotor()) enableAngularMotor(true, s.getMotorTargetVelocity(), s.getMaxMotorImpulse());

	const int flags = stock.getFlags();
	// Stock's normal ERP acts on every row; its normal CFM only on the motor row (axis 5).
	if (flags & BT_HINGE_FLAGS_ERP_NORM) setParam(BT_CONSTRAINT_ERP, stock.getParam(BT_CONSTRAINT_ERP));
	if (flags & BT_HINGE_FLAGS_CFM_NORM) setParam(BT_CONSTRAINT_CFM, stock.getParam(BT_CONSTRAINT_CFM), 5);
	if (flags & BT_HINGE_FLAGS_ERP_STOP) setParam(BT_CONSTRAINT_STOP_ERP, stock.getParam(BT_CONSTRAINT_STOP_ERP));
	if (flags & BT_HINGE_FLAGS_CFM_STOP) setParam(BT_CONSTRAINT_STOP_CFM, stock.getParam(BT_CONSTRAINT_STOP_CFM));

	setBreakingImpulseThreshold(stock.getBreakingImpulseThreshold());
	setEnabled(stock.isEnabled());
	setUserConstraintType(stock.getUserConstraintType());
	setUserConstraintPtr(mutableStock(stock).getUserConstraintPtr());  // shares storage with the user id
	setOverrideNumSolverIterations(stock.getOverrideNumSolverIterations());
	setJointFeedback(mutableStock(stock).getJointFeedback());
	enableFeedback(stock.needsFeedback());
	setDbgDrawSize(mutableStock(stock).getDbgDrawSize());
}

void btSwapConstraintInWorld(btDynamicsWorld* world, btTypedConstraint* constraint, btTypedConstraint* replacement)
{
	// The replacement takes the constraint's place in the world's constraint order, the order Bullet's solver meets
	// the joints in (Gauss–Seidel's result after a fixed number of iterations depends on it: spider.bullet's hinges,
	// swapped one by one in another order, separated 1.22× stock's at 10 iterations against 1.01× in place; issue 16,
	// docs/ROW_BASIS.md). Bullet's removeConstraint moves the world's last constraint into the freed place and
	// addConstraint appends, so after the swap the former last constraint sits in that place and the replacement at
	// the end; taking the former last out and adding it again swaps them back. Three linear searches, no copy of the
	// list. A world that removes otherwise keeps whatever order it made (every constraint is still in it).
	const int count = world->getNumConstraints();
	int place = -1;
	for (int i = 0; i < count && place < 0; ++i)
		if (world->getConstraint(i) == constraint) place = i;
	btTypedConstraint* last = count > 0 ? world->getConstraint(count - 1) : 0;
	// addConstraint(c, true) registers c with both bodies; that is how the world remembers the choice.
	const bool disableCollisions = bodyRefersTo(constraint->getRigidBodyA(), constraint);
	world->removeConstraint(constraint);
	world->addConstraint(replacement, disableCollisions);
	if (place < 0 || last == constraint || place >= world->getNumConstraints() || world->getConstraint(place) != last)
		return;
	const bool lastDisablesCollisions = bodyRefersTo(last->getRigidBodyA(), last);
	world->removeConstraint(last);  // the replacement, now the last, moves into its place
	world->addConstraint(last, lastDisablesCollisions);
}

namespace
{
bool listed(const btAlignedObjectArray<btTypedConstraint*>* list, const btTypedConstraint* constraint)
{
	if (!list) return false;
	for (int i = 0; i < list->size(); ++i)
		if ((*list)[i] == constraint) return true;
	return false;
}

// Replaces the world's stock hinges; each removed one goes to *yours unless it is listed in *ownedElsewhere, and to
// *every (the deprecated form's list) in any case. Deletes none of them: this function did not allocate them.
int replaceHinges(btDynamicsWorld* world, btAlignedObjectArray<btQuaternionHingeConstraint*>* added,
				  btAlignedObjectArray<btHingeConstraint*>* yours,
				  const btAlignedObjectArray<btTypedConstraint*>* ownedElsewhere,
				  btAlignedObjectArray<btHingeConstraint*>* every)
{
	btAlignedObjectArray<btHingeConstraint*> stockHinges;
	for (int i = 0; i < world->getNumConstraints(); ++i)
	{
		btTypedConstraint* constraint = world->getConstraint(i);
		if (constraint->getConstraintType() == HINGE_CONSTRAINT_TYPE)
			stockHinges.push_back(static_cast<btHingeConstraint*>(constraint));
	}
	for (int i = 0; i < stockHinges.size(); ++i)
	{
		btHingeConstraint* stock = stockHinges[i];
		// a btHingeAccumulatedAngleConstraint becomes the class with its names, its count of turns carried over
		btQuaternionHingeConstraint* replacement =
			dynamic_cast<btHingeAccumulatedAngleConstraint*>(stock)
				? new btQuaternionHingeAccumulatedAngleConstraint(*stock)
				: new btQuaternionHingeConstraint(*stock);
		btSwapConstraintInWorld(world, stock, replacement);  // in the stock hinge's place
		if (added) added->push_back(replacement);
		// a world importer owns the hinges it loaded and deletes them in deleteAllData; an app deletes its own
		if (yours && !listed(ownedElsewhere, stock)) yours->push_back(stock);
		if (every) every->push_back(stock);
	}
	return stockHinges.size();
}
}  // namespace

int btReplaceHingeConstraints(btDynamicsWorld* world, btAlignedObjectArray<btQuaternionHingeConstraint*>* added)
{
	return replaceHinges(world, added, 0, 0, 0);
}

int btReplaceHingeConstraints(btDynamicsWorld* world, btAlignedObjectArray<btQuaternionHingeConstraint*>* added,
							  btAlignedObjectArray<btHingeConstraint*>* removedYours,
							  const btAlignedObjectArray<btTypedConstraint*>* ownedElsewhere)
{
	return replaceHinges(world, added, removedYours, ownedElsewhere, 0);
}

int btReplaceHingeConstraints(btDynamicsWorld* world, btAlignedObjectArray<btQuaternionHingeConstraint*>* added,
							  btAlignedObjectArray<btHingeConstraint*>* removedStock)
{
	return replaceHinges(world, added, 0, 0, removedStock);
}
