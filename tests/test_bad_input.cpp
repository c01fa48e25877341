// Bad input gets a clear error naming the parameter (std::invalid_argument, or the error callback in a build without
// exceptions) and never reaches the joint or the solver; bad state from outside (a NaN velocity) disables the joint instead of spreading.
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/World.h"

#include "support/Refusal.h"
#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>

namespace
{
const btScalar kNaN = std::numeric_limits<btScalar>::quiet_NaN();
const btScalar kInf = std::numeric_limits<btScalar>::infinity();

// Expects `call` to be refused with a message naming `parameter` (thrown with exceptions, reported through the error
// callback without them: support/Refusal.h).
void expectRefused(const std::function<void()>& call, const std::string& parameter)
{
	EXPECT_TRUE(qh_test::refused(call, parameter));
}

// Every field of two settings structs (frames exactly, scalars exactly).
void expectSameSettings(const btQuaternionHingeSettings& x, const btQuaternionHingeSettings& y, const std::string& after)
{
	EXPECT_TRUE(x.frameInA == y.frameInA) << after;
	EXPECT_TRUE(x.frameInB == y.frameInB) << after;
	EXPECT_EQ(x.useReferenceFrameA, y.useReferenceFrameA) << after;
	EXPECT_EQ(x.angularOnly, y.angularOnly) << after;
	EXPECT_EQ(x.useFrameOffset, y.useFrameOffset) << after;
	EXPECT_EQ(x.hasLimit, y.hasLimit) << after;
	EXPECT_EQ(x.lowerLimit, y.lowerLimit) << after;
	EXPECT_EQ(x.upperLimit, y.upperLimit) << after;
	EXPECT_EQ(x.limitSoftness, y.limitSoftness) << after;
	EXPECT_EQ(x.limitBiasFactor, y.limitBiasFactor) << after;
	EXPECT_EQ(x.limitRelaxationFactor, y.limitRelaxationFactor) << after;
	EXPECT_EQ(x.driveMode, y.driveMode) << after;
	EXPECT_EQ(x.motorTargetVelocity, y.motorTargetVelocity) << after;
	EXPECT_EQ(x.maxMotorImpulse, y.maxMotorImpulse) << after;
	EXPECT_EQ(x.servoTargetAngle, y.servoTargetAngle) << after;
	EXPECT_EQ(x.servoMaxSpeed, y.servoMaxSpeed) << after;
	EXPECT_EQ(x.servoMaxTorque, y.servoMaxTorque) << after;
	EXPECT_EQ(x.springRestAngle, y.springRestAngle) << after;
	EXPECT_EQ(x.springFrequency, y.springFrequency) << after;
	EXPECT_EQ(x.springDampingRatio, y.springDampingRatio) << after;
	EXPECT_EQ(x.maxFrictionTorque, y.maxFrictionTorque) << after;
	for (int i = 0; i < 6; ++i)
	{
		EXPECT_EQ(x.rowErp[i], y.rowErp[i]) << after;
		EXPECT_EQ(x.rowCfm[i], y.rowCfm[i]) << after;
	}
	EXPECT_EQ(x.stopErp, y.stopErp) << after;
	EXPECT_EQ(x.stopCfm, y.stopCfm) << after;
	EXPECT_EQ(x.flags, y.flags) << after;
}

struct Bodies
{
	btBoxShape shape{btVector3(1, 1, 1)};
	btRigidBody a{1, nullptr, &shape, btVector3(1, 1, 1)};
	btRigidBody b{1, nullptr, &shape, btVector3(1, 1, 1)};
};
}  // namespace

