// Real callers as tests (issue 17, item 6), part 1: Bullet's own examples and extras (bulletphysics/bullet3). Each test
// replays one caller's calls, with its values, on btHingeConstraint and on btQuaternionHingeConstraint in identical
// scenes (support/CallerReplay.h: nothing refused, nothing thrown) and compares what the caller reads back and how the
// scene moves. Unless a test says otherwise: 60 Hz, 10 solver iterations, sequential impulse, and the same motion means
// getHingeAngle() within kAngleTol at every step.
#include "support/CallerReplay.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

using qh_test::CallerRun;
using qh_test::HingeOf;
using qh_test::record;
using qh_test::replayOnBoth;

namespace
{
const double kAngleTol = qh_test::kSameMotionTol;  // rad
const btScalar kPi = SIMD_PI;
}  // namespace

TEST(CallerPatterns, BulletMotorOnTheWorldDrivesAgainstGravity)
{
	// bulletphysics/bullet3 examples/Constraints/ConstraintDemo.cpp, "Hinge connected to the world, with motor":
	// btHingeConstraint(body, pivotA (10, 0, 0), axisA (0, 0, 1)); enableAngularMotor(true, -1.0f, 1.65f) ("use for the
	// new SIMD solver"), under gravity −10 m/s² along −y with the 1 kg cube 10 m from its pivot. Reads: the motor's state.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w;
		btRigidBody* body = w.addBox(1, btVector3(1, 1, 1), btTransform::getIdentity());
		Hinge* hinge = w.add(new Hinge(*body, btVector3(10, 0, 0), btVector3(0, 0, 1)), false);
		hinge->enableAngularMotor(true, btScalar(-1.0), btScalar(1.65));
		run.reads = {double(hinge->getEnableAngularMotor()), hinge->getMotorTargetVelocity(), hinge->getMaxMotorImpulse()};
		record(run, w, *hinge, 180);
		return run;
	});
	qh_test::expectSameRun("ConstraintDemo motor", r.stock, r.quat, kAngleTol);
}

TEST(CallerPatterns, BulletGearHingeInReferenceFrameAOnATiltedBody)
{
	// bulletphysics/bullet3 examples/Constraints/ConstraintDemo.cpp, the gear section: a body turned by −THETA (π/4)
	// about z, setLinearFactor(0, 0, 0), btHingeConstraint(*body, btVector3(0, 0, 0), btVector3(0, 1, 0), true) (pivot
	// at the centre of mass, useReferenceFrameA), setAngularVelocity((0, 3, 0)) in world — partly off the hinge axis,
	// which the joint takes out. 6.28 kg as in the demo.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w;
		const btTransform start(btQuaternion(btVector3(0, 0, 1), -kPi / 4), btVector3(-10, 2, -8));
		btRigidBody* body = w.addBox(btScalar(6.28), btVector3(btScalar(0.2), btScalar(0.26), btScalar(0.2)), start);
		body->setLinearFactor(btVector3(0, 0, 0));
		Hinge* hinge = w.add(new Hinge(*body, btVector3(0, 0, 0), btVector3(0, 1, 0), true), false);
		body->setAngularVelocity(btVector3(0, 3, 0));
		run.reads = {double(hinge->getUseReferenceFrameA()), hinge->getHingeAngle()};
		record(run, w, *hinge, 120);
		run.reads.push_back(body->getAngularVelocity().dot(quatRotate(start.getRotation(), btVector3(0, 1, 0))));
		return run;
	});
	// the spin left about the tilted axis: 3 cos(π/4) rad/s; compared within 1e-3 rad/s
	qh_test::expectSameRun("ConstraintDemo gear", r.stock, r.quat, kAngleTol, 1e-3);
	EXPECT_NEAR(r.quat.reads.back(), 3 * std::cos(M_PI / 4), 1e-3);
}

