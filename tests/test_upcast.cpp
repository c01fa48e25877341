// btQuaternionHingeConstraint::upcast (issue 17, item 5): a checked downcast that takes no other constraint for a
// quaternion hinge — not Bullet's own, and not another plugin's that happens to use the same type number.
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/World.h"

#include "BulletDynamics/ConstraintSolver/btHingeConstraint.h"

#include <gtest/gtest.h>

#ifdef QUATHINGE_HAVE_STABILIZER
#include "quathinge/btQuaternionHingeStabilizer.h"
#endif

namespace
{
// Another plugin's constraint that claims the quaternion hinge's type number: one bilateral row holding body A's
// height, nothing like a hinge in memory. A static_cast on the number would read its fields as a hinge's.
class ImpostorConstraint : public btTypedConstraint
{
public:
	explicit ImpostorConstraint(btRigidBody& a) : btTypedConstraint(QUATERNION_HINGE_CONSTRAINT_TYPE, a) {}
	void getInfo1(btConstraintInfo1* info) override
	{
		info->m_numConstraintRows = 1;
		info->nub = 1;
	}
	void getInfo2(btConstraintInfo2* info) override
	{
		info->m_J1linearAxis[1] = 1;
		info->m_constraintError[0] = -info->fps * info->erp * m_rbA.getCenterOfMassPosition().y();
	}
	void setParam(int, btScalar, int) override {}
	btScalar getParam(int, int) const override { return 0; }
};
}  // namespace

TEST(Upcast, TakesOnlyQuaternionHinges)
{
	btBoxShape shape(btVector3(1, 1, 1));
	btRigidBody a(1, nullptr, &shape, btVector3(1, 1, 1)), b(1, nullptr, &shape, btVector3(1, 1, 1));
	btQuaternionHingeConstraint hinge(a, b, btTransform::getIdentity(), btTransform::getIdentity());
	btHingeConstraint stock(a, b, btTransform::getIdentity(), btTransform::getIdentity());
	ImpostorConstraint impostor(a);
	ASSERT_EQ(impostor.getConstraintType(), hinge.getConstraintType());  // the same number
	btTypedConstraint* asTyped = &hinge;
	EXPECT_EQ(btQuaternionHingeConstraint::upcast(asTyped), &hinge);
	EXPECT_EQ(btQuaternionHingeConstraint::upcast(static_cast<const btTypedConstraint*>(asTyped)), &hinge);
	EXPECT_EQ(btQuaternionHingeConstraint::upcast(&stock), nullptr);
	EXPECT_EQ(btQuaternionHingeConstraint::upcast(&impostor), nullptr);
	EXPECT_EQ(btQuaternionHingeConstraint::upcast(static_cast<const btTypedConstraint*>(&impostor)), nullptr);
	EXPECT_EQ(btQuaternionHingeConstraint::upcast(static_cast<btTypedConstraint*>(nullptr)), nullptr);
}

#ifdef QUATHINGE_HAVE_STABILIZER
TEST(Upcast, StabilizerSkipsAnotherPluginsConstraintWithTheSameNumber)
{
	// A world with a quaternion hinge pendulum and an impostor of the same type number: the stabilizer projects the
	// hinge (one joint in its islands) and leaves the impostor alone.
	qh_test::World world;
	btRigidBody* base = world.addBox(0, btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)), btTransform::getIdentity());
	btRigidBody* bob = world.addBox(1, btVector3(btScalar(0.1), btScalar(0.5), btScalar(0.1)),
									btTransform(btQuaternion::getIdentity(), btVector3(0, -1, 0)));
	btRigidBody* other = world.addBox(1, btVector3(btScalar(0.2), btScalar(0.2), btScalar(0.2)),
									  btTransform(btQuaternion::getIdentity(), btVector3(3, 0, 0)));
	world.add(new btQuaternionHingeConstraint(*base, *bob, btVector3(0, 0, 0), btVector3(0, 1, 0), btVector3(0, 0, 1),
											  btVector3(0, 0, 1)));
	world.add(new ImpostorConstraint(*other));
	btQuaternionHingeStabilizer stabilizer;
	world.world().addAction(&stabilizer);
	bob->setLinearVelocity(btVector3(2, 0, 0));
	world.step(30);
	world.world().removeAction(&stabilizer);
	EXPECT_EQ(stabilizer.getLastStats().joints, 1);
	EXPECT_LT(std::fabs(double(other->getCenterOfMassPosition().y())), 0.05);  // the impostor's own row held it
}
#endif