TEST(BadInput, ConstructorsRefuseBadArguments)
{
	// NaN/Inf pivots, zero and non-unit axes, non-rigid frames, the same body twice.
	Bodies s;
	const btVector3 z(0, 0, 1), o(0, 0, 0);
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.a, o, o, z, z); }, "rbB");
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.b, btVector3(kNaN, 0, 0), o, z, z); }, "pivotInA");
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.b, o, btVector3(0, kInf, 0), z, z); }, "pivotInB");
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.b, btVector3(btScalar(3e38), 0, 0), o, z, z); }, "pivotInA");
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.b, o, o, btVector3(0, 0, 0), z); }, "axisInA");
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.b, o, o, z, btVector3(0, kInf, 2)); }, "axisInB");
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, o, btVector3(kNaN, 0, 1)); }, "axisInA");
	btTransform sheared = btTransform::getIdentity();
	sheared.getBasis()[0][1] = btScalar(0.5);
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.b, sheared, btTransform::getIdentity()); }, "rbAFrame");
	btTransform mirrored = btTransform::getIdentity();
	mirrored.getBasis()[2][2] = -1;
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.b, btTransform::getIdentity(), mirrored); }, "rbBFrame");
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, sheared); }, "rbAFrame");
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.a, btTransform::getIdentity(), btTransform::getIdentity()); }, "rbB");
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, btVector3(0, kNaN, 0), z); }, "pivotInA");
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, o, btVector3(0, 0, 0)); }, "axisInA");
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, btTransform(btQuaternion::getIdentity(), btVector3(kInf, 0, 0))); }, "rbAFrame");
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.b, btTransform::getIdentity(), btTransform(btQuaternion::getIdentity(), btVector3(0, 0, kNaN))); }, "rbBFrame");
	// the settings constructor checks every field as the setters do
	btQuaternionHingeSettings settings;
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.a, settings); }, "rbB");
	settings.driveMode = btQuaternionHingeDriveMode(17);
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.b, settings); }, "driveMode");
	settings = btQuaternionHingeSettings();
	settings.frameInA = sheared;
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.b, settings); }, "frameInA");
	settings = btQuaternionHingeSettings();
	settings.hasLimit = true;
	settings.lowerLimit = kNaN;
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.b, settings); }, "low");
	settings = btQuaternionHingeSettings();
	settings.maxFrictionTorque = -1;
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.b, settings); }, "maxTorque");
	settings = btQuaternionHingeSettings();
	settings.driveMode = BT_QHINGE_DRIVE_SPRING;
	settings.springFrequency = 0;
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.b, settings); }, "frequencyHz");
	settings = btQuaternionHingeSettings();
	settings.flags = BT_QHINGE_FLAGS_ERP_ROW0 << 3;
	settings.rowErp[3] = kInf;
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.b, settings); }, "ERP");
	settings = btQuaternionHingeSettings();
	settings.driveMode = BT_QHINGE_DRIVE_VELOCITY;
	settings.maxMotorImpulse = -1;
	expectRefused([&] { btQuaternionHingeConstraint j(s.a, s.b, settings); }, "maxMotorImpulse");
}