TEST(CallerPatterns, BulletTwoDynamicBodiesLimitedAboutTheVertical)
{
	// bulletphysics/bullet3 examples/Constraints/ConstraintDemo.cpp, "create a Hinge joint between two dynamic bodies":
	// bodies of 1 kg at (−20, −2, 0) and 10 kg at (−30, −2, 0), btHingeConstraint(A, B, pivotA (−5, 0, 0), pivotB
	// (5, 0, 0), axisA = axisB = (0, 1, 0)), setLimit(-SIMD_HALF_PI * 0.5f, SIMD_HALF_PI * 0.5f), both falling. A is
	// spun at 3 rad/s about the axis so that the pair hits a stop.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w;
		btRigidBody* a = w.addBox(1, btVector3(1, 1, 1), btTransform(btQuaternion::getIdentity(), btVector3(-20, -2, 0)));
		btRigidBody* b = w.addBox(10, btVector3(1, 1, 1), btTransform(btQuaternion::getIdentity(), btVector3(-30, -2, 0)));
		Hinge* hinge = w.add(new Hinge(*a, *b, btVector3(-5, 0, 0), btVector3(5, 0, 0), btVector3(0, 1, 0), btVector3(0, 1, 0)));
		hinge->setLimit(-SIMD_HALF_PI * btScalar(0.5), SIMD_HALF_PI * btScalar(0.5));
		run.reads = {hinge->getLowerLimit(), hinge->getUpperLimit()};
		a->setAngularVelocity(btVector3(0, 3, 0));
		record(run, w, *hinge, 120);
		return run;
	});
	qh_test::expectSameRun("ConstraintDemo dynamic pair", r.stock, r.quat, kAngleTol);
	for (double a : r.quat.angles) EXPECT_LE(std::fabs(a), 0.25 * M_PI + 0.02);
}

TEST(CallerPatterns, BulletMotorDemoLegFollowsATargetBetweenItsLimits)
{
	// bulletphysics/bullet3 examples/DynamicControlDemo/MotorDemo.cpp: TestRig's hip (frames, localA basis
	// setEulerZYX(0, -fAngle, 0), localB from the bodies' poses, setLimit(-0.75 * M_PI_4, M_PI_8)) and, every internal
	// tick, MotorDemo::setMotorTargets: fCurAngle = getHingeAngle(), target = getLowerLimit() + s · (getUpperLimit() −
	// getLowerLimit()) with s = ½(1 + sin 2π t/T), T = 2000 ms, enableAngularMotor(true, (target − fCurAngle)/dt,
	// m_fMuscleStrength = 0.5). The body is static here (bFixed), the leg a 1 kg box of half extents 0.1, 0.225, 0.1 m.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w;
		btRigidBody* torso = w.addBox(0, btVector3(btScalar(0.25), btScalar(0.1), btScalar(0.25)), btTransform::getIdentity());
		torso->setCollisionFlags(torso->getCollisionFlags() | btCollisionObject::CF_NO_CONTACT_RESPONSE);
		const btScalar size = btScalar(0.25), leg = btScalar(0.45);
		btTransform legPose(btQuaternion(btVector3(0, 0, 1), kPi / 2), btVector3(size + leg / 2, 0, 0));
		btRigidBody* thigh = w.addBox(1, btVector3(btScalar(0.1), leg / 2, btScalar(0.1)), legPose);
		btTransform localA;
		localA.setIdentity();
		localA.getBasis().setEulerZYX(0, 0, 0);  // -fAngle, with fAngle = 0 for the first leg
		localA.setOrigin(btVector3(size, 0, 0));
		const btTransform localB = thigh->getWorldTransform().inverse() * torso->getWorldTransform() * localA;
		Hinge* hinge = w.add(new Hinge(*torso, *thigh, localA, localB));
		hinge->setLimit(btScalar(-0.75 * M_PI_4), btScalar(M_PI / 8));
		float timeUs = 0;  // m_Time, in microseconds as the demo keeps it
		record(run, w, *hinge, 180, [&](int) {
			const float us = 1000000.f / 60.f;
			timeUs += us;
			const btScalar cur = hinge->getHingeAngle();
			const btScalar percent = btScalar((int(timeUs / 1000) % 2000) / 2000.0);
			const btScalar s = btScalar(0.5 * (1 + std::sin(2 * M_PI * percent)));
			const btScalar target = hinge->getLowerLimit() + s * (hinge->getUpperLimit() - hinge->getLowerLimit());
			hinge->enableAngularMotor(true, btScalar(1000000.f * (target - cur) / us), btScalar(0.5));
			run.reads.push_back(hinge->getLowerLimit());
			run.reads.push_back(hinge->getUpperLimit());
		});
		return run;
	});
	// stock recomputes its ends from centre and half range (wrapped getters): the same to float round-off, 1e-6 rad
	qh_test::expectSameRun("MotorDemo hip", r.stock, r.quat, kAngleTol, 1e-6);
	for (double a : r.quat.angles) EXPECT_TRUE(a >= -0.75 * M_PI_4 - 0.02 && a <= M_PI / 8 + 0.02) << a;
}

