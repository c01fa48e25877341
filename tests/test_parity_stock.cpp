// Parity with btHingeConstraint: identical scenes through all four constructor forms and both useReferenceFrameA
// values give the same getHingeAngle trajectory; the stock-to-quaternion conversion and world replacement keep every
// setting.
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/World.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

namespace
{
// Trajectory agreement (rad) over 1 s of a converged 3-link chain: both solve the same hinge and differ only in how
// their rows treat the small residual misalignment; a triple pendulum is chaotic, which bounds how long this holds.
const double kParityTol = 1e-3;
// "Converged": enough iterations that both solvers meet their rows closely; 1 s of a chaotic triple pendulum.
const int kIterations = 50;
const int kSteps = 60;

using Make = std::function<btTypedConstraint*(btRigidBody&, btRigidBody&, bool, bool)>;

// Three links hanging from a static base, released at 60° from x, hinged about z; returns the angle trajectories.
std::vector<double> run(bool quaternion, int form, bool refA, double* maxSeparation)
{
	qh_test::World world;
	const btVector3 half(btScalar(0.05), btScalar(0.25), btScalar(0.05));
	btRigidBody* base = world.addBox(0, half, btTransform::getIdentity());
	// The world-hinge constructors do not link the first body to the base, so the base must not collide with it.
	base->setCollisionFlags(base->getCollisionFlags() | btCollisionObject::CF_NO_CONTACT_RESPONSE);
	std::vector<btRigidBody*> links;
	std::vector<btTypedConstraint*> joints;
	const btQuaternion tilt(btVector3(0, 0, 1), btScalar(SIMD_PI / 3));
	btVector3 top(0, 0, 0);
	btRigidBody* parent = base;
	for (int i = 0; i < 3; ++i)
	{
		const btVector3 centre = top + quatRotate(tilt, btVector3(0, btScalar(-0.25), 0));
		btRigidBody* link = world.addBox(1, half, btTransform(tilt, centre));
		const btVector3 pivotInParent =
			parent->getCenterOfMassTransform().inverse()(top);
		const btVector3 pivotInChild(0, btScalar(0.25), 0);
		btTransform frameParent(parent->getCenterOfMassTransform().getBasis().transpose(), pivotInParent);
		btTransform frameChild(link->getCenterOfMassTransform().getBasis().transpose(), pivotInChild);
		btTypedConstraint* joint = nullptr;
		const btVector3 z(0, 0, 1);
		if (quaternion)
		{
			switch (form)
			{
				case 0: joint = new btQuaternionHingeConstraint(*parent, *link, pivotInParent, pivotInChild, frameParent.getBasis() * z, frameChild.getBasis() * z, refA); break;
				case 1: joint = parent == base ? new btQuaternionHingeConstraint(*link, pivotInChild, frameChild.getBasis() * z, refA)
											   : new btQuaternionHingeConstraint(*parent, *link, frameParent, frameChild, refA); break;
				case 2: joint = new btQuaternionHingeConstraint(*parent, *link, frameParent, frameChild, refA); break;
				default: joint = parent == base ? new btQuaternionHingeConstraint(*link, frameChild, refA)
												: new btQuaternionHingeConstraint(*parent, *link, frameParent, frameChild, refA); break;
			}
		}
		else
		{
			switch (form)
			{
				case 0: joint = new btHingeConstraint(*parent, *link, pivotInParent, pivotInChild, frameParent.getBasis() * z, frameChild.getBasis() * z, refA); break;
				case 1: joint = parent == base ? new btHingeConstraint(*link, pivotInChild, frameChild.getBasis() * z, refA)
											   : new btHingeConstraint(*parent, *link, frameParent, frameChild, refA); break;
				case 2: joint = new btHingeConstraint(*parent, *link, frameParent, frameChild, refA); break;
				default: joint = parent == base ? new btHingeConstraint(*link, frameChild, refA)
												: new btHingeConstraint(*parent, *link, frameParent, frameChild, refA); break;
			}
		}
		world.add(joint);
		joints.push_back(joint);
		links.push_back(link);
		parent = link;
		top = top + quatRotate(tilt, btVector3(0, btScalar(-0.5), 0));
	}
	std::vector<double> angles;
	*maxSeparation = 0;
	for (int step = 0; step < kSteps; ++step)
	{
		world.step(1, btScalar(1) / 60, kIterations);
		for (btTypedConstraint* j : joints)
		{
			if (quaternion)
			{
				auto* q = static_cast<btQuaternionHingeConstraint*>(j);
				angles.push_back(q->getHingeAngle());
				*maxSeparation = std::max(*maxSeparation, qh_test::separation(q->getRigidBodyA(), q->getAFrame(), q->getRigidBodyB(), q->getBFrame()));
			}
			else
			{
				auto* h = static_cast<btHingeConstraint*>(j);
				angles.push_back(h->getHingeAngle());
				*maxSeparation = std::max(*maxSeparation, qh_test::separation(h->getRigidBodyA(), h->getAFrame(), h->getRigidBodyB(), h->getBFrame()));
			}
		}
	}
	return angles;
}
}  // namespace

