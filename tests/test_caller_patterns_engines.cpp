// Real callers as tests (issue 17, item 6), part 2: game engines' and simulators' Bullet back-ends — Godot 3's Bullet
// module, Panda3D, Urho3D, jMonkeyEngine's native Bullet, Gazebo classic, Samsung's SXR SDK. Each test replays one
// caller's calls, with its values, on btHingeConstraint and on btQuaternionHingeConstraint in identical scenes
// (support/CallerReplay.h: nothing refused, nothing thrown) and compares what the caller reads back and how the scene
// moves. Unless a test says otherwise: 60 Hz, 10 solver iterations, sequential impulse, and the same motion means
// getHingeAngle() within kAngleTol at every step.
#include "support/CallerReplay.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <type_traits>

using qh_test::CallerRun;
using qh_test::HingeOf;
using qh_test::record;
using qh_test::replayOnBoth;

namespace
{
const double kAngleTol = qh_test::kSameMotionTol;  // rad
// Limit ends read back: stock recomputes them from centre and half range (its getters wrap), the quaternion hinge
// returns them as given; the same to float round-off (rad).
const double kEndTol = 1e-6;
const double kPi = 3.14159265358979323846;

template <class Hinge>
constexpr bool isQuat()
{
	return std::is_same<Hinge, btQuaternionHingeConstraint>::value;
}

// A wheel: a 1 kg bar (1 × 0.1 × 0.1 m) on a static base, both at the origin, no contacts; gravity off unless given.
struct WheelScene
{
	btRigidBody* base;
	btRigidBody* wheel;
};
WheelScene wheelScene(qh_test::World& w)
{
	WheelScene s;
	s.base = w.addBox(0, btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)), btTransform::getIdentity());
	s.wheel = w.addBox(1, btVector3(btScalar(0.5), btScalar(0.05), btScalar(0.05)), btTransform::getIdentity());
	for (btRigidBody* b : {s.base, s.wheel}) b->setCollisionFlags(b->getCollisionFlags() | btCollisionObject::CF_NO_CONTACT_RESPONSE);
	return s;
}
void spin(btRigidBody* wheel, btScalar rate) { wheel->setAngularVelocity(btVector3(0, 0, rate)); }

// Godot 3 modules/bullet/hinge_joint_bullet.cpp, HingeJointBullet::set_param: every limit parameter is set by calling
// setLimit with the other four read back from the joint.
template <class Hinge>
void godotSetParam(Hinge& h, int param, btScalar v)
{
	enum
	{
		UPPER = 1,
		LOWER,
		BIAS,
		SOFTNESS,
		RELAXATION,
		TARGET_VELOCITY,
		MAX_IMPULSE
	};
	switch (param)
	{
		case UPPER: h.setLimit(h.getLowerLimit(), v, h.getLimitSoftness(), h.getLimitBiasFactor(), h.getLimitRelaxationFactor()); break;
		case LOWER: h.setLimit(v, h.getUpperLimit(), h.getLimitSoftness(), h.getLimitBiasFactor(), h.getLimitRelaxationFactor()); break;
		case BIAS: h.setLimit(h.getLowerLimit(), h.getUpperLimit(), h.getLimitSoftness(), v, h.getLimitRelaxationFactor()); break;
		case SOFTNESS: h.setLimit(h.getLowerLimit(), h.getUpperLimit(), v, h.getLimitBiasFactor(), h.getLimitRelaxationFactor()); break;
		case RELAXATION: h.setLimit(h.getLowerLimit(), h.getUpperLimit(), h.getLimitSoftness(), h.getLimitBiasFactor(), v); break;
		case TARGET_VELOCITY: h.setMotorTargetVelocity(v); break;
		case MAX_IMPULSE: h.setMaxMotorImpulse(v); break;
		default: break;  // PARAM_BIAS: "deprecated", no call
	}
}
// Godot 3 scene/3d/physics_joint.cpp, HingeJoint::_configure_joint: joint_create_hinge (the frames constructor), then
// set_param for every parameter with the node's defaults (bias 0.3, upper π/2, lower −π/2, limit bias 0.3, softness
// 0.9, relaxation 1, motor velocity 1, max impulse 1), then the flags: angular_limit/enable (default false:
// setLimit(-Math_PI, Math_PI)) and motor/enable (default false: enableMotor(false)).
template <class Hinge>
void godotConfigure(Hinge& h, bool useLimit)
{
	const double params[] = {0.3, kPi * 0.5, -kPi * 0.5, 0.3, 0.9, 1.0, 1, 1};
	for (int i = 0; i < 8; ++i) godotSetParam(h, i, btScalar(float(params[i])));  // real_t is float
	if (!useLimit) h.setLimit(btScalar(-kPi), btScalar(kPi));
	h.enableMotor(false);
}
template <class Hinge>
std::vector<double> godotGetParams(Hinge& h)  // non-const: stock's motor getters are
{
	return {h.getUpperLimit(), h.getLowerLimit(), h.getLimitBiasFactor(), h.getLimitSoftness(),
			h.getLimitRelaxationFactor(), h.getMotorTargetVelocity(), h.getMaxMotorImpulse(),
			double(h.getEnableAngularMotor())};
}
}  // namespace