TEST(CallerPatterns, BulletForkLiftLocksTheLiftWhereTheKeyWasReleased)
{
	// bulletphysics/bullet3 examples/ForkLift/ForkLiftDemo.cpp: the lift (10 kg box 0.5 × 2 × 0.05 at (0, 2.5, 3.05))
	// on the chassis by frames localA/localB with basis setEulerZYX(0, M_PI_2, 0) and origins (0, 1, 3.05) and
	// (0, −1.5, −0.05), then setLimit(0.0f, 0.0f) (locked). Shift+arrow key down: setLimit(-M_PI / 16.0f, M_PI / 8.0f)
	// and enableAngularMotor(true, 0.1, maxMotorImpulse = 4000). Key up, lockLiftHinge(): hingeAngle = getHingeAngle(),
	// lowLim = getLowerLimit(), hiLim = getUpperLimit(), enableAngularMotor(false, 0, 0), setLimit(hingeAngle,
	// hingeAngle) (or the end it passed). The chassis is static here.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w;
		btRigidBody* chassis = w.addBox(0, btVector3(1, btScalar(0.5), 2), btTransform::getIdentity());
		btRigidBody* lift = w.addBox(10, btVector3(btScalar(0.5), 2, btScalar(0.05)), btTransform(btQuaternion::getIdentity(), btVector3(0, btScalar(2.5), btScalar(3.05))));
		btTransform localA, localB;
		localA.setIdentity();
		localB.setIdentity();
		localA.getBasis().setEulerZYX(0, btScalar(M_PI_2), 0);
		localA.setOrigin(btVector3(0, 1, btScalar(3.05)));
		localB.getBasis().setEulerZYX(0, btScalar(M_PI_2), 0);
		localB.setOrigin(btVector3(0, btScalar(-1.5), btScalar(-0.05)));
		Hinge* hinge = w.add(new Hinge(*chassis, *lift, localA, localB));
		hinge->setLimit(0, 0);
		record(run, w, *hinge, 30);  // parked
		hinge->setLimit(btScalar(-M_PI / 16), btScalar(M_PI / 8));
		hinge->enableAngularMotor(true, btScalar(0.1), btScalar(4000));
		record(run, w, *hinge, 60);  // key held for 1 s
		const btScalar hingeAngle = hinge->getHingeAngle();
		const btScalar lowLim = hinge->getLowerLimit(), hiLim = hinge->getUpperLimit();
		hinge->enableAngularMotor(false, 0, 0);
		const btScalar lock = hingeAngle < lowLim ? lowLim : hingeAngle > hiLim ? hiLim
																				: hingeAngle;
		hinge->setLimit(lock, lock);
		run.reads = {lowLim, hiLim, hinge->getLowerLimit(), hinge->getUpperLimit(), double(hinge->getEnableAngularMotor())};
		record(run, w, *hinge, 60);  // locked where released
		run.reads.push_back(hingeAngle);
		return run;
	});
	// Within 0.005 rad: stock's lock (setLimit(0, 0), then setLimit(a, a)) lets the 10 kg lift sag by up to 0.0041 rad
	// (0.0023 rad after the release) before its limit bias brings it back over a second; the quaternion hinge's lock
	// holds the angle to 1e-4 rad (its limit row is a stop on both sides at once). The reads follow the angle.
	qh_test::expectSameRun("ForkLift lift", r.stock, r.quat, 0.005, 0.005);
	EXPECT_NEAR(std::fabs(r.quat.reads.back()), 0.1, 0.01);        // 0.1 rad/s for 1 s
	EXPECT_NEAR(r.quat.angles.back(), r.quat.reads.back(), 1e-4);  // held at the lock
	EXPECT_NEAR(r.quat.angles[29], 0, 1e-4);                       // and parked at 0
}

