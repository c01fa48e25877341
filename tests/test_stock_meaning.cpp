// Every call stock btHingeConstraint (Bullet 3.24) accepts keeps stock's meaning: each test runs the same calls on
// both classes and compares what they report and how they move (issue 17, item 1).
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/World.h"

#include "BulletDynamics/ConstraintSolver/btHingeConstraint.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <type_traits>

namespace
{
// Angles compared between the two classes (rad): both integrate the same free body with the same Bullet integrator;
// 1e-3 rad leaves room for their different rows' residuals over a second of 60 Hz steps.
const double kAngleTol = 1e-3;
// A target held by the motor (rad): 10 iterations, 60 Hz, a one-step P controller; both reach it to round-off.
const double kHoldTol = 1e-3;

// A wheel (1 kg bar) on a static base, hinged about z through its centre; zero gravity unless asked.
template <class Hinge>
struct Wheel
{
	qh_test::World world;
	btRigidBody* base;
	btRigidBody* wheel;
	Hinge* hinge;
	explicit Wheel(bool referenceFrameA = false, const btVector3& axis = btVector3(0, 0, 1),
				   const btVector3& gravity = btVector3(0, 0, 0))
		: world(qh_test::SolverKind::SequentialImpulse, gravity)
	{
		base = world.addBox(0, btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)), btTransform::getIdentity());
		base->setCollisionFlags(base->getCollisionFlags() | btCollisionObject::CF_NO_CONTACT_RESPONSE);
		wheel = world.addBox(1, btVector3(btScalar(0.5), btScalar(0.05), btScalar(0.05)), btTransform::getIdentity());
		wheel->setCollisionFlags(wheel->getCollisionFlags() | btCollisionObject::CF_NO_CONTACT_RESPONSE);
		const btVector3 o(0, 0, 0);
		hinge = world.add(new Hinge(*base, *wheel, o, o, axis, axis, referenceFrameA));
	}
	/// Spins the wheel at `rate` rad/s about +z for `steps` steps.
	void spin(btScalar rate, int steps)
	{
		wheel->activate(true);
		wheel->setAngularVelocity(btVector3(0, 0, rate));
		world.step(steps);
	}
	btScalar angleAboutZ() const
	{
		btScalar yaw, pitch, roll;
		wheel->getCenterOfMassTransform().getBasis().getEulerZYX(yaw, pitch, roll);
		return yaw;
	}
};

using Stock = Wheel<btHingeConstraint>;
using Quat = Wheel<btQuaternionHingeConstraint>;

double wrapped(double a) { return std::remainder(a, 2 * M_PI); }
}  // namespace

TEST(StockMeaning, NeverLimitedHingeReportsStocksValues)
{
	Stock s;
	Quat q;
	EXPECT_EQ(q.hinge->hasLimit(), s.hinge->hasLimit());
	EXPECT_EQ(q.hinge->getLowerLimit(), s.hinge->getLowerLimit());  // stock: 1
	EXPECT_EQ(q.hinge->getUpperLimit(), s.hinge->getUpperLimit());  // stock: −1
	EXPECT_EQ(q.hinge->getLimitSoftness(), s.hinge->getLimitSoftness());
	EXPECT_EQ(q.hinge->getLimitBiasFactor(), s.hinge->getLimitBiasFactor());
	EXPECT_EQ(q.hinge->getLimitRelaxationFactor(), s.hinge->getLimitRelaxationFactor());
	s.world.step(1);
	q.world.step(1);
	EXPECT_EQ(q.hinge->getSolveLimit(), s.hinge->getSolveLimit());
	EXPECT_EQ(q.hinge->getLimitSign(), s.hinge->getLimitSign());
}