TEST(CallerPatterns, GodotHingeJointNodeWithItsLimitOffTurnsFreely)
{
	// godotengine/godot (3.x) scene/3d/physics_joint.cpp HingeJoint::_configure_joint with the node's defaults, through
	// modules/bullet/hinge_joint_bullet.cpp HingeJointBullet(rbA, rbB, frameA, frameB), set_param and set_flag:
	// setLimit(getLowerLimit(), π/2, …), setLimit(−π/2, getUpperLimit(), …), three more setLimit with the read-back
	// ends, setMotorTargetVelocity(1), setMaxMotorImpulse(1), then angular_limit/enable = false as setLimit(-Math_PI,
	// Math_PI) and enableMotor(false); get_param reads every value back. The wheel is spun at 5 rad/s for 1.5 s.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w(qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, 0));
		WheelScene s = wheelScene(w);
		Hinge* hinge = w.add(new Hinge(*s.base, *s.wheel, btTransform::getIdentity(), btTransform::getIdentity()));
		godotConfigure(*hinge, false);
		run.reads = godotGetParams(*hinge);
		run.reads.push_back(double(hinge->hasLimit()));
		spin(s.wheel, 5);
		record(run, w, *hinge, 90);
		return run;
	});
	// Godot's "limit off" is setLimit(−π, π): a range of exactly one turn, which never acts in stock (it wraps the angle
	// into a turn) nor in the quaternion hinge (README, "limits"). Both wheels turn freely (7.5 rad in 1.5 s), the
	// same motion, and read back the same parameters (ends to float round-off) and hasLimit() true.
	qh_test::expectSameRun("Godot HingeJoint, limit off", r.stock, r.quat, kAngleTol, kEndTol);
	std::printf("[ figures  ] Godot limit off, 5 rad/s for 1.5 s: stock turned %.3f rad, quaternion %.3f rad\n",
				qh_test::unwrapped(r.stock.angles), qh_test::unwrapped(r.quat.angles));
	EXPECT_NEAR(qh_test::unwrapped(r.stock.angles), -7.5, 0.05);
	EXPECT_NEAR(qh_test::unwrapped(r.quat.angles), -7.5, 0.05);
}

TEST(CallerPatterns, GodotUpperLimitEditedBelowLowerFreesThenLimitsAgain)
{
	// godotengine/godot (3.x) modules/bullet/hinge_joint_bullet.cpp, set_param(PARAM_LIMIT_UPPER) calls
	// setLimit(getLowerLimit(), upper, getLimitSoftness(), getLimitBiasFactor(), getLimitRelaxationFactor()). A node
	// configured with its limit on (±π/2), then edited in the inspector: upper to −115° (below the lower end: the
	// joint is free and reports both ends), the wheel turns at 3 rad/s for 1 s; then lower to −130°: a range
	// [−2.27, −2.01] rad that the wheel, at −3 rad, is outside of; it is brought back to it.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w(qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, 0));
		WheelScene s = wheelScene(w);
		Hinge* hinge = w.add(new Hinge(*s.base, *s.wheel, btTransform::getIdentity(), btTransform::getIdentity()));
		godotConfigure(*hinge, true);
		godotSetParam(*hinge, 1, btScalar(float(-115 * kPi / 180)));
		run.reads = godotGetParams(*hinge);
		run.reads.push_back(double(hinge->hasLimit()));
		spin(s.wheel, 3);
		record(run, w, *hinge, 60);
		godotSetParam(*hinge, 2, btScalar(float(-130 * kPi / 180)));
		for (double v : godotGetParams(*hinge)) run.reads.push_back(v);
		record(run, w, *hinge, 120);
		return run;
	});
	std::printf("[ figures  ] Godot edited limits: after 1 s free and 2 s limited, stock %.4f rad, quaternion %.4f rad\n",
				r.stock.angles.back(), r.quat.angles.back());
	// The free second and the return into the range are the same motion (to 0.01 rad, the first 82 steps). From the
	// first contact with the far stop on, the wheel (no damping, no gravity) rattles between the two stops, and the
	// rebounds differ by design (README, "limit softness": stock's limit row comes on only past a stop, the
	// quaternion hinge's before it, so stock rebounds from its overshoot faster). Asserted instead: from 1.7 s on,
	// the quaternion hinge stays within [−130°, −115°] to 1e-3 rad, stock to 0.02 rad (it passes a stop by up to
	// 0.012 rad before its row comes on).
	CallerRun stockStart = r.stock, quatStart = r.quat;
	stockStart.angles.resize(82);
	quatStart.angles.resize(82);
	qh_test::expectSameRun("Godot edited limits, until the far stop", stockStart, quatStart, kAngleTol, kEndTol);
	EXPECT_NEAR(r.quat.angles[59], -3.0, 0.01);
	const double low = -130 * kPi / 180, high = -115 * kPi / 180;
	for (const CallerRun* run : {&r.stock, &r.quat})
	{
		const double tol = run == &r.quat ? 1e-3 : 0.02;
		for (size_t i = 100; i < run->angles.size(); ++i)
			EXPECT_TRUE(run->angles[i] > low - tol && run->angles[i] < high + tol) << i << " " << run->angles[i];
	}
}