TEST(CallerPatterns, BulletRagdollKneeSwingsWithinZeroToAQuarterTurn)
{
	// bulletphysics/bullet3 examples/Benchmarks/BenchmarkDemo.cpp, RagDoll (the "Ragdolls" benchmark), the knee:
	// localA/localB basis setEulerZYX(0, M_PI_2, 0), origins (0, −0.225, 0) in the thigh and (0, 0.185, 0) in the shin,
	// btHingeConstraint(thigh, shin, localA, localB), setLimit(btScalar(0), btScalar(M_PI_2)): the straight leg sits on
	// its lower stop. The thigh is held static and the shin kicked both ways (±4 rad/s about the knee axis).
	for (const double kick : {4.0, -4.0})
	{
		auto r = replayOnBoth([kick](auto* tag) {
			using Hinge = HingeOf<decltype(tag)>;
			CallerRun run;
			qh_test::World w;
			btRigidBody* thigh = w.addBox(0, btVector3(btScalar(0.07), btScalar(0.225), btScalar(0.07)), btTransform(btQuaternion::getIdentity(), btVector3(0, 1, 0)));
			btRigidBody* shin = w.addBox(1, btVector3(btScalar(0.05), btScalar(0.185), btScalar(0.05)), btTransform(btQuaternion::getIdentity(), btVector3(0, btScalar(1 - 0.225 - 0.185), 0)));
			btTransform localA, localB;
			localA.setIdentity();
			localB.setIdentity();
			localA.getBasis().setEulerZYX(0, btScalar(M_PI_2), 0);
			localA.setOrigin(btVector3(0, btScalar(-0.225), 0));
			localB.getBasis().setEulerZYX(0, btScalar(M_PI_2), 0);
			localB.setOrigin(btVector3(0, btScalar(0.185), 0));
			Hinge* hinge = w.add(new Hinge(*thigh, *shin, localA, localB));
			hinge->setLimit(btScalar(0), btScalar(M_PI_2));
			run.reads = {hinge->getLowerLimit(), hinge->getUpperLimit()};
			shin->setAngularVelocity(btVector3(btScalar(kick), 0, 0));
			record(run, w, *hinge, 120);
			return run;
		});
		// Deliberately different near the stop (README, "limit softness"): stock's limit row comes on only once the
		// shin is past the stop (kicked into it at 1.05 rad/s, it is 0.0176 rad through before stopping), the
		// quaternion hinge's within (1 − softness) · half range of it, so it never passes and rebounds with
		// restitution bias · relaxation (0.3) from the step of impact. Asserted instead: the quaternion hinge stays
		// within [0, π/2] to 1e-3 rad, and both settle on the stop, within 0.01 rad after 2 s.
		const double settledTol = 0.01;
		CallerRun stock = r.stock, quat = r.quat;
		stock.angles.erase(stock.angles.begin(), stock.angles.end() - 1);
		quat.angles.erase(quat.angles.begin(), quat.angles.end() - 1);
		qh_test::expectSameRun(kick > 0 ? "BenchmarkDemo knee settled, kicked +" : "BenchmarkDemo knee settled, kicked -",
							   stock, quat, settledTol, 1e-6);
		for (double a : r.quat.angles) EXPECT_TRUE(a >= -1e-3 && a <= M_PI_2 + 1e-3) << a;
		if (kick > 0)  // into the stop: stock passes it
		{
			EXPECT_LT(*std::min_element(r.stock.angles.begin(), r.stock.angles.end()), -0.01);
		}
	}
}