TEST(StockMeaning, LowAboveHighIsAFreeJoint)
{
	// Bullet's URDF importer (Base_2.urdf's lower="1" upper="0"), Godot's edited limits (−π/2, −2), the "free" idiom
	// (1, −1): no limit, both ends reported back, and the wheel spins through where a stop would be.
	const double cases[][2] = {{1, 0}, {-M_PI / 2, -2}, {1, -1}};
	for (const auto& c : cases)
	{
		Stock s;
		Quat q;
		s.hinge->setLimit(btScalar(c[0]), btScalar(c[1]));
		q.hinge->setLimit(btScalar(c[0]), btScalar(c[1]));
		EXPECT_FALSE(s.hinge->hasLimit());
		EXPECT_FALSE(q.hinge->hasLimit());
		EXPECT_NEAR(q.hinge->getLowerLimit(), s.hinge->getLowerLimit(), 1e-6) << c[0];
		EXPECT_NEAR(q.hinge->getUpperLimit(), s.hinge->getUpperLimit(), 1e-6) << c[1];
		for (int i = 0; i < 30; ++i)
		{
			s.spin(5, 1);
			q.spin(5, 1);
			EXPECT_EQ(q.hinge->getSolveLimit(), s.hinge->getSolveLimit());
		}
		// 30 steps at 5 rad/s: 2.5 rad, past any of these ends
		EXPECT_NEAR(wrapped(q.angleAboutZ() - s.angleAboutZ()), 0, kAngleTol) << c[0] << " " << c[1];
		EXPECT_NEAR(wrapped(s.angleAboutZ()), 2.5, 0.01);
	}
}

TEST(StockMeaning, OneTurnRangeIsAFreeJointThatReportsALimit)
{
	// setLimit(−π, π) (Godot's HingeJoint with its limit off, and a common "no limit"): stock never stops there (it wraps
	// the angle into a turn) and says hasLimit(); so does the quaternion hinge. Also with ends a turn apart elsewhere
	// (0, 2π) and from degrees in float. A range wider than a turn acts (README: multi-turn limits).
	const double cases[][2] = {{-M_PI, M_PI}, {0, 2 * M_PI}, {double(float(-180 * M_PI / 180)), double(float(180 * M_PI / 180))}};
	for (const auto& c : cases)
	{
		Stock s;
		Quat q;
		s.hinge->setLimit(btScalar(c[0]), btScalar(c[1]));
		q.hinge->setLimit(btScalar(c[0]), btScalar(c[1]));
		EXPECT_TRUE(s.hinge->hasLimit());
		EXPECT_TRUE(q.hinge->hasLimit()) << c[0] << " " << c[1];
		EXPECT_FALSE(q.hinge->getSettings().hasLimit);
		(void)q.hinge->getMultiTurnAngle();  // tracked from here on
		for (int i = 0; i < 90; ++i)
		{
			s.spin(5, 1);
			q.spin(5, 1);
			EXPECT_EQ(q.hinge->getSolveLimit(), s.hinge->getSolveLimit());
		}
		// 90 steps at 5 rad/s: 7.5 rad, more than a turn, same pose
		EXPECT_NEAR(wrapped(q.angleAboutZ() - s.angleAboutZ()), 0, kAngleTol) << c[0] << " " << c[1];
		EXPECT_NEAR(std::fabs(double(q.hinge->getMultiTurnAngle())), 7.5, 0.01);
	}
	Quat wider;
	wider.hinge->setLimit(btScalar(-M_PI - 0.1), btScalar(M_PI + 0.1));
	EXPECT_TRUE(wider.hinge->getSettings().hasLimit);
	wider.spin(5, 90);
	EXPECT_LT(std::fabs(double(wider.hinge->getMultiTurnAngle())), M_PI + 0.1 + 1e-3);  // rad: the stop holds
}

TEST(StockMeaning, EqualEndsLockTheHingeAndReportNoLimit)
{
	// setLimit(0, 0): stock's half range 0 still acts (a lock) while hasLimit() says false.
	Stock s;
	Quat q;
	s.hinge->setLimit(0, 0);
	q.hinge->setLimit(0, 0);
	EXPECT_EQ(q.hinge->hasLimit(), s.hinge->hasLimit());
	EXPECT_FALSE(q.hinge->hasLimit());
	s.spin(5, 30);
	q.spin(5, 30);
	std::printf("[ figures  ] locked by setLimit(0, 0), pushed at 5 rad/s: stock %.3g rad, quaternion %.3g rad\n",
				double(s.angleAboutZ()), double(q.angleAboutZ()));
	EXPECT_LT(std::fabs(double(s.angleAboutZ())), 0.1);
	EXPECT_LT(std::fabs(double(q.angleAboutZ())), 0.1);
}

