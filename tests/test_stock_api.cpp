// The class swap at the level of the compiler: one function template calls every public method of Bullet 3.24's
// btHingeConstraint (and of its subclass btHingeAccumulatedAngleConstraint) with stock's argument types, and is
// instantiated for stock and for the quaternion hinge. A method missing or with another signature on the quaternion
// side stops this file from compiling; the reads that have the same meaning on both are compared. (What each call
// does is tested in test_stock_meaning.cpp, test_caller_patterns_*.cpp, test_limits.cpp, test_drives.cpp.)
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/World.h"

#include "BulletDynamics/ConstraintSolver/btHingeConstraint.h"

#include <gtest/gtest.h>

#include <type_traits>
#include <vector>

namespace
{
// Reads compared between the classes: the same bodies, frames and calls; the hinge angle after one step differs by the
// two joints' residuals (rad), far below this.
const double kReadTol = 1e-4;

template <class Hinge>
std::vector<double> useEveryStockMethod()
{
	static_assert(std::is_base_of<btTypedConstraint, Hinge>::value, "a btTypedConstraint, as stock");
	std::vector<double> reads;
	qh_test::World w;
	btRigidBody* a = w.addBox(1, btVector3(1, 1, 1), btTransform::getIdentity());
	btRigidBody* b = w.addBox(1, btVector3(1, 1, 1), btTransform(btQuaternion::getIdentity(), btVector3(0, -3, 0)));
	const btVector3 pivotA(0, btScalar(-1.5), 0), pivotB(0, btScalar(1.5), 0), axis(0, 0, 1);
	// the four constructors
	Hinge* h = w.add(new Hinge(*a, *b, pivotA, pivotB, axis, axis, false));
	w.add(new Hinge(*a, pivotA, axis, false));
	w.add(new Hinge(*a, *b, btTransform::getIdentity(), btTransform::getIdentity(), false));
	w.add(new Hinge(*a, btTransform::getIdentity(), false));
	for (int i = w.world().getNumConstraints() - 1; i > 0; --i)
		w.world().removeConstraint(w.world().getConstraint(i));  // only h takes part in the steps below

	h->buildJacobian();
	h->updateRHS(btScalar(1) / 60);
	const Hinge& c = *h;
	reads.push_back(&c.getRigidBodyA() == a);
	reads.push_back(&c.getRigidBodyB() == b);
	reads.push_back(&h->getRigidBodyA() == a);
	reads.push_back(h->getFrameOffsetA().getOrigin().y());
	reads.push_back(h->getFrameOffsetB().getOrigin().y());
	h->setFrames(h->getAFrame(), h->getBFrame());
	h->setAngularOnly(false);
	h->enableAngularMotor(true, btScalar(0.5), btScalar(2));
	h->enableMotor(false);
	h->setMaxMotorImpulse(btScalar(3));
	h->setMotorTargetVelocity(btScalar(0.25));
	h->setMotorTarget(btQuaternion::getIdentity(), btScalar(1) / 60);
	h->setMotorTarget(btScalar(0.1), btScalar(1) / 60);
	h->setLimit(btScalar(-1), btScalar(1));
	h->setLimit(btScalar(-1), btScalar(1), btScalar(0.8), btScalar(0.4), btScalar(0.9));
	reads.push_back(h->getLimitSoftness());
	reads.push_back(h->getLimitBiasFactor());
	reads.push_back(h->getLimitRelaxationFactor());
	btVector3 axisInA(0, 0, 1);  // stock takes a non-const reference
	h->setAxis(axisInA);
	reads.push_back(h->hasLimit());
	reads.push_back(h->getLowerLimit());
	reads.push_back(h->getUpperLimit());
	reads.push_back(h->getHingeAngle());
	reads.push_back(h->getHingeAngle(a->getCenterOfMassTransform(), b->getCenterOfMassTransform()));
	h->testLimit(a->getCenterOfMassTransform(), b->getCenterOfMassTransform());
	reads.push_back(c.getAFrame().getOrigin().y());
	reads.push_back(c.getBFrame().getOrigin().y());
	reads.push_back(h->getAFrame().getOrigin().y());
	reads.push_back(h->getBFrame().getOrigin().y());
	reads.push_back(h->getSolveLimit());
	reads.push_back(h->getLimitSign());
	reads.push_back(h->getAngularOnly());
	reads.push_back(h->getEnableAngularMotor());
	reads.push_back(h->getMotorTargetVelocity());
	reads.push_back(h->getMaxMotorImpulse());
	h->setUseFrameOffset(h->getUseFrameOffset());
	h->setUseReferenceFrameA(h->getUseReferenceFrameA());
	h->setParam(BT_CONSTRAINT_ERP, btScalar(0.3));
	h->setParam(BT_CONSTRAINT_STOP_CFM, btScalar(0.01), 5);
	reads.push_back(h->getParam(BT_CONSTRAINT_ERP));
	reads.push_back(h->getParam(BT_CONSTRAINT_STOP_CFM, 5));
	reads.push_back(h->getFlags() != 0);
	// the solver's entry points (the non-virtual path with rows of the size getInfo1NonVirtual reserved)
	btTypedConstraint::btConstraintInfo1 info1;
	h->getInfo1(&info1);
	h->getInfo1NonVirtual(&info1);
	const int n = info1.m_numConstraintRows;
	std::vector<btScalar> rows(size_t(8 * n * 8), 0);
	btTypedConstraint::btConstraintInfo2 info2;
	info2.fps = 60;
	info2.erp = btScalar(0.2);
	info2.rowskip = 8;
	info2.m_J1linearAxis = &rows[0];
	info2.m_J1angularAxis = &rows[size_t(8 * n)];
	info2.m_J2linearAxis = &rows[size_t(16 * n)];
	info2.m_J2angularAxis = &rows[size_t(24 * n)];
	info2.m_constraintError = &rows[size_t(32 * n)];
	info2.cfm = &rows[size_t(40 * n)];
	info2.m_lowerLimit = &rows[size_t(48 * n)];
	info2.m_upperLimit = &rows[size_t(56 * n)];
	info2.m_numIterations = 10;
	info2.m_damping = 1;
	const btTransform tA = a->getCenterOfMassTransform(), tB = b->getCenterOfMassTransform();
	const btVector3 wA = a->getAngularVelocity(), wB = b->getAngularVelocity();
	h->getInfo2NonVirtual(&info2, tA, tB, wA, wB);
	h->getInfo2Internal(&info2, tA, tB, wA, wB);
	h->getInfo2InternalUsingFrameOffset(&info2, tA, tB, wA, wB);
	// serialization (what a btSerializer asks first; the chunks themselves: test_serialize.cpp)
	reads.push_back(h->calculateSerializeBufferSize() >= int(sizeof(btHingeConstraintData)));
	w.step(1);
	reads.push_back(h->getHingeAngle());
	return reads;
}

template <class Hinge>
std::vector<double> useEveryAccumulatedAngleMethod()
{
	std::vector<double> reads;
	qh_test::World w(qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, 0));
	btRigidBody* a = w.addBox(0, btVector3(1, 1, 1), btTransform::getIdentity());
	btRigidBody* b = w.addBox(1, btVector3(1, 1, 1), btTransform::getIdentity());
	const btVector3 o(0, 0, 0), z(0, 0, 1);
	Hinge* h = w.add(new Hinge(*a, *b, o, o, z, z, false));
	w.add(new Hinge(*a, o, z, false));
	w.add(new Hinge(*a, *b, btTransform::getIdentity(), btTransform::getIdentity(), false));
	w.add(new Hinge(*a, btTransform::getIdentity(), false));
	for (int i = w.world().getNumConstraints() - 1; i > 0; --i)
		w.world().removeConstraint(w.world().getConstraint(i));
	b->setAngularVelocity(btVector3(0, 0, 2));
	w.step(240);  // 8 rad
	reads.push_back(h->getAccumulatedHingeAngle());
	h->setAccumulatedHingeAngle(h->getAccumulatedHingeAngle() + btScalar(SIMD_2_PI));
	reads.push_back(h->getAccumulatedHingeAngle());
	return reads;
}
}  // namespace

TEST(StockApi, EveryPublicMethodOfStocksHingeCompilesAndReadsAsStock)
{
	const std::vector<double> stock = useEveryStockMethod<btHingeConstraint>();
	const std::vector<double> quat = useEveryStockMethod<btQuaternionHingeConstraint>();
	ASSERT_EQ(quat.size(), stock.size());
	for (size_t i = 0; i < stock.size(); ++i) EXPECT_NEAR(quat[i], stock[i], kReadTol) << "read " << i;
}

TEST(StockApi, EveryPublicMethodOfStocksAccumulatedAngleHingeCompilesAndReadsAsStock)
{
	const std::vector<double> stock = useEveryAccumulatedAngleMethod<btHingeAccumulatedAngleConstraint>();
	const std::vector<double> quat = useEveryAccumulatedAngleMethod<btQuaternionHingeAccumulatedAngleConstraint>();
	ASSERT_EQ(quat.size(), stock.size());
	for (size_t i = 0; i < stock.size(); ++i) EXPECT_NEAR(quat[i], stock[i], kReadTol) << "read " << i;
	EXPECT_NEAR(quat[0], -8.0, kReadTol);  // 2 rad/s for 4 s, stock's sign
}