TEST(ParityWithStock, SameAngleTrajectoryThroughAllConstructorsAndReferenceFrames)
{
	// 4 constructor forms × 2 reference frames: the chain's joint angles follow stock's within kParityTol.
	double worstAll = 0;
	for (int form = 0; form < 4; ++form)
		for (bool refA : {false, true})
		{
			double sepStock = 0, sepQuat = 0;
			const std::vector<double> stock = run(false, form, refA, &sepStock);
			const std::vector<double> quat = run(true, form, refA, &sepQuat);
			ASSERT_EQ(stock.size(), quat.size());
			double worst = 0;
			for (size_t i = 0; i < stock.size(); ++i)
				worst = std::max(worst, std::fabs(std::remainder(stock[i] - quat[i], 2 * M_PI)));
			std::printf("[ figures  ] form %d refA %d: max angle difference %.3g rad; max separation stock %.3g m, quaternion %.3g m\n",
						form, int(refA), worst, sepStock, sepQuat);
			EXPECT_LT(worst, kParityTol) << "form " << form << " refA " << refA;
			worstAll = std::max(worstAll, worst);
		}
	std::printf("[ figures  ] parity: worst angle difference %.3g rad\n", worstAll);
}

TEST(ParityWithStock, ConversionKeepsEverySetting)
{
	// btQuaternionHingeConstraint(const btHingeConstraint&) copies frames, limit, motor, parameters, threshold, enabled.
	btBoxShape shape(btVector3(1, 1, 1));
	btRigidBody a(1, nullptr, &shape, btVector3(1, 1, 1)), b(1, nullptr, &shape, btVector3(1, 1, 1));
	const btTransform fa(btQuaternion(btVector3(1, 0, 0), btScalar(0.3)), btVector3(0, 1, 0));
	const btTransform fb(btQuaternion(btVector3(0, 1, 0), btScalar(0.2)), btVector3(0, -1, 0));
	btHingeConstraint stock(a, b, fa, fb, true);
	stock.setLimit(btScalar(2.5), btScalar(3.8), btScalar(0.8), btScalar(0.4), btScalar(0.5));  // across ±π
	stock.enableAngularMotor(true, btScalar(1.5), btScalar(7));
	stock.setParam(BT_CONSTRAINT_ERP, btScalar(0.6));
	stock.setParam(BT_CONSTRAINT_STOP_CFM, btScalar(0.01));
	stock.setBreakingImpulseThreshold(btScalar(123));
	stock.setEnabled(false);
	stock.setUserConstraintType(42);
	stock.setOverrideNumSolverIterations(17);
	btQuaternionHingeConstraint q(stock);
	EXPECT_EQ(q.getAFrame().getOrigin(), fa.getOrigin());
	EXPECT_EQ(q.getBFrame().getOrigin(), fb.getOrigin());
	EXPECT_TRUE(q.getUseReferenceFrameA());
	EXPECT_TRUE(q.hasLimit());
	EXPECT_NEAR(q.getLowerLimit(), 2.5, 1e-5);
	EXPECT_NEAR(q.getUpperLimit(), 3.8, 1e-5);  // unwrapped: stock reports −2.48
	EXPECT_NEAR(q.getLimitSoftness(), 0.8, 1e-6);
	EXPECT_NEAR(q.getLimitBiasFactor(), 0.4, 1e-6);
	EXPECT_NEAR(q.getLimitRelaxationFactor(), 0.5, 1e-6);
	EXPECT_TRUE(q.getEnableAngularMotor());
	EXPECT_EQ(q.getMotorTargetVelocity(), btScalar(1.5));
	EXPECT_EQ(q.getMaxMotorImpulse(), btScalar(7));
	EXPECT_EQ(q.getParam(BT_CONSTRAINT_ERP, 0), btScalar(0.6));  // stock's normal ERP acts on every row
	EXPECT_EQ(q.getParam(BT_CONSTRAINT_STOP_CFM), btScalar(0.01));
	EXPECT_EQ(q.getBreakingImpulseThreshold(), btScalar(123));
	EXPECT_FALSE(q.isEnabled());
	EXPECT_EQ(q.getUserConstraintType(), 42);
	EXPECT_EQ(q.getOverrideNumSolverIterations(), 17);
}