TEST(StockMeaning, HugeFiniteRangeIsAccepted)
{
	// SDF's default limits ±1e16: stock accepts them and never stops; here they are sides without a stop.
	Stock s;
	Quat q;
	s.hinge->setLimit(btScalar(-1e16), btScalar(1e16));
	q.hinge->setLimit(btScalar(-1e16), btScalar(1e16));
	EXPECT_TRUE(s.hinge->hasLimit());
	EXPECT_TRUE(q.hinge->hasLimit());
	s.spin(5, 60);
	q.spin(5, 60);
	EXPECT_NEAR(wrapped(q.angleAboutZ() - s.angleAboutZ()), 0, kAngleTol);
	EXPECT_GT(q.hinge->getMultiTurnAngle() * (q.hinge->getUseReferenceFrameA() ? 1 : -1), 4.9);  // 5 rad, no stop
}

TEST(StockMeaning, AnySoftnessBiasAndRelaxationIsAcceptedAndReported)
{
	// Stock stores any values; the limit still stops the wheel with them.
	Stock s;
	Quat q;
	s.hinge->setLimit(-1, 1, 0, 2, -1);
	q.hinge->setLimit(-1, 1, 0, 2, -1);
	EXPECT_EQ(q.hinge->getLimitSoftness(), s.hinge->getLimitSoftness());
	EXPECT_EQ(q.hinge->getLimitBiasFactor(), s.hinge->getLimitBiasFactor());
	EXPECT_EQ(q.hinge->getLimitRelaxationFactor(), s.hinge->getLimitRelaxationFactor());
	q.hinge->setLimit(-1, 1, btScalar(1.7), btScalar(-0.5), 3);
	EXPECT_EQ(q.hinge->getLimitSoftness(), btScalar(1.7));
	q.hinge->setLimit(-1, 1, 0, 2, -1);
	for (int i = 0; i < 60; ++i)
	{
		s.spin(3, 1);
		q.spin(3, 1);
	}
	std::printf("[ figures  ] wheel pushed at 3 rad/s into a stop at 1 rad (bias 2): stock %.4f, quaternion %.4f rad\n",
				std::fabs(double(s.angleAboutZ())), std::fabs(double(q.angleAboutZ())));
	EXPECT_LT(std::fabs(double(q.angleAboutZ())), 1.05);
	EXPECT_LT(std::fabs(double(s.angleAboutZ())), 1.05);
}

TEST(StockMeaning, GetParamOfAnUnsetParameterIsZeroAndAxisFiveIsTheJoint)
{
	Stock s;
	Quat q;
	for (int num : {BT_CONSTRAINT_ERP, BT_CONSTRAINT_STOP_ERP, BT_CONSTRAINT_CFM, BT_CONSTRAINT_STOP_CFM})
		for (int axis : {-1, 5})
			EXPECT_EQ(q.hinge->getParam(num, axis), s.hinge->getParam(num, axis)) << num << " " << axis;
	EXPECT_EQ(q.hinge->getParam(99), 0);     // unknown num: 0, as stock's release build
	EXPECT_EQ(q.hinge->getParam(1, 17), 0);  // unknown axis
	// stock's axis 5 is the joint: its ERP acts on every row, read back through −1
	for (auto* h : {static_cast<btTypedConstraint*>(s.hinge), static_cast<btTypedConstraint*>(q.hinge)})
	{
		h->setParam(BT_CONSTRAINT_ERP, btScalar(1.5), 5);  // above 1, as stock takes it
		h->setParam(BT_CONSTRAINT_CFM, btScalar(0.5), 5);
		h->setParam(BT_CONSTRAINT_STOP_CFM, btScalar(0.01), -1);
	}
	for (int num : {BT_CONSTRAINT_ERP, BT_CONSTRAINT_STOP_ERP, BT_CONSTRAINT_CFM, BT_CONSTRAINT_STOP_CFM})
		for (int axis : {-1, 5})
			EXPECT_EQ(q.hinge->getParam(num, axis), s.hinge->getParam(num, axis)) << num << " " << axis;
	EXPECT_EQ(q.hinge->getParam(BT_CONSTRAINT_ERP, 0), btScalar(1.5));  // every row
	EXPECT_EQ(q.hinge->getParam(BT_CONSTRAINT_CFM, 0), 0);              // CFM: the motor row only, as stock
	EXPECT_EQ(q.hinge->getFlags(), s.hinge->getFlags() | q.hinge->getFlags());
}