TEST(CallerPatterns, BulletSoftDemoGearTurnsAtItsMotorSpeed)
{
	// bulletphysics/bullet3 examples/SoftDemo/SoftDemo.cpp, Ctor_Gear: a 10 kg body, btHingeConstraint(*body,
	// btTransform::getIdentity()) (the one-body frame form: axis z through the centre of mass), then
	// enableAngularMotor(true, speed, 3) when speed != 0; here speed 1 rad/s, under gravity.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w;
		btRigidBody* gear = w.addBox(10, btVector3(5, 1, 6), btTransform(btQuaternion::getIdentity(), btVector3(0, 5, 0)));
		Hinge* hinge = w.add(new Hinge(*gear, btTransform::getIdentity()), false);
		hinge->enableAngularMotor(true, 1, 3);
		record(run, w, *hinge, 120);
		run.reads = {gear->getAngularVelocity().z()};
		return run;
	});
	qh_test::expectSameRun("SoftDemo gear", r.stock, r.quat, kAngleTol, 1e-3);  // spin within 1e-3 rad/s
	EXPECT_NEAR(r.quat.reads[0], 1, 1e-3);
}

TEST(CallerPatterns, BulletTestHingeTorqueReadsJointFeedback)
{
	// bulletphysics/bullet3 examples/Constraints/TestHingeTorque.cpp, initPhysics/stepSimulation: gravity (0, 0, −10),
	// getSolverInfo().m_splitImpulse = false, a static base box (0.05, 0.37, 0.1) and a 1 kg link below it,
	// btHingeConstraint(base, link, pivotInA (0, −0.37, 0), pivotInB (0, 0.37, 0), axisInA = axisInB = (1, 0, 0),
	// useReferenceA = true), setJointFeedback(new btJointFeedback) without enableFeedback, addConstraint(con, true),
	// stepSimulation(1. / 240, 0) and m_appliedForceBodyB / m_appliedTorqueBodyB printed. The link swings about x.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w(qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, -10));
		w.world().getSolverInfo().m_splitImpulse = false;
		const btVector3 half(btScalar(0.05), btScalar(0.37), btScalar(0.1));
		btRigidBody* base = w.addBox(0, half, btTransform(btQuaternion::getIdentity(), btVector3(btScalar(-0.4), 3, 0)));
		btRigidBody* link = w.addBox(1, half, btTransform(btQuaternion::getIdentity(), btVector3(btScalar(-0.4), btScalar(3 - 0.74), 0)));
		Hinge* hinge = w.add(new Hinge(*base, *link, btVector3(0, btScalar(-0.37), 0), btVector3(0, btScalar(0.37), 0), btVector3(1, 0, 0), btVector3(1, 0, 0), true));
		btJointFeedback feedback;
		hinge->setJointFeedback(&feedback);
		link->setAngularVelocity(btVector3(2, 0, 0));  // a swing, so that the feedback carries more than the weight
		record(run, w, *hinge, 240, {}, btScalar(1) / 240);
		run.reads = {feedback.m_appliedForceBodyB.x(), feedback.m_appliedForceBodyB.y(), feedback.m_appliedForceBodyB.z()};
		return run;
	});
	// the force on the link (N) within 0.05 N: the same point rows carry it in both classes
	qh_test::expectSameRun("TestHingeTorque", r.stock, r.quat, kAngleTol, 0.05);
}