TEST(CallerPatterns, GodotSimpleHingeScalesPivotAndAxisByTheBodyScale)
{
	// godotengine/godot (3.x) modules/bullet/hinge_joint_bullet.cpp, HingeJointBullet(rbA, rbB, pivotInA, pivotInB,
	// axisInA, axisInB) (joint_create_hinge_simple): G_TO_B(axisInA * rbA->get_body_scale()) (and the pivots
	// likewise), so a body scaled by 2 passes the axis (0, 0, 2). A pendulum: the bar hangs from a pivot 0.5 m along
	// it, released horizontal under gravity; get_hinge_angle() read every step.
	auto pendulum = [](btScalar bodyScale) {
		return [bodyScale](auto* tag) {
			using Hinge = HingeOf<decltype(tag)>;
			CallerRun run;
			qh_test::World w;
			WheelScene s = wheelScene(w);
			const btVector3 scale(bodyScale, bodyScale, bodyScale);
			const btVector3 pivotA = btVector3(btScalar(0.5), 0, 0), pivotB = btVector3(btScalar(0.5), 0, 0);
			const btVector3 axis = btVector3(0, 0, 1) * scale;
			Hinge* hinge = w.add(new Hinge(*s.base, *s.wheel, pivotA, pivotB, axis, axis));
			record(run, w, *hinge, 120);
			return run;
		};
	};
	auto scaled = replayOnBoth(pendulum(2));
	auto unit = replayOnBoth(pendulum(1));
	// Deliberately different (README, "axes"): stock takes the axis (0, 0, 2) as given, which scales its frames'
	// columns and so its rows and its getHingeAngle(); the quaternion hinge normalizes it. Asserted: the quaternion
	// hinge with the scaled axis swings as stock does with the unit axis the caller meant, and as itself with it.
	qh_test::expectSameRun("Godot scaled axis: quaternion (scaled) vs stock (unit)", unit.stock, scaled.quat, kAngleTol);
	qh_test::expectSameRun("Godot scaled axis: quaternion, scaled vs unit", unit.quat, scaled.quat, 1e-6);
	std::printf("[ figures  ] Godot scaled axis: stock with (0, 0, 2) ends at %.4f rad, with (0, 0, 1) at %.4f rad\n",
				scaled.stock.angles.back(), unit.stock.angles.back());
}

TEST(CallerPatterns, PandaDoorLimitSetAndReadInDegrees)
{
	// panda3d/panda3d panda/src/bullet/bulletHingeConstraint.cxx: BulletHingeConstraint(node_a, node_b, pivot_a,
	// pivot_b, axis_a, axis_b, use_frame_a = True) → btHingeConstraint(*a, *b, pivot_a, pivot_b, axis_a, axis_b, true);
	// set_limit(low, high, softness, bias, relaxation) → setLimit(deg_2_rad(low), deg_2_rad(high), …) with the Panda3D
	// manual's door values (programming/physics/bullet/constraints: setLimit(-90, 120, softness=0.9, bias=0.3,
	// relaxation=1.0)); get_lower_limit()/get_upper_limit()/get_hinge_angle() → rad_2_deg of the stock getter. Z up
	// (gravity −9.81 along the hinge axis), the door pushed open at 1 rad/s about the hinge.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w(qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, btScalar(-9.81)));
		btRigidBody* wall = w.addBox(0, btVector3(btScalar(0.5), btScalar(0.05), 1), btTransform::getIdentity());
		btRigidBody* door = w.addBox(1, btVector3(btScalar(0.5), btScalar(0.05), 1), btTransform(btQuaternion::getIdentity(), btVector3(btScalar(1.05), 0, 0)));
		Hinge* hinge = w.add(new Hinge(*wall, *door, btVector3(btScalar(0.525), 0, 0), btVector3(btScalar(-0.525), 0, 0), btVector3(0, 0, 1), btVector3(0, 0, 1), true));
		const btScalar degToRad = btScalar(kPi / 180);
		hinge->setLimit(-90 * degToRad, 120 * degToRad, btScalar(0.9), btScalar(0.3), btScalar(1.0));
		run.reads = {hinge->getLowerLimit() / degToRad, hinge->getUpperLimit() / degToRad};
		door->setAngularVelocity(btVector3(0, 0, 1));
		door->setLinearVelocity(btVector3(0, 0, 1).cross(btVector3(btScalar(0.525), 0, 0)));
		record(run, w, *hinge, 90);
		run.reads.push_back(hinge->getHingeAngle() / degToRad);
		return run;
	});
	// the door opens the same way (86° in 1.5 s, short of the stop); the reads, in degrees, within kAngleTol in degrees
	// (the last is get_hinge_angle()), and the ends exactly as Panda3D's user gave them, to 1e-4°
	qh_test::expectSameRun("Panda3D door", r.stock, r.quat, kAngleTol, kAngleTol * 180 / kPi);
	EXPECT_NEAR(r.quat.reads[0], -90, 1e-4);
	EXPECT_NEAR(r.quat.reads[1], 120, 1e-4);
}

TEST(CallerPatterns, PandaMotorTargetEveryFrameAfterSetAxis)
{
	// panda3d/panda3d panda/src/bullet/bulletHingeConstraint.cxx: set_axis(axis) → nassertv(!axis.is_nan()),
	// setAxis(v); enable_motor(True) → enableMotor(true); set_max_motor_impulse(10) → setMaxMotorImpulse(10); every
	// frame set_motor_target(0.7, dt) → setMotorTarget(0.7, dt). The joint is built about x and turned to z by set_axis.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w(qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, 0));
		WheelScene s = wheelScene(w);
		Hinge* hinge = w.add(new Hinge(*s.base, *s.wheel, btVector3(0, 0, 0), btVector3(0, 0, 0), btVector3(1, 0, 0), btVector3(1, 0, 0)));
		btVector3 axis(0, 0, 1);
		hinge->setAxis(axis);
		hinge->enableMotor(true);
		hinge->setMaxMotorImpulse(10);
		record(run, w, *hinge, 120, [&](int) { hinge->setMotorTarget(btScalar(0.7), btScalar(1) / 60); });
		run.reads = {double(hinge->getEnableAngularMotor()), hinge->getMaxMotorImpulse(), hinge->getHingeAngle()};
		return run;
	});
	// the target is reached to 1e-3 rad by both (read back last)
	qh_test::expectSameRun("Panda3D motor target after set_axis", r.stock, r.quat, kAngleTol, 1e-3);
	EXPECT_NEAR(r.quat.reads.back(), 0.7, 1e-3);
}