TEST(StockMeaning, MotorTargetAngleIsHeldAsStock)
{
	// Panda3D's set_motor_target(angle, dt) every tick, with and without a limit, both reference frames.
	for (bool referenceFrameA : {false, true})
		for (bool limited : {false, true})
		{
			Stock s(referenceFrameA);
			Quat q(referenceFrameA);
			s.hinge->enableMotor(true);
			q.hinge->enableMotor(true);
			s.hinge->setMaxMotorImpulse(10);
			q.hinge->setMaxMotorImpulse(10);
			if (limited)
			{
				s.hinge->setLimit(-1, 1);
				q.hinge->setLimit(-1, 1);
			}
			for (int i = 0; i < 120; ++i)
			{
				s.hinge->setMotorTarget(btScalar(0.7), btScalar(1) / 60);
				q.hinge->setMotorTarget(btScalar(0.7), btScalar(1) / 60);
				s.world.step(1);
				q.world.step(1);
			}
			EXPECT_NEAR(s.hinge->getHingeAngle(), 0.7, kHoldTol) << referenceFrameA << limited;
			EXPECT_NEAR(q.hinge->getHingeAngle(), 0.7, kHoldTol) << referenceFrameA << limited;
			EXPECT_NEAR(q.wheel->getAngularVelocity().z(), 0, 1e-3);
		}
}

TEST(StockMeaning, MotorTargetQuaternionDrivesWhereStockDoes)
{
	// Panda3D's set_motor_target(quat, dt): qAinB, the rotation of A relative to B. Stock takes its twist as the
	// target angle in both reference frames; so does the quaternion hinge.
	for (bool referenceFrameA : {false, true})
		for (bool limited : {false, true})
		{
			Stock s(referenceFrameA);
			Quat q(referenceFrameA);
			s.hinge->enableMotor(true);
			q.hinge->enableMotor(true);
			s.hinge->setMaxMotorImpulse(10);
			q.hinge->setMaxMotorImpulse(10);
			if (limited)
			{
				s.hinge->setLimit(-1, 1);
				q.hinge->setLimit(-1, 1);
			}
			const btQuaternion qAinB(btVector3(0, 0, 1), btScalar(0.7));
			for (int i = 0; i < 120; ++i)
			{
				s.hinge->setMotorTarget(qAinB, btScalar(1) / 60);
				q.hinge->setMotorTarget(qAinB, btScalar(1) / 60);
				s.world.step(1);
				q.world.step(1);
			}
			EXPECT_NEAR(std::fabs(double(s.hinge->getHingeAngle())), 0.7, kHoldTol);
			EXPECT_NEAR(q.hinge->getHingeAngle(), s.hinge->getHingeAngle(), kHoldTol) << referenceFrameA << limited;
		}
}