TEST(BadInput, SettersRefuseBadArgumentsAndKeepTheJointUnchanged)
{
	// Every setter: the error names the parameter, and the settings after the refusal are the settings before it.
	Bodies s;
	btQuaternionHingeConstraint j(s.a, s.b, btTransform::getIdentity(), btTransform::getIdentity());
	j.setLimit(-1, 1);
	j.enableAngularMotor(true, 1, 2);
	j.setParam(BT_CONSTRAINT_CFM, btScalar(0.01), 4);
	const btQuaternionHingeSettings before = j.getSettings();
	// each refusal leaves every setting as it was
	auto expectRefused = [&](const std::function<void()>& call, const std::string& parameter) {
		::expectRefused(call, parameter);
		expectSameSettings(j.getSettings(), before, "after the refusal naming " + parameter);
	};
	expectRefused([&] { j.setLimit(kNaN, 1); }, "low");
	expectRefused([&] { j.setLimit(0, kNaN); }, "high");
	expectRefused([&] { j.setLimit(-1, 1, kNaN); }, "softness");
	expectRefused([&] { j.setLimit(-1, 1, btScalar(0.9), kInf); }, "biasFactor");
	expectRefused([&] { j.setLimit(-1, 1, btScalar(0.9), btScalar(0.3), -kInf); }, "relaxationFactor");
	expectRefused([&] { j.enableAngularMotor(true, kNaN, 1); }, "targetVelocity");
	expectRefused([&] { j.enableAngularMotor(true, 1, -1); }, "maxMotorImpulse");
	expectRefused([&] { j.setMaxMotorImpulse(-2); }, "maxMotorImpulse");
	expectRefused([&] { j.setMotorTargetVelocity(kInf); }, "motorTargetVelocity");
	expectRefused([&] { j.setMotorTarget(1, 0); }, "dt");
	expectRefused([&] { j.setMotorTarget(btQuaternion(0, 0, 0, 0), 1); }, "qAinB");
	expectRefused([&] { j.setServoTarget(1, 0); }, "maxSpeed");
	expectRefused([&] { j.setServoTarget(1, 1, -1); }, "maxTorque");
	expectRefused([&] { j.setSpring(0, 0, 1); }, "frequencyHz");
	expectRefused([&] { j.setSpring(0, 1, -1); }, "dampingRatio");
	expectRefused([&] { j.setMaxFrictionTorque(-1); }, "maxTorque");
	expectRefused([&] { j.setSpring(0, -1, 1); }, "frequencyHz");
	expectRefused([&] { j.setSpring(kNaN, 1, 1); }, "restAngle");
	expectRefused([&] { j.setServoTarget(kNaN); }, "targetAngle");
	expectRefused([&] { j.setMaxFrictionTorque(kNaN); }, "maxTorque");
	expectRefused([&] { j.setParam(BT_CONSTRAINT_ERP, kInf); }, "value");
	expectRefused([&] { j.setParam(BT_CONSTRAINT_ERP, kNaN, 3); }, "value");
	expectRefused([&] { j.setParam(BT_CONSTRAINT_STOP_ERP, -kInf); }, "value");
	expectRefused([&] { j.setParam(BT_CONSTRAINT_STOP_CFM, kNaN); }, "value");
	expectRefused([&] { j.setParam(BT_CONSTRAINT_CFM, kNaN, 0); }, "value");
	expectRefused([&] { j.setParam(BT_CONSTRAINT_ERP, btScalar(0.5), -2); }, "axis");
	expectRefused([&] { j.setParam(BT_CONSTRAINT_ERP, btScalar(2)); }, "ERP");
	expectRefused([&] { j.setParam(BT_CONSTRAINT_ERP, -btScalar(0.1), 3); }, "ERP");
	expectRefused([&] { j.setParam(BT_CONSTRAINT_CFM, 1); }, "CFM");
	expectRefused([&] { j.setParam(BT_CONSTRAINT_CFM, -btScalar(0.1)); }, "CFM");
	expectRefused([&] { j.setParam(BT_CONSTRAINT_STOP_CFM, 1); }, "STOP_CFM");
	expectRefused([&] { j.setParam(99, 0); }, "num");
	expectRefused([&] { j.setParam(BT_CONSTRAINT_ERP, btScalar(0.5), 6); }, "axis");
	expectRefused([&] { j.setParam(BT_CONSTRAINT_STOP_ERP, btScalar(0.5), 2); }, "axis");
	expectRefused([&] { j.setFrames(btTransform(btMatrix3x3(2, 0, 0, 0, 1, 0, 0, 0, 1)), btTransform::getIdentity()); }, "frameA");
	btVector3 zero(0, 0, 0);
	expectRefused([&] { j.setAxis(zero); }, "axisInA");
	expectRefused([&] { j.setMultiTurnAngle(kNaN); }, "angle");
	// magnitudes the solver cannot carry in float (found by the fuzzer): pivots beyond 1e6 m, angles beyond 1e6 rad,
	// springs above 1e6 Hz
	expectRefused([&] { j.setFrames(btTransform(btQuaternion::getIdentity(), btVector3(0, btScalar(2e6), 0)), btTransform::getIdentity()); }, "frameA");
	expectRefused([&] { j.setSpring(btScalar(1e26), 1, 1); }, "restAngle");
	expectRefused([&] { j.setSpring(0, btScalar(2e6), 1); }, "frequencyHz");
	expectRefused([&] { j.setServoTarget(btScalar(-3e6)); }, "targetAngle");
	expectRefused([&] { j.setLimit(btScalar(2e6), btScalar(3e6)); }, "low");
	expectRefused([&] { j.setLimit(btScalar(-3e6), btScalar(-2e6)); }, "high");
	expectSameSettings(j.getSettings(), before, "after all refusals");
	// and the joint still takes valid values
	j.setLimit(-2, 2);
	EXPECT_EQ(j.getUpperLimit(), 2);
}

namespace
{
// Two boxes hinged and stepped a little, then a user sets a NaN angular velocity on `a` and the world steps once.
btQuaternionHingeConstraint* hingeHitByNaNVelocity(qh_test::World& world, btRigidBody*& a, btRigidBody*& b)
{
	a = world.addBox(1, btVector3(1, 1, 1), btTransform::getIdentity());
	b = world.addBox(1, btVector3(1, 1, 1), btTransform(btQuaternion::getIdentity(), btVector3(0, -2, 0)));
	auto* joint = world.add(new btQuaternionHingeConstraint(*a, *b, btVector3(0, -1, 0), btVector3(0, 1, 0), btVector3(0, 0, 1), btVector3(0, 0, 1)));
	world.step(5);
	a->setAngularVelocity(btVector3(kNaN, 0, 0));
	world.step(1);
	return joint;
}
}  // namespace