TEST(CallerPatterns, PandaConstraintParametersOnAxisMinusOne)
{
	// panda3d/panda3d panda/src/bullet/bulletConstraint.cxx: set_param(num, value, axis = -1) → setParam(num, value,
	// axis), get_param(num, axis) → getParam, enable_feedback(True) → enableFeedback(true), set_debug_draw_size(2.0) →
	// setDbgDrawSize, get_applied_impulse() → getAppliedImpulse(). CP_erp 0.8, CP_stop_erp 0.9, CP_cfm 0.01,
	// CP_stop_cfm 0; a pendulum on the world hinge (one-body pivot/axis form) released horizontal.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w;
		WheelScene s = wheelScene(w);
		Hinge* hinge = w.add(new Hinge(*s.wheel, btVector3(btScalar(0.5), 0, 0), btVector3(0, 0, 1)), false);
		hinge->setParam(BT_CONSTRAINT_ERP, btScalar(0.8), -1);
		hinge->setParam(BT_CONSTRAINT_STOP_ERP, btScalar(0.9), -1);
		hinge->setParam(BT_CONSTRAINT_CFM, btScalar(0.01), -1);
		hinge->setParam(BT_CONSTRAINT_STOP_CFM, btScalar(0), -1);
		hinge->enableFeedback(true);
		hinge->setDbgDrawSize(btScalar(2.0));
		for (int num : {BT_CONSTRAINT_ERP, BT_CONSTRAINT_STOP_ERP, BT_CONSTRAINT_CFM, BT_CONSTRAINT_STOP_CFM})
			run.reads.push_back(hinge->getParam(num, -1));
		run.reads.push_back(hinge->getDbgDrawSize());
		record(run, w, *hinge, 120);
		run.extra.push_back(hinge->getAppliedImpulse());
		return run;
	});
	qh_test::expectSameRun("Panda3D set_param", r.stock, r.quat, kAngleTol);
	// getAppliedImpulse is the impulse of the joint's last solver row, which is another row in each class (README,
	// "rows reported"): only finite is asserted
	std::printf("[ figures  ] Panda3D get_applied_impulse: stock %.4g, quaternion %.4g N·s\n", r.stock.extra[0], r.quat.extra[0]);
	EXPECT_TRUE(std::isfinite(r.quat.extra[0]));
}

TEST(CallerPatterns, UrhoDefaultHingeOnTheFixedBodyIsLockedWithStopParameters)
{
	// urho3d/urho3d Source/Urho3D/Physics/Constraint.cpp, CreateConstraint and ApplyLimits for CONSTRAINT_HINGE with
	// no other body: otherBody = &btTypedConstraint::getFixedBody(); new btHingeConstraint(*ownBody, *otherBody,
	// ownFrame, otherFrame) (the two-body frames form against the fixed body, otherFrame in world);
	// setUserConstraintPtr(this); setEnabled(true); setLimit(lowLimit_.x_ · M_DEGTORAD, highLimit_.x_ · M_DEGTORAD)
	// with the attributes' default Vector2::ZERO (a lock); SetERP(0.5)/SetCFM(0.001) → setParam(BT_CONSTRAINT_STOP_ERP,
	// erp_) and setParam(BT_CONSTRAINT_STOP_CFM, cfm_) on axis −1; addConstraint(constraint_, disableCollision_ =
	// false). The body is spun at 5 rad/s against the lock.
	int owner = 0;
	auto r = replayOnBoth([&owner](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w(qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, 0));
		WheelScene s = wheelScene(w);
		const btTransform ownFrame(btQuaternion::getIdentity(), btVector3(0, 0, 0));
		const btTransform otherFrame(btQuaternion::getIdentity(), s.wheel->getWorldTransform() * ownFrame.getOrigin());
		Hinge* hinge = new Hinge(*s.wheel, btTypedConstraint::getFixedBody(), ownFrame, otherFrame);
		hinge->setUserConstraintPtr(&owner);
		hinge->setEnabled(true);
		hinge->setLimit(0 * btScalar(M_PI / 180), 0 * btScalar(M_PI / 180));
		hinge->setParam(BT_CONSTRAINT_STOP_ERP, btScalar(0.5));
		hinge->setParam(BT_CONSTRAINT_STOP_CFM, btScalar(0.001));
		w.add(hinge, false);
		run.reads = {double(hinge->hasLimit()), hinge->getParam(BT_CONSTRAINT_STOP_ERP), hinge->getParam(BT_CONSTRAINT_STOP_CFM),
					 double(hinge->getUserConstraintPtr() == &owner)};
		spin(s.wheel, 5);
		record(run, w, *hinge, 60);
		return run;
	});
	// Both hold the lock, within 0.09 rad of each other: stock's lock row (half range 0) comes on only once the angle
	// has left the locked value, so its wheel turns one step's worth (5 rad/s · 1/60 s = 0.083 rad) before it is
	// brought back; the quaternion hinge's row acts from the first step and holds it to 1e-3 rad.
	qh_test::expectSameRun("Urho3D locked hinge on the fixed body", r.stock, r.quat, 0.09);
	for (double a : r.stock.angles) EXPECT_LT(std::fabs(a), 0.09);
	for (double a : r.quat.angles) EXPECT_LT(std::fabs(a), 1e-3);
}