TEST(StockMeaning, NonUnitAxisIsNormalized)
{
	// Godot scales the axis by the body's scale: stock takes any non-zero axis; the quaternion hinge normalizes it.
	Stock s;
	Quat unit;
	Quat scaled(false, btVector3(0, 0, btScalar(2.5)));
	Quat tiny(false, btVector3(0, 0, btScalar(1e-30)));
	EXPECT_TRUE(scaled.hinge->getAFrame() == unit.hinge->getAFrame());
	EXPECT_TRUE(scaled.hinge->getBFrame() == unit.hinge->getBFrame());
	EXPECT_TRUE(tiny.hinge->getAFrame() == unit.hinge->getAFrame());
	btVector3 axis(0, btScalar(3), 0);
	scaled.hinge->setAxis(axis);
	EXPECT_NEAR(scaled.hinge->getAFrame().getBasis().getColumn(2).length(), 1, 1e-6);
	s.spin(2, 30);
	unit.spin(2, 30);
	EXPECT_NEAR(wrapped(unit.angleAboutZ() - s.angleAboutZ()), 0, kAngleTol);
}

TEST(StockMeaning, AntiparallelAxesGiveAnAngleInRange)
{
	// axisB = −axisA: the quaternion hinge's getHingeAngle() is within (−π, π] (it was −2π at construction from
	// atan2(−0, −0)) and is stock's angle, at construction and after B turned about the axis.
	btBoxShape shape(btVector3(1, 1, 1));
	for (int k = 0; k < 12; ++k)
	{
		const btQuaternion turn(btVector3(btScalar(0.3), 1, btScalar(0.2 * k)).normalized(), btScalar(0.5 * k));
		btRigidBody a(1, nullptr, &shape, btVector3(1, 1, 1)), b(1, nullptr, &shape, btVector3(1, 1, 1));
		a.setCenterOfMassTransform(btTransform(turn));
		// B turned about A's hinge axis in world: the axes stay exactly antiparallel, the angle runs through a turn
		const btQuaternion twist(quatRotate(turn, btVector3(0, 0, 1)), btScalar(0.55 * k - 3));
		b.setCenterOfMassTransform(btTransform(twist * turn, btVector3(2, 0, 0)));
		const btVector3 axis(0, 0, 1);
		btHingeConstraint s(a, b, btVector3(1, 0, 0), btVector3(-1, 0, 0), axis, -axis);
		btQuaternionHingeConstraint q(a, b, btVector3(1, 0, 0), btVector3(-1, 0, 0), axis, -axis);
		for (int pose = 0; pose < 2; ++pose)
		{
			const double angle = q.getHingeAngle();
			EXPECT_GT(angle, -M_PI) << k;
			EXPECT_LE(angle, M_PI) << k;
			EXPECT_NEAR(wrapped(angle - s.getHingeAngle()), 0, 1e-4) << k << " " << pose;
			b.setCenterOfMassTransform(btTransform(twist * twist * turn, btVector3(2, 0, 0)));
		}
	}
}

TEST(StockMeaning, SetAxisOnAJointInAWorld)
{
	// setAxis after some steps, as stock: A's frame takes the axis, B's is re-derived from the current pose; both
	// classes then turn about the new axis.
	Stock s(false, btVector3(0, 0, 1), btVector3(0, -10, 0));
	Quat q(false, btVector3(0, 0, 1), btVector3(0, -10, 0));
	s.world.step(10);
	q.world.step(10);
	btVector3 axis(1, 0, 0);
	s.hinge->setAxis(axis);
	q.hinge->setAxis(axis);
	const btVector3 zS = s.hinge->getBFrame().getBasis().getColumn(2), zQ = q.hinge->getBFrame().getBasis().getColumn(2);
	EXPECT_NEAR((zS - zQ).length(), 0, 1e-4);
	EXPECT_NEAR((s.hinge->getBFrame().getOrigin() - q.hinge->getBFrame().getOrigin()).length(), 0, 1e-4);
	for (int i = 0; i < 60; ++i)
	{
		s.world.step(1);
		q.world.step(1);
	}
	const double sepS = qh_test::separation(*s.base, s.hinge->getAFrame(), *s.wheel, s.hinge->getBFrame());
	const double sepQ = qh_test::separation(*q.base, q.hinge->getAFrame(), *q.wheel, q.hinge->getBFrame());
	std::printf("[ figures  ] after setAxis in a world, 60 steps: pivot separation stock %.3g m, quaternion %.3g m\n",
				sepS, sepQ);
	EXPECT_LT(sepQ, 1e-3);
	EXPECT_NEAR(q.hinge->getHingeAngle(), s.hinge->getHingeAngle(), 0.01);
}