TEST(ParityWithStock, ReplaceHingeConstraintsSwapsEveryStockHinge)
{
	// A world with three stock hinges and one other constraint: three are replaced, the other stays, the count is 3.
	qh_test::World world;
	btRigidBody* base = world.addBox(0, btVector3(1, 1, 1), btTransform::getIdentity());
	btRigidBody* b1 = world.addBox(1, btVector3(1, 1, 1), btTransform(btQuaternion::getIdentity(), btVector3(0, -2, 0)));
	btRigidBody* b2 = world.addBox(1, btVector3(1, 1, 1), btTransform(btQuaternion::getIdentity(), btVector3(0, -4, 0)));
	btRigidBody* b3 = world.addBox(1, btVector3(1, 1, 1), btTransform(btQuaternion::getIdentity(), btVector3(0, -6, 0)));
	btDiscreteDynamicsWorld& w = world.world();
	btHingeConstraint h1(*base, *b1, btVector3(0, -1, 0), btVector3(0, 1, 0), btVector3(0, 0, 1), btVector3(0, 0, 1));
	btHingeConstraint h2(*b1, *b2, btVector3(0, -1, 0), btVector3(0, 1, 0), btVector3(0, 0, 1), btVector3(0, 0, 1));
	btHingeConstraint h3(*b2, *b3, btVector3(0, -1, 0), btVector3(0, 1, 0), btVector3(0, 0, 1), btVector3(0, 0, 1));
	btPoint2PointConstraint p(*base, *b3, btVector3(5, 0, 0), btVector3(5, 0, 0));
	w.addConstraint(&h1, true);
	w.addConstraint(&h2, false);
	w.addConstraint(&h3, true);
	w.addConstraint(&p);
	btAlignedObjectArray<btQuaternionHingeConstraint*> added;
	btAlignedObjectArray<btHingeConstraint*> removed;
	EXPECT_EQ(btReplaceHingeConstraints(&w, &added, &removed), 3);
	EXPECT_EQ(w.getNumConstraints(), 4);
	EXPECT_EQ(added.size(), 3);
	EXPECT_EQ(removed.size(), 3);
	int quaternionHinges = 0;
	for (int i = 0; i < w.getNumConstraints(); ++i)
		quaternionHinges += w.getConstraint(i)->getConstraintType() == QUATERNION_HINGE_CONSTRAINT_TYPE;
	EXPECT_EQ(quaternionHinges, 3);
	// disableCollisionsBetweenLinkedBodies kept: h2 was added with false, so its replacement is not referenced by b1
	int refsB1 = 0;
	for (int i = 0; i < b1->getNumConstraintRefs(); ++i) refsB1 += b1->getConstraintRef(i) == added[1];
	EXPECT_EQ(refsB1, 0);
	int refsBase = 0;
	for (int i = 0; i < base->getNumConstraintRefs(); ++i) refsBase += base->getConstraintRef(i) == added[0];
	EXPECT_EQ(refsBase, 1);
	world.step(10);
	for (int i = 0; i < added.size(); ++i)
	{
		w.removeConstraint(added[i]);
		delete added[i];
	}
	w.removeConstraint(&p);
}
