// Bullet's debugDrawConstraint draws only the stock types it downcasts, so the joint reports another type and draws
// itself.
#include "quathinge/btQuaternionHingeConstraint.h"

#include <btBulletDynamicsCommon.h>
#include <gtest/gtest.h>

namespace
{
struct CountingDrawer : btIDebugDraw
{
	int lines = 0;
	int mode = DBG_DrawConstraints | DBG_DrawConstraintLimits;
	void drawLine(const btVector3&, const btVector3&, const btVector3&) override { ++lines; }
	void drawContactPoint(const btVector3&, const btVector3&, btScalar, int, const btVector3&) override {}
	void reportErrorWarning(const char*) override {}
	void draw3dText(const btVector3&, const char*) override {}
	void setDebugMode(int m) override { mode = m; }
	int getDebugMode() const override { return mode; }
};
}  // namespace

TEST(DebugDraw, TypeIsNoneThatBulletDowncasts)
{
	// Not POINT2POINT, HINGE, CONETWIST, D6, D6_SPRING, D6_SPRING_2 or SLIDER (MATH.md, "Bullet's conventions").
	btBoxShape shape(btVector3(1, 1, 1));
	btRigidBody a(1, nullptr, &shape, btVector3(1, 1, 1)), b(1, nullptr, &shape, btVector3(1, 1, 1));
	btQuaternionHingeConstraint joint(a, b, btTransform::getIdentity(), btTransform::getIdentity());
	for (btTypedConstraintType t : {POINT2POINT_CONSTRAINT_TYPE, HINGE_CONSTRAINT_TYPE, CONETWIST_CONSTRAINT_TYPE,
									D6_CONSTRAINT_TYPE, SLIDER_CONSTRAINT_TYPE, D6_SPRING_CONSTRAINT_TYPE,
									D6_SPRING_2_CONSTRAINT_TYPE, GEAR_CONSTRAINT_TYPE, FIXED_CONSTRAINT_TYPE})
		EXPECT_NE(joint.getConstraintType(), t);
	EXPECT_EQ(joint.getConstraintType(), QUATERNION_HINGE_CONSTRAINT_TYPE);
}

TEST(DebugDraw, DrawsFramesAxisAndLimitArc)
{
	// Frames and axis always; the limit adds its arc.
	btBoxShape shape(btVector3(1, 1, 1));
	btRigidBody a(1, nullptr, &shape, btVector3(1, 1, 1)), b(1, nullptr, &shape, btVector3(1, 1, 1));
	btQuaternionHingeConstraint joint(a, b, btTransform::getIdentity(), btTransform::getIdentity());
	CountingDrawer plain, limited;
	joint.debugDraw(&plain);
	EXPECT_GE(plain.lines, 7);  // two frames (3 lines each) and the axis
	joint.setLimit(-1, 1);
	joint.debugDraw(&limited);
	EXPECT_GT(limited.lines, plain.lines);
}

TEST(DebugDraw, WorldDebugDrawSkipsTheJointSafely)
{
	// btDiscreteDynamicsWorld::debugDrawWorld with constraints on: the unknown type falls through its switch (no
	// downcast to a stock class), so drawing a world that holds the joint is safe (UBSan checks the enum value).
	btDefaultCollisionConfiguration config;
	btCollisionDispatcher dispatcher(&config);
	btDbvtBroadphase broadphase;
	btSequentialImpulseConstraintSolver solver;
	btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
	btBoxShape shape(btVector3(1, 1, 1));
	btRigidBody a(1, nullptr, &shape, btVector3(1, 1, 1)), b(1, nullptr, &shape, btVector3(1, 1, 1));
	btQuaternionHingeConstraint joint(a, b, btTransform::getIdentity(), btTransform::getIdentity());
	joint.setLimit(-1, 1);
	world.addRigidBody(&a);
	world.addRigidBody(&b);
	world.addConstraint(&joint, true);
	CountingDrawer drawer;
	drawer.mode = btIDebugDraw::DBG_DrawConstraints | btIDebugDraw::DBG_DrawConstraintLimits;
	world.setDebugDrawer(&drawer);
	world.debugDrawWorld();
	EXPECT_EQ(drawer.lines, 0);  // nothing drawn for it by the world: it draws itself (debugDraw above)
	world.removeConstraint(&joint);
	world.removeRigidBody(&b);
	world.removeRigidBody(&a);
}