TEST(BadInput, NaNVelocityFromOutsideDisablesTheJointInsteadOfSpreading)
{
	// A user sets a NaN velocity on one body: the joint reports no rows, disables itself, says why, and the body on
	// the other side stays finite.
	qh_test::World world;
	btRigidBody *a, *b;
	btQuaternionHingeConstraint* joint = hingeHitByNaNVelocity(world, a, b);
	EXPECT_EQ(joint->getFault(), BT_QHINGE_FAULT_NONFINITE_BODY_STATE);
	EXPECT_FALSE(joint->isEnabled());
	EXPECT_EQ(joint->getNumRowsLastStep(), 0);
	for (int i = 0; i < 10; ++i)
	{
		world.step(1);
		EXPECT_TRUE(qh_test::finiteState(*b)) << "step " << i;  // nothing NaN reached the other body
		EXPECT_EQ(joint->getNumRowsLastStep(), 0);
	}
	// repaired and cleared: the joint works again
	a->setAngularVelocity(btVector3(0, 0, 0));
	a->setLinearVelocity(btVector3(0, 0, 0));
	a->setCenterOfMassTransform(btTransform::getIdentity());
	joint->clearFault();
	world.step(1);
	EXPECT_EQ(joint->getFault(), BT_QHINGE_FAULT_NONE);
	EXPECT_EQ(joint->getNumRowsLastStep(), 5);
}

TEST(BadInput, AFaultStandsUntilClearFaultEvenIfTheJointIsReenabledByHand)
{
	// A joint that faulted and was re-enabled with setEnabled(true) instead of clearFault() gives the solver no rows
	// while its fault stands (the stabilizer skips such a joint too: both must agree); clearFault() brings it back.
	qh_test::World world;
	btRigidBody *a, *b;
	btQuaternionHingeConstraint* joint = hingeHitByNaNVelocity(world, a, b);
	ASSERT_EQ(joint->getFault(), BT_QHINGE_FAULT_NONFINITE_BODY_STATE);
	a->setAngularVelocity(btVector3(0, 0, 0));  // repaired, but the fault is not cleared
	a->setLinearVelocity(btVector3(0, 0, 0));
	a->setCenterOfMassTransform(btTransform::getIdentity());
	b->setCenterOfMassTransform(btTransform(btQuaternion::getIdentity(), btVector3(0, -2, 0)));
	b->setLinearVelocity(btVector3(0, 0, 0));
	b->setAngularVelocity(btVector3(0, 0, 0));
	joint->setEnabled(true);
	world.step(1);
	EXPECT_EQ(joint->getFault(), BT_QHINGE_FAULT_NONFINITE_BODY_STATE);
	EXPECT_EQ(joint->getNumRowsLastStep(), 0);
	EXPECT_FALSE(joint->isEnabled());  // disabled again by the standing fault
	joint->setEnabled(true);
	btTypedConstraint::btConstraintInfo1 info;
	joint->getInfo1(&info);
	EXPECT_EQ(info.m_numConstraintRows, 0);
	joint->clearFault();
	world.step(1);
	EXPECT_EQ(joint->getFault(), BT_QHINGE_FAULT_NONE);
	EXPECT_EQ(joint->getNumRowsLastStep(), 5);
}

TEST(BadInput, AbsurdBodyStateDisablesTheJoint)
{
	// A body at 2e38 m or with a non-finite inverse inertia (a 1e-38 kg body) is state the rows cannot carry: no rows,
	// the joint disables itself and says why (cases found by the fuzzer).
	Bodies s;
	s.b.setWorldTransform(btTransform(btQuaternion::getIdentity(), btVector3(btScalar(2e38), 0, 0)));
	btQuaternionHingeConstraint far(s.a, s.b, btTransform::getIdentity(), btTransform::getIdentity());
	btTypedConstraint::btConstraintInfo1 info;
	far.getInfo1(&info);
	EXPECT_EQ(info.m_numConstraintRows, 0);
	EXPECT_EQ(far.getFault(), BT_QHINGE_FAULT_NONFINITE_BODY_STATE);
	btBoxShape shape(btVector3(1, 1, 1));
	btVector3 tiny;
	shape.calculateLocalInertia(btScalar(1e-38), tiny);
	btRigidBody feather(btScalar(1e-38), nullptr, &shape, tiny);
	btQuaternionHingeConstraint light(s.a, feather, btTransform::getIdentity(), btTransform::getIdentity());
	light.getInfo1(&info);
	EXPECT_EQ(info.m_numConstraintRows, 0);
	EXPECT_FALSE(light.isEnabled());
}