TEST(StockMeaning, FeedbackBreakingAndIterationOverrideWork)
{
	// btTypedConstraint's services through the solver: joint feedback filled, a joint breaks above its threshold,
	// the iteration override is kept.
	auto run = [](auto& w, btJointFeedback& feedback) {
		w.hinge->enableFeedback(true);
		w.hinge->setJointFeedback(&feedback);
		w.hinge->setOverrideNumSolverIterations(30);
		w.world.step(5);
		EXPECT_EQ(w.hinge->getOverrideNumSolverIterations(), 30);
		EXPECT_TRUE(w.hinge->isEnabled());
		const btJointFeedback held = feedback;  // the solver rewrites it every step
		w.hinge->setBreakingImpulseThreshold(btScalar(1e-3));
		w.world.step(1);
		EXPECT_FALSE(w.hinge->isEnabled());  // gravity's 1/6 N·s per step exceeds 1e-3
		feedback = held;
	};
	Stock s(false, btVector3(0, 0, 1), btVector3(0, -10, 0));
	Quat q(false, btVector3(0, 0, 1), btVector3(0, -10, 0));
	btJointFeedback fs, fq;
	run(s, fs);
	run(q, fq);
	// the wheel hangs at its centre: the joint carries its weight (10 N) on body B, as stock reports
	std::printf("[ figures  ] joint feedback force on B: stock %.4f N, quaternion %.4f N\n",
				double(fs.m_appliedForceBodyB.y()), double(fq.m_appliedForceBodyB.y()));
	EXPECT_NEAR(fq.m_appliedForceBodyB.y(), fs.m_appliedForceBodyB.y(), 0.05);
	EXPECT_NEAR(fq.m_appliedForceBodyB.y(), 10, 0.05);
}

TEST(StockMeaning, PivotAlongTheAxisFromTheCentreHoldsAsStock)
{
	// A one-body hinge whose pivot lies 1 m along the hinge axis from the bar's centre, under gravity, with and without
	// a motor (2 rad/s): stock holds the pivot to 2e-10 m; the exact lever arms' axial parts used to couple the point
	// rows to the swing and left 0.043 m after 10 iterations (fillBilateralRows now takes them off by a row operation).
	// 1e-6 m: float round-off of a 1 m arm over 5 s of 60 Hz steps, far below the 0.04 m of the coupling.
	const double kPivotTol = 1e-6;
	for (bool motor : {false, true})
	{
		double worst[2] = {0, 0};
		auto run = [&](auto* tag, int k) {
			using Hinge = std::remove_pointer_t<decltype(tag)>;
			qh_test::World w;
			btRigidBody* bar = w.addBox(1, btVector3(btScalar(0.5), btScalar(0.05), btScalar(0.05)), btTransform::getIdentity());
			const btVector3 pivot(0, 0, 1);
			Hinge* h = w.add(new Hinge(*bar, pivot, btVector3(0, 0, 1)));
			h->enableAngularMotor(motor, 2, 10);
			for (int i = 0; i < 300; ++i)
			{
				w.step(1);
				worst[k] = std::max(worst[k], double((bar->getCenterOfMassTransform()(pivot) - pivot).length()));
			}
		};
		run(static_cast<btHingeConstraint*>(nullptr), 0);
		run(static_cast<btQuaternionHingeConstraint*>(nullptr), 1);
		std::printf("[ figures  ] pivot 1 m along the axis, %s: stock %.3g m, quaternion %.3g m\n",
					motor ? "motor" : "no motor", worst[0], worst[1]);
		EXPECT_LT(worst[0], kPivotTol);
		EXPECT_LT(worst[1], kPivotTol);
	}
}