TEST(CallerPatterns, BulletWorldImporterRestoresASavedHinge)
{
	// bulletphysics/bullet3 Extras/Serialize/BulletWorldImporter/btWorldImporter.cpp, convertConstraintFloat /
	// convertConstraintDouble, case HINGE_CONSTRAINT_TYPE, then the common tail: createHingeConstraint(*rbA, *rbB,
	// rbAFrame, rbBFrame, m_useReferenceFrameA != 0); if (m_enableAngularMotor) enableAngularMotor(true,
	// m_motorTargetVelocity, m_maxMotorImpulse); setAngularOnly(m_angularOnly != 0); setLimit(m_lowerLimit,
	// m_upperLimit, m_limitSoftness, m_biasFactor, m_relaxationFactor); setDbgDrawSize; setBreakingImpulseThreshold;
	// setEnabled(m_isEnabled != 0); setOverrideNumSolverIterations; addConstraint(constraint,
	// m_disableCollisionsBetweenLinkedBodies != 0). The values are what btHingeConstraint::serialize writes for a
	// motorized hinge that was never limited (read off a stock hinge through the getters serialize uses).
	btBoxShape shape(btVector3(1, 1, 1));
	btRigidBody ra(0, nullptr, &shape), rb(1, nullptr, &shape, btVector3(1, 1, 1));
	btHingeConstraint saved(ra, rb, btTransform::getIdentity(), btTransform::getIdentity());
	saved.enableAngularMotor(true, 2, 5);
	auto r = replayOnBoth([&saved](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w;
		btRigidBody* a = w.addBox(0, btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)), btTransform::getIdentity());
		btRigidBody* b = w.addBox(1, btVector3(btScalar(0.5), btScalar(0.05), btScalar(0.05)), btTransform::getIdentity());
		Hinge* hinge = new Hinge(*a, *b, saved.getAFrame(), saved.getBFrame(), saved.getUseReferenceFrameA());
		if (saved.getEnableAngularMotor())
			hinge->enableAngularMotor(true, saved.getMotorTargetVelocity(), saved.getMaxMotorImpulse());
		hinge->setAngularOnly(saved.getAngularOnly());
		hinge->setLimit(saved.getLowerLimit(), saved.getUpperLimit(), saved.getLimitSoftness(), saved.getLimitBiasFactor(),
						saved.getLimitRelaxationFactor());
		hinge->setDbgDrawSize(saved.getDbgDrawSize());
		hinge->setBreakingImpulseThreshold(saved.getBreakingImpulseThreshold());
		hinge->setEnabled(saved.isEnabled());
		hinge->setOverrideNumSolverIterations(saved.getOverrideNumSolverIterations());
		w.add(hinge, true);
		run.reads = {hinge->getLowerLimit(), hinge->getUpperLimit(), double(hinge->hasLimit()), hinge->getLimitSoftness(),
					 hinge->getLimitBiasFactor(), hinge->getLimitRelaxationFactor(), double(hinge->getEnableAngularMotor()),
					 hinge->getMotorTargetVelocity(), hinge->getMaxMotorImpulse(), double(hinge->getAngularOnly()),
					 hinge->getBreakingImpulseThreshold(), double(hinge->getOverrideNumSolverIterations())};
		record(run, w, *hinge, 120);
		return run;
	});
	qh_test::expectSameRun("btWorldImporter hinge", r.stock, r.quat, kAngleTol);
	EXPECT_EQ(r.quat.reads[0], 1);  // the never-limited hinge's 1 and −1 come back as a free joint
	EXPECT_EQ(r.quat.reads[1], -1);
}