TEST(CallerPatterns, UrhoRagdollKneeSetsFramesThenItsLimit)
{
	// urho3d/urho3d Source/Samples/13_Ragdolls/CreateRagdoll.cpp, CreateRagdollConstraint("Bip01_L_Calf",
	// "Bip01_L_Thigh", CONSTRAINT_HINGE, Vector3::BACK, Vector3::BACK, Vector2(90, 0), Vector2::ZERO), through
	// Source/Urho3D/Physics/Constraint.cpp: SetOtherBody recreates the hinge (frames, identity rotations, at the
	// bodies' centres) with setLimit(0, 0); SetWorldPosition, SetAxis(BACK) and SetOtherAxis(BACK) each call
	// setFrames(ownFrame, otherFrame) (rotation_ = Quaternion(FORWARD, BACK): a half turn, the hinge axis along −z);
	// SetHighLimit(Vector2(90, 0)) → setLimit(0, 90 · M_DEGTORAD); SetLowLimit(ZERO) is no change, so no call. The calf
	// (1 kg) hangs from a static thigh, bent 0.6 rad at the knee when the frames are set, and falls under gravity.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w;
		btRigidBody* thigh = w.addBox(0, btVector3(btScalar(0.1), btScalar(0.25), btScalar(0.1)), btTransform(btQuaternion::getIdentity(), btVector3(0, btScalar(0.75), 0)));
		const btQuaternion bend(btVector3(0, 0, 1), btScalar(-0.6));
		const btVector3 knee(0, btScalar(0.5), 0);
		btRigidBody* calf = w.addBox(1, btVector3(btScalar(0.07), btScalar(0.25), btScalar(0.07)), btTransform(bend, knee + quatRotate(bend, btVector3(0, btScalar(-0.25), 0))));
		Hinge* hinge = w.add(new Hinge(*calf, *thigh, btTransform::getIdentity(), btTransform::getIdentity()));
		hinge->setLimit(0, 0);
		const btQuaternion forwardToBack(btVector3(0, 1, 0), btScalar(M_PI));
		const btVector3 own = calf->getWorldTransform().invXform(knee), other = thigh->getWorldTransform().invXform(knee);
		hinge->setFrames(btTransform(btQuaternion::getIdentity(), own), btTransform(btQuaternion::getIdentity(), other));
		hinge->setFrames(btTransform(forwardToBack, own), btTransform(btQuaternion::getIdentity(), other));
		hinge->setFrames(btTransform(forwardToBack, own), btTransform(forwardToBack, other));
		hinge->setLimit(0, 90 * btScalar(M_PI / 180));
		run.reads = {hinge->getLowerLimit(), hinge->getUpperLimit(), hinge->getHingeAngle()};
		record(run, w, *hinge, 120);
		return run;
	});
	// the fall from 0.6 rad to the stop at 0 is the same motion to 0.01 rad until the stop is near (first 15 steps);
	// there the rebounds differ by design (README, "limit softness"; see the BenchmarkDemo knee); both settle on the stop
	// within 0.01 rad by 2 s and the quaternion hinge never passes it by more than 1e-3 rad
	CallerRun stockFall = r.stock, quatFall = r.quat;
	stockFall.angles.resize(15);
	quatFall.angles.resize(15);
	qh_test::expectSameRun("Urho3D ragdoll knee, falling", stockFall, quatFall, kAngleTol, kEndTol);
	EXPECT_NEAR(std::fabs(r.quat.reads[2]), 0.6, 1e-3);
	EXPECT_NEAR(r.quat.angles.back(), r.stock.angles.back(), 0.01);
	for (double a : r.quat.angles) EXPECT_GE(a, -1e-3);
}

TEST(CallerPatterns, UrhoDebugDrawThroughTheWorldDrawsOnlyStock)
{
	// urho3d/urho3d Source/Urho3D/Physics/Constraint.cpp, Constraint::DrawDebugGeometry:
	// physicsWorld_->GetWorld()->debugDrawConstraint(constraint_) (bulletphysics/bullet3
	// src/BulletDynamics/Dynamics/btDiscreteDynamicsWorld.cpp, case HINGE_CONSTRAINT_TYPE: frames, and the limit arc
	// with DBG_DrawConstraintLimits). Deliberately different (README, "constraint type"): Bullet's world downcasts only
	// its own types, so it draws nothing for the quaternion hinge; hinge->debugDraw(drawer) draws it.
	struct CountingDrawer : btIDebugDraw
	{
		int lines = 0;
		void drawLine(const btVector3&, const btVector3&, const btVector3&) override { ++lines; }
		void drawContactPoint(const btVector3&, const btVector3&, btScalar, int, const btVector3&) override {}
		void reportErrorWarning(const char*) override {}
		void draw3dText(const btVector3&, const char*) override {}
		void setDebugMode(int) override {}
		int getDebugMode() const override { return DBG_DrawConstraints | DBG_DrawConstraintLimits; }
	};
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w;
		WheelScene s = wheelScene(w);
		Hinge* hinge = w.add(new Hinge(*s.base, *s.wheel, btTransform::getIdentity(), btTransform::getIdentity()));
		hinge->setLimit(-1, 1);
		CountingDrawer drawer;
		w.world().setDebugDrawer(&drawer);
		w.world().debugDrawConstraint(hinge);
		w.world().setDebugDrawer(nullptr);
		run.extra.push_back(drawer.lines);
		if constexpr (isQuat<Hinge>())
		{
			CountingDrawer own;
			hinge->debugDraw(&own);
			run.extra.push_back(own.lines);
		}
		return run;
	});
	std::printf("[ figures  ] debugDrawConstraint lines: stock %g, quaternion %g (its own debugDraw: %g)\n",
				r.stock.extra[0], r.quat.extra[0], r.quat.extra[1]);
	EXPECT_GT(r.stock.extra[0], 0);
	EXPECT_EQ(r.quat.extra[0], 0);
	EXPECT_GT(r.quat.extra[1], 0);
}