TEST(BadInput, FrameEditedThroughAReferenceIsCheckedBeforeTheSolve)
{
	// getFrameOffsetA() hands out a non-const reference (as stock); a non-rigid edit disables the joint at the next
	// solve instead of feeding the solver a sheared frame.
	Bodies s;
	btQuaternionHingeConstraint j(s.a, s.b, btTransform::getIdentity(), btTransform::getIdentity());
	j.getFrameOffsetA().getBasis()[0][0] = 3;
	btTypedConstraint::btConstraintInfo1 info;
	j.getInfo1(&info);
	EXPECT_EQ(info.m_numConstraintRows, 0);
	EXPECT_EQ(j.getFault(), BT_QHINGE_FAULT_FRAME_EDITED_INVALID);
	EXPECT_FALSE(j.isEnabled());
}

TEST(BadInput, RefusedConstructorYieldsASafeJoint)
{
	// With exceptions the constructor throws (no object); without, the object exists, is disabled, reports no rows
	// and says why — and clearFault() does not bring it back.
	Bodies s;
	const btVector3 z(0, 0, 1), o(0, 0, 0);
	if (qh_test::kExceptions)
	{
		EXPECT_REFUSED(btQuaternionHingeConstraint j(s.a, s.b, o, o, btVector3(0, 0, 0), z), "axisInA");
		return;
	}
	qh_test::ErrorCapture errors;
	btQuaternionHingeConstraint j(s.a, s.b, o, o, btVector3(0, 0, 0), z);
	EXPECT_EQ(errors.count, 1);
	EXPECT_NE(errors.first.find("axisInA"), std::string::npos) << errors.first;
	EXPECT_EQ(j.getFault(), BT_QHINGE_FAULT_INVALID_ARGUMENT);
	EXPECT_FALSE(j.isEnabled());
	j.clearFault();
	j.setEnabled(true);
	btTypedConstraint::btConstraintInfo1 info;
	j.getInfo1(&info);
	EXPECT_EQ(info.m_numConstraintRows, 0);
	EXPECT_EQ(j.getFault(), BT_QHINGE_FAULT_INVALID_ARGUMENT);
	// a refused setter in a settings struct refuses the whole construction
	btQuaternionHingeSettings settings;
	settings.maxFrictionTorque = -1;
	btQuaternionHingeConstraint k(s.a, s.b, settings);
	EXPECT_EQ(errors.count, 2);
	EXPECT_EQ(k.getFault(), BT_QHINGE_FAULT_INVALID_ARGUMENT);
	EXPECT_EQ(k.getSettings().maxFrictionTorque, 0);
}

TEST(BadInput, DefaultErrorCallbackAndItsReplacement)
{
	// The callback is settable and readable; null restores the default (one line through printf).
	void* user = nullptr;
	EXPECT_EQ(btQuaternionHingeGetErrorCallback(&user), btQuaternionHingeDefaultErrorCallback);
	int calls = 0;
	btQuaternionHingeSetErrorCallback([](const char*, void* u) { ++*static_cast<int*>(u); }, &calls);
	EXPECT_NE(btQuaternionHingeGetErrorCallback(&user), btQuaternionHingeDefaultErrorCallback);
	EXPECT_EQ(user, &calls);
	btQuaternionHingeSetErrorCallback(nullptr, nullptr);
	EXPECT_EQ(btQuaternionHingeGetErrorCallback(&user), btQuaternionHingeDefaultErrorCallback);
	EXPECT_EQ(user, nullptr);
	testing::internal::CaptureStdout();
	btQuaternionHingeDefaultErrorCallback("a message", nullptr);
	EXPECT_EQ(testing::internal::GetCapturedStdout(), "QuatHinge: a message\n");
}