TEST(CallerPatterns, BulletDoorOnTheWorldHangsOnItsFarPivotAsStock)
{
	// This door's pivot is 12.3 m from its centre of mass (12.1 m out, 2 m along the axis), gravity along the axis.
	// Hanging at rest its pivot sagged 0.0155 m at 10 iterations where stock's holds (0): the axial point row's long
	// lever coupled it to the quaternion rows. Stock drops that lever for a joint to a static body; the quaternion
	// hinge now takes it off exactly (fillBilateralRows) and holds the pivot as stock. Pushed into its stop at 2 rad/s
	// the pivots parted 1.84 m against stock's 0.215 m at 10 iterations: the stop row halted the door's turn and left
	// its 24 m/s to the point rows through the 12.1 m lever. Stock also drops the tangential row's lever at a stop; the
	// quaternion hinge takes it off by a row operation with the stop row while the stop binds (measured 0.266 m).
	// bulletphysics/bullet3 examples/Constraints/ConstraintDemo.cpp, initPhysics, "create a door using hinge constraint
	// attached to the world": a door (box 2 × 5 × 0.2 half extents, 1 kg, DISABLE_DEACTIVATION) at (−5, −2, 0),
	// btHingeConstraint(*pDoorBody, btPivotA (10.f + 2.1f, −2, 0) "right next to the door slightly outside",
	// btAxisA (0, 1, 0)) (the one-body pivot/axis form), setLimit(-SIMD_PI * 0.25f, SIMD_PI * 0.25f),
	// setDbgDrawSize(5); gravity −10 m/s² along the axis. The door hangs for 1 s, then is pushed open at 2 rad/s
	// about the hinge (the demo's user drags it) and runs into the stop at π/4.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w;
		btRigidBody* door = w.addBox(1, btVector3(2, 5, btScalar(0.2)), btTransform(btQuaternion::getIdentity(), btVector3(-5, -2, 0)));
		const btVector3 pivot(btScalar(12.1), -2, 0);
		Hinge* hinge = w.add(new Hinge(*door, pivot, btVector3(0, 1, 0)), false);
		hinge->setLimit(-kPi * btScalar(0.25), kPi * btScalar(0.25));
		hinge->setDbgDrawSize(btScalar(5));
		run.reads = {hinge->getLowerLimit(), hinge->getUpperLimit(), hinge->getDbgDrawSize(), double(hinge->hasLimit())};
		record(run, w, *hinge, 60);
		run.extra.push_back(run.maxSeparation);  // hanging
		const btVector3 spin(0, 2, 0);
		door->setAngularVelocity(spin);
		door->setLinearVelocity(spin.cross(-(door->getCenterOfMassTransform().getBasis() * pivot)));
		record(run, w, *hinge, 120);
		run.extra.push_back(run.maxSeparation);  // through the stop
		return run;
	});
	std::printf(
		"[ figures  ] ConstraintDemo door, pivots apart at most: hanging stock %.3g m, quaternion %.3g m; at the "
		"stop stock %.3g m, quaternion %.3g m\n",
		r.stock.extra[0], r.quat.extra[0], r.stock.extra[1], r.quat.extra[1]);
	// Stock's behaviour while hanging: the pivot held to 1e-3 m, the angle (0) the same to 0.01 rad.
	CallerRun stockHanging = r.stock, quatHanging = r.quat;
	stockHanging.angles.resize(60);
	quatHanging.angles.resize(60);
	stockHanging.maxSeparation = r.stock.extra[0];
	quatHanging.maxSeparation = r.quat.extra[0];
	qh_test::expectSameRun("ConstraintDemo door, hanging", stockHanging, quatHanging, kAngleTol);
	EXPECT_LE(r.stock.extra[0], 1e-3);
	EXPECT_LE(r.quat.extra[0], 1e-3);
	// Through the stop: the pivots part at most 1.5 × stock's (m; measured 1.24 ×, 1.84 m = 8.6 × before).
	EXPECT_LE(r.quat.extra[1], 1.5 * r.stock.extra[1]);
}