TEST(CallerPatterns, JmeHammerJoinedOneMetreApartThenDrivenByKeys)
{
	// jMonkeyEngine/jmonkeyengine jme3-examples/src/main/java/jme3test/bullet/TestPhysicsHingeJoint.java, setupJoint
	// and onAnalog, through jme3-bullet-native/src/native/cpp/com_jme3_bullet_joints_HingeJoint.cpp (createJoint:
	// new btHingeConstraint(*bodyA, *bodyB, pivotA, pivotB, axisA, axisB); enableMotor: enableAngularMotor(enable,
	// targetVelocity, maxMotorImpulse)): a static holder (box 0.1) at the origin, a 1 kg hammer (box 0.3) at
	// (0, −1, 0), new HingeJoint(holder, hammer, Vector3f.ZERO, new Vector3f(0f, -1, 0f), UNIT_Z, UNIT_Z) — the pivots
	// start 2 m apart and the joint pulls them together; while "Left" is held (1 s) enableMotor(true, 1, .1f) every
	// frame, then "Swing" (1 s) enableMotor(false, 0, 0) every frame. jME's gravity (0, −9.81, 0); linked bodies collide
	// (PhysicsJoint's collisionBetweenLinkedBodys = true: addConstraint(joint, false)), so the holder is made contact-free
	// here to keep the scene deterministic across the two classes' slightly different paths.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w(qh_test::SolverKind::SequentialImpulse, btVector3(0, btScalar(-9.81), 0));
		btRigidBody* holder = w.addBox(0, btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)), btTransform::getIdentity());
		holder->setCollisionFlags(holder->getCollisionFlags() | btCollisionObject::CF_NO_CONTACT_RESPONSE);
		btRigidBody* hammer = w.addBox(1, btVector3(btScalar(0.3), btScalar(0.3), btScalar(0.3)), btTransform(btQuaternion::getIdentity(), btVector3(0, -1, 0)));
		Hinge* joint = w.add(new Hinge(*holder, *hammer, btVector3(0, 0, 0), btVector3(0, -1, 0), btVector3(0, 0, 1), btVector3(0, 0, 1)), false);
		record(run, w, *joint, 60, [&](int) { joint->enableAngularMotor(true, 1, btScalar(.1f)); });
		run.reads = {double(joint->getEnableAngularMotor()), joint->getMotorTargetVelocity(), joint->getMaxMotorImpulse()};
		record(run, w, *joint, 60, [&](int) { joint->enableAngularMotor(false, 0, 0); });
		run.reads.push_back(double(joint->getEnableAngularMotor()));
		run.extra.push_back(qh_test::separation(*holder, joint->getAFrame(), *hammer, joint->getBFrame()));
		return run;
	});
	qh_test::expectSameRun("jME hammer", r.stock, r.quat, kAngleTol);
	for (const CallerRun* run : {&r.stock, &r.quat}) EXPECT_LT(run->extra[0], 0.01);  // joined within 2 s (m)
}

TEST(CallerPatterns, JmeReadOfASaveWithoutLimitsLeavesTheJointFree)
{
	// jMonkeyEngine/jmonkeyengine jme3-bullet/src/main/java/com/jme3/bullet/joints/HingeJoint.java, read(): createJoint()
	// (native btHingeConstraint(*bodyA, *bodyB, pivotA, pivotB, axisA, axisB)), enableMotor(enableAngularMotor,
	// targetVelocity, maxMotorImpulse) with the capsule's defaults (false, 0, 0), setLimit(lowerLimit, upperLimit,
	// limitSoftness, biasFactor, relaxationFactor) with the defaults 1e30f, -1e30f, 0.9f, 0.3f, 1f (a save that holds no
	// limit); write() stores getLowerLimit()/getUpperLimit(), and a second read() passes those back to setLimit.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w(qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, 0));
		WheelScene s = wheelScene(w);
		const btVector3 o(0, 0, 0), z(0, 0, 1);
		Hinge* first = new Hinge(*s.base, *s.wheel, o, o, z, z);
		first->enableAngularMotor(false, 0, 0);
		first->setLimit(1e30f, -1e30f, 0.9f, 0.3f, 1.0f);
		run.reads = {double(first->hasLimit())};
		const btScalar savedLow = first->getLowerLimit(), savedHigh = first->getUpperLimit();  // write()
		run.extra = {savedLow, savedHigh};
		delete first;
		Hinge* hinge = w.add(new Hinge(*s.base, *s.wheel, o, o, z, z));  // read() of that save
		hinge->enableAngularMotor(false, 0, 0);
		hinge->setLimit(savedLow, savedHigh, 0.9f, 0.3f, 1.0f);
		run.extra.push_back(double(hinge->hasLimit()));
		spin(s.wheel, 3);
		record(run, w, *hinge, 120);
		return run;
	});
	// Deliberately different (README, "limits": getters return the ends as given): stock wraps ±1e30 into (−π, π] and
	// write() saves those wrapped values; the quaternion hinge saves 1e30 and −1e30, so the save it writes back is
	// still a free joint, turning 6 rad in 2 s at 3 rad/s (to 0.01 rad).
	std::printf(
		"[ figures  ] jME read of setLimit(1e30f, -1e30f): stock reports [%.4f, %.4f] (saved: limit %s), "
		"quaternion [%g, %g] (limit %s)\n",
		r.stock.extra[0], r.stock.extra[1], r.stock.extra[2] != 0 ? "on" : "off",
		r.quat.extra[0], r.quat.extra[1], r.quat.extra[2] != 0 ? "on" : "off");
	EXPECT_EQ(r.stock.reads[0], 0);  // the first read is free in both
	EXPECT_EQ(r.quat.reads[0], 0);
	EXPECT_EQ(r.quat.extra[0], double(1e30f));
	EXPECT_EQ(r.quat.extra[1], double(-1e30f));
	EXPECT_EQ(r.quat.extra[2], 0);
	EXPECT_NEAR(qh_test::unwrapped(r.quat.angles), -6, 0.01);
}

namespace
{
// gazebosim/gazebo-classic gazebo/physics/bullet/BulletHingeJoint.cc, Init(): the child link is body A, the parent body
// B; pivots and axes from the anchor and the world axis in each link's frame; angleOffset = getHingeAngle(); the
// SDF limit (default lower −1e16, upper 1e16) as setLimit(angleOffset + lower, angleOffset + upper); SetParam
// ("friction", 0) as enableAngularMotor(true, 0, dt · friction); addConstraint(hinge, true); enableFeedback(true);
// BulletJoint::SetupJointFeedback: setJointFeedback(feedback). The child (1 kg bar) is turned 0.3 rad about the
// axis (world z, along gravity) from the parent (static), so angleOffset is not 0.
template <class Hinge>
struct GazeboJoint
{
	qh_test::World w{qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, btScalar(-9.8))};
	WheelScene s = wheelScene(w);
	btJointFeedback feedback;
	Hinge* hinge = nullptr;
	btScalar angleOffset = 0;
	GazeboJoint()
	{
		const btQuaternion childRot(btVector3(0, 0, 1), btScalar(0.3));
		s.wheel->setCenterOfMassTransform(btTransform(childRot, quatRotate(childRot, btVector3(btScalar(0.5), 0, 0))));
		const btVector3 anchor(0, 0, 0), axis(0, 0, 1);
		const btVector3 pivotChild = s.wheel->getCenterOfMassTransform().invXform(anchor);
		const btVector3 axisChild = quatRotate(childRot.inverse(), axis);
		hinge = new Hinge(*s.wheel, *s.base, pivotChild, anchor, axisChild, axis);
		angleOffset = hinge->getHingeAngle();
		hinge->setLimit(btScalar(angleOffset + -1e16), btScalar(angleOffset + 1e16));
		hinge->enableAngularMotor(true, 0, btScalar(0.001 * 0));  // max step size 0.001 s, friction 0
		w.add(hinge, true);
		hinge->enableFeedback(true);
		hinge->setJointFeedback(&feedback);
	}
	// SetForceImpl(effort): applyTorque(effort · axis of frame A in world) on A, the opposite about frame B's on B
	void setForce(btScalar effort)
	{
		const btVector3 axisA = hinge->getRigidBodyA().getWorldTransform().getBasis() * hinge->getFrameOffsetA().getBasis().getColumn(2);
		const btVector3 axisB = hinge->getRigidBodyB().getWorldTransform().getBasis() * hinge->getFrameOffsetB().getBasis().getColumn(2);
		hinge->getRigidBodyA().applyTorque(effort * axisA);
		hinge->getRigidBodyB().applyTorque(-effort * axisB);
	}
	// PositionImpl: getHingeAngle() − angleOffset (getAccumulatedHingeAngle on Bullet > 2.82, a subclass of stock's)
	double position() { return double(hinge->getHingeAngle()) - double(angleOffset); }
};
}  // namespace

TEST(CallerPatterns, GazeboRevoluteJointDrivenByEffort)
{
	// gazebosim/gazebo-classic gazebo/physics/bullet/BulletHingeJoint.cc Init (GazeboJoint above), then every step
	// SetForceImpl(0.5 N·m) and the reads PositionImpl (getHingeAngle() − angleOffset) and GetVelocity (the frame A
	// axis in world · the child's angular velocity); UpperLimit()/LowerLimit() read getUpperLimit()/getLowerLimit().
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		GazeboJoint<Hinge> g;
		run.reads = {g.angleOffset, double(g.hinge->hasLimit())};
		record(run, g.w, *g.hinge, 60, [&](int) { g.setForce(btScalar(0.5)); });
		const btVector3 axis = g.hinge->getRigidBodyA().getWorldTransform().getBasis() * g.hinge->getFrameOffsetA().getBasis().getColumn(2);
		run.reads.push_back(g.position());
		run.reads.push_back(axis.dot(g.s.wheel->getAngularVelocity()));
		run.reads.push_back(g.feedback.m_appliedForceBodyA.length());
		run.extra = {g.hinge->getLowerLimit(), g.hinge->getUpperLimit()};
		return run;
	});
	// position (rad), velocity (rad/s) and feedback force (N) within 1e-3; the ends read back differ by design
	// (README, "limits": stock wraps ±1e16 into (−π, π], the quaternion hinge reports a side without a stop as ±∞)
	qh_test::expectSameRun("Gazebo revolute joint", r.stock, r.quat, kAngleTol, 1e-3);
	std::printf("[ figures  ] Gazebo limits read back: stock [%.4f, %.4f], quaternion [%g, %g]\n", r.stock.extra[0],
				r.stock.extra[1], r.quat.extra[0], r.quat.extra[1]);
	EXPECT_EQ(r.quat.extra[0], -std::numeric_limits<double>::infinity());
	EXPECT_EQ(r.quat.extra[1], std::numeric_limits<double>::infinity());
	EXPECT_NEAR(std::fabs(r.quat.reads[0]), 0.3, 1e-3);
}

TEST(CallerPatterns, GazeboSetUpperLimitKeepsTheSdfLowerEnd)
{
	// gazebosim/gazebo-classic gazebo/physics/bullet/BulletHingeJoint.cc SetUpperLimit(0, 0.5) after Init with the SDF
	// defaults: setLimit(getLowerLimit(), angleOffset + 0.5) ("this function will reset [the other parameters] to
	// default settings"); then the effort of 0.5 N·m pushes towards the upper end for 2 s.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		GazeboJoint<Hinge> g;
		g.hinge->setLimit(g.hinge->getLowerLimit(), g.angleOffset + btScalar(0.5));
		run.extra = {g.hinge->getLowerLimit(), double(g.hinge->hasLimit())};
		double most = -1e9;
		record(run, g.w, *g.hinge, 120, [&](int) {
			g.setForce(btScalar(0.5));
			most = std::max(most, g.position());
		});
		run.extra.push_back(std::max(most, g.position()));
		double least = 1e9;  // then pushed the other way for 3 s
		record(run, g.w, *g.hinge, 180, [&](int) {
			g.setForce(btScalar(-0.5));
			least = std::min(least, double(g.hinge->getHingeAngle()));
		});
		if constexpr (isQuat<Hinge>()) least = double(g.hinge->getMultiTurnAngle());
		run.extra.push_back(least - double(g.angleOffset));
		return run;
	});
	// Deliberately different (README, "limits"): stock's getLowerLimit() is −1e16 wrapped into (−π, π], so the
	// limit it is handed back has an arbitrary lower end; the quaternion hinge hands back −∞ (no stop on that side)
	// and stops the joint at the upper end the caller gave: position (getHingeAngle − angleOffset) at most 0.5 rad
	// + 1e-3 rad; pushed back, it has no lower stop (it turns past −π; stock stops at its arbitrary lower end).
	std::printf(
		"[ figures  ] Gazebo SetUpperLimit(0.5): stock lower end %.4f rad (limit %s), reached %.4f rad; "
		"quaternion lower end %g (limit %s), reached %.4f rad; pushed back: stock least %.4f rad, quaternion %.4f rad\n",
		r.stock.extra[0], r.stock.extra[1] != 0 ? "on" : "off", r.stock.extra[2], r.quat.extra[0],
		r.quat.extra[1] != 0 ? "on" : "off", r.quat.extra[2], r.stock.extra[3], r.quat.extra[3]);
	EXPECT_EQ(r.quat.extra[0], -std::numeric_limits<double>::infinity());
	EXPECT_LE(r.quat.extra[2], 0.5 + 1e-3);
	EXPECT_GT(r.quat.extra[2], 0.5 - 0.02);  // and it got there
	EXPECT_LT(r.quat.extra[3], -kPi);
}

TEST(CallerPatterns, SxrFileLoaderTurnsTheFramesInPlace)
{
	// sxrsdk/sxrsdk SXR/Extensions/sxr-physics/src/main/jni/engine/bullet/bullet_fileloader.cpp,
	// BulletFileLoader::createHingeConstraint: for a loaded btHingeConstraint, if (mNeedRotate) { btTransform& tA =
	// hg->getAFrame(); btTransform& tB = hg->getBFrame(); tA = mTransformCoords * tA; tB = mTransformCoords * tB; } —
	// both frames edited through the non-const references (here a −90° turn about x, which makes the z axis y), before
	// the joint is added. The wheel is then spun about y and about z.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w(qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, 0));
		WheelScene s = wheelScene(w);
		Hinge* hinge = new Hinge(*s.base, *s.wheel, btTransform::getIdentity(), btTransform::getIdentity());
		const btTransform transformCoords(btQuaternion(btVector3(1, 0, 0), btScalar(-M_PI / 2)));
		btTransform& tA = hinge->getAFrame();
		btTransform& tB = hinge->getBFrame();
		tA = transformCoords * tA;
		tB = transformCoords * tB;
		w.add(hinge);
		s.wheel->setAngularVelocity(btVector3(0, 2, 2));  // the y part turns the hinge, the z part the joint takes out
		record(run, w, *hinge, 60);
		const btVector3 axis = hinge->getAFrame().getBasis().getColumn(2);
		run.reads = {axis.x(), axis.y(), axis.z(), s.wheel->getAngularVelocity().y(), s.wheel->getAngularVelocity().z()};
		return run;
	});
	// the hinge turns about y, the z spin taken out by the joint; the spin left (rad/s) within 1e-3
	qh_test::expectSameRun("SXR frames edited in place", r.stock, r.quat, kAngleTol, 1e-3);
	EXPECT_NEAR(r.quat.reads[1], 1, 1e-6);
	EXPECT_NEAR(r.quat.reads[4], 0, 1e-3);
}

TEST(CallerPatterns, SxrInactiveLimitAndInfiniteBreakingImpulse)
{
	// sxrsdk/sxrsdk SXR/Extensions/sxr-physics/src/main/jni/engine/bullet/bullet_hingeconstraint.cpp,
	// BulletHingeConstraint::updateConstructionInfo: new btHingeConstraint(*rbA, *rbB, pivotInA, pivotInB, axisInA,
	// axisInB); setLimit(mTempLower = 2.0f, mTempUpper = 0.0f) ("By default angular limit is inactive");
	// setBreakingImpulseThreshold(mBreakingImpulse = SIMD_INFINITY); getLowerLimit/getUpperLimit/
	// getBreakingImpulseThreshold read back. The wheel turns at 4 rad/s for 1 s.
	auto r = replayOnBoth([](auto* tag) {
		using Hinge = HingeOf<decltype(tag)>;
		CallerRun run;
		qh_test::World w(qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, 0));
		WheelScene s = wheelScene(w);
		const btVector3 o(0, 0, 0), z(0, 0, 1);
		Hinge* hinge = w.add(new Hinge(*s.base, *s.wheel, o, o, z, z));
		hinge->setLimit(2.0f, 0.0f);
		hinge->setBreakingImpulseThreshold(SIMD_INFINITY);
		run.reads = {hinge->getLowerLimit(), hinge->getUpperLimit(), hinge->getBreakingImpulseThreshold(), double(hinge->hasLimit())};
		spin(s.wheel, 4);
		record(run, w, *hinge, 60);
		run.reads.push_back(double(hinge->isEnabled()));
		return run;
	});
	qh_test::expectSameRun("SXR inactive limit", r.stock, r.quat, kAngleTol, kEndTol);
	EXPECT_NEAR(qh_test::unwrapped(r.quat.angles), -4, 0.01);  // free: 4 rad in 1 s
}
