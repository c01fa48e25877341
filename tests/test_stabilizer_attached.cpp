// moveAttachedBodies: a body held to a projected body only by constraints the stabilizer does not project (a
// gripper's finger on its slider, a lamp on a point-to-point) moves rigidly with it, so the projection does not
// leave it behind; off (the default) it is not moved. closeAttachedConstraints: such a body held by one constraint of
// a known form (a point, a slider, a weld) is put on it, so that constraint holds like the projected joints.
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/StabilizerScene.h"

#ifdef QUATHINGE_HAVE_SCENES
#include "JointKinds.h"
#include "SceneSpec.h"
#include "Simulation.h"
#include "support/SliderRuns.h"
#endif

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

using namespace qh_test;

namespace
{
// The angle between two orientations (rad), resolved near zero: 2 atan2(|v|, |w|) of the relative quaternion
// conj(a) b, in double. (Bullet's angleShortestPath takes the arc cosine of a dot product: in float a dot product one
// rounding below 1 already reads 6.9e-4 rad, and whether it rounds to 1 or just below is the platform's bits; aarch64's
// fused multiply-adds give the latter.)
double turnBetween(const btQuaternion& a, const btQuaternion& b)
{
	const double aw = a.w(), ax = a.x(), ay = a.y(), az = a.z(), bw = b.w(), bx = b.x(), by = b.y(), bz = b.z();
	const double w = aw * bw + ax * bx + ay * by + az * bz;
	const double x = aw * bx - bw * ax - (ay * bz - az * by), y = aw * by - bw * ay - (az * bx - ax * bz),
				 z = aw * bz - bw * az - (ax * by - ay * bx);
	return 2 * std::atan2(std::sqrt(x * x + y * y + z * z), std::fabs(w));
}

const btScalar kLink = btScalar(0.5);  // m

// A 4-link chain (StabilizerScene::chain) with a lamp hung from its last link by a point-to-point, and, when
// `tiedToWorld`, the lamp also tied to the world by a second point-to-point (then it has two partners).
struct ChainWithLamp
{
	StabilizerScene scene;
	std::vector<btRigidBody*> links;
	btRigidBody* lamp = nullptr;
	btPoint2PointConstraint* cord = nullptr;
	explicit ChainWithLamp(bool tiedToWorld = false)
	{
		links = scene.chain(4);
		const btVector3 end = links.back()->getCenterOfMassTransform() * btVector3(kLink / 2, 0, 0);
		lamp = scene.box(btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)), btScalar(0.5),
						 end - btVector3(0, btScalar(0.3), 0));
		cord = new btPoint2PointConstraint(*links.back(), *lamp, btVector3(kLink / 2, 0, 0), btVector3(0, btScalar(0.3), 0));
		scene.addConstraint(cord);
		if (tiedToWorld)
			scene.addConstraint(new btPoint2PointConstraint(*lamp, btVector3(0, btScalar(-0.1), 0)));
	}
	double cordSeparation() const
	{
		const btVector3 a = links.back()->getCenterOfMassTransform() * cord->getPivotInA();
		const btVector3 b = lamp->getCenterOfMassTransform() * cord->getPivotInB();
		return double((b - a).length());
	}
};

// Attached bodies are those held by constraints the stabilizer does not project: the hinges alone projected.
btQuaternionHingeStabilizerSettings carrying(bool on, bool close = false)
{
	btQuaternionHingeStabilizerSettings s = hingesOnly();
	s.moveAttachedBodies = on;
	s.closeAttachedConstraints = close;
	return s;
}

// The velocity of body's material point at world point p.
btVector3 pointVelocity(const btRigidBody& body, const btVector3& p)
{
	return body.getLinearVelocity() + body.getAngularVelocity().cross(p - body.getCenterOfMassPosition());
}
}  // namespace

TEST(StabilizerAttached, ALampOnAPointToPointMovesWithItsLinkAndKeepsItsPoseRelativeToIt)
{
	// One projection by hand after Bullet's steps have pulled the chain apart: the lamp's pose and velocity relative
	// to its link are what Bullet left them (to rounding), the chain is closed, and the lamp was counted
	ChainWithLamp w;
	btQuaternionHingeStabilizer stabilizer(carrying(true));
	for (int i = 0; i < 30; ++i) w.scene.world().stepSimulation(kTimeStep, 0, kTimeStep);
	double separation = 0, misalignment = 0;
	w.scene.jointErrors(separation, misalignment);
	ASSERT_GT(separation, 1e-3) << "the test needs a chain Bullet's solver left apart";
	btRigidBody& host = *w.links.back();
	const btTransform relativeBefore = host.getCenterOfMassTransform().inverse() * w.lamp->getCenterOfMassTransform();
	const btVector3 relativeSpinBefore = w.lamp->getAngularVelocity() - host.getAngularVelocity();
	const double cordBefore = w.cordSeparation();
	const btQuaternionHingeStabilizerStats& stats = stabilizer.stabilize(&w.scene.world(), kTimeStep);
	w.scene.jointErrors(separation, misalignment);
	EXPECT_LE(separation, kSeparationTolerance);
	EXPECT_EQ(stats.attachedBodiesMoved, 1);
	const btTransform relativeAfter = host.getCenterOfMassTransform().inverse() * w.lamp->getCenterOfMassTransform();
	// m and rad: rounding of poses a few metres from the origin (float: ~1e-6)
	const double kKept = 20 * double(SIMD_EPSILON) * 10;
	EXPECT_LT(double((relativeAfter.getOrigin() - relativeBefore.getOrigin()).length()), kKept);
	EXPECT_LT(double(relativeAfter.getRotation().angleShortestPath(relativeBefore.getRotation())), kKept);
	EXPECT_NEAR(w.cordSeparation(), cordBefore, kKept) << "the cord keeps the error Bullet's solver left";
	// its spin relative to the link, turned with the link, has the same size
	const btVector3 relativeSpinAfter = w.lamp->getAngularVelocity() - host.getAngularVelocity();
	EXPECT_NEAR(double(relativeSpinAfter.length()), double(relativeSpinBefore.length()), 1e-4);
}

TEST(StabilizerAttached, OffTheLampIsLeftWhereItIs)
{
	// the default: the lamp is not moved (bit for bit), so its cord takes up the link's correction
	ChainWithLamp w;
	btQuaternionHingeStabilizer stabilizer(carrying(false));
	EXPECT_FALSE(stabilizer.getSettings().moveAttachedBodies);
	EXPECT_FALSE(stabilizer.getSettings().closeAttachedConstraints);
	for (int i = 0; i < 30; ++i) w.scene.world().stepSimulation(kTimeStep, 0, kTimeStep);
	const btTransform before = w.lamp->getCenterOfMassTransform();
	const double cordBefore = w.cordSeparation();
	const btQuaternionHingeStabilizerStats& stats = stabilizer.stabilize(&w.scene.world(), kTimeStep);
	EXPECT_EQ(stats.attachedBodiesMoved, 0);
	EXPECT_EQ(stats.attachedConstraintsClosed, 0);
	EXPECT_TRUE(w.lamp->getCenterOfMassTransform() == before);
	const double kOpened = 1e-3;  // m: the chain's end moves by more than this, and the cord with it
	EXPECT_GT(std::fabs(w.cordSeparation() - cordBefore), kOpened);
}

TEST(StabilizerAttached, ABodyWithASecondPartnerIsNotCarried)
{
	// tied to the world as well, the lamp cannot follow its link without tearing the other tie: left alone
	ChainWithLamp w(true);
	btQuaternionHingeStabilizer stabilizer(carrying(true));
	for (int i = 0; i < 30; ++i) w.scene.world().stepSimulation(kTimeStep, 0, kTimeStep);
	const btTransform before = w.lamp->getCenterOfMassTransform();
	EXPECT_EQ(stabilizer.stabilize(&w.scene.world(), kTimeStep).attachedBodiesMoved, 0);
	EXPECT_TRUE(w.lamp->getCenterOfMassTransform() == before);
}

TEST(StabilizerAttached, ClosingPutsTheLampBackOnItsCord)
{
	// One projection by hand after Bullet's steps have pulled the chain and the cord apart: with closing, the cord's
	// pivots meet and move together (its relative velocity taken out by an impulse on the lamp alone, which takes
	// kinetic energy out, never in), in both orders of the settings' work (carried first, or not carried)
	for (bool carry : {true, false})
	{
		ChainWithLamp w;
		btQuaternionHingeStabilizer stabilizer(carrying(carry, true));
		for (int i = 0; i < 30; ++i) w.scene.world().stepSimulation(kTimeStep, 0, kTimeStep);
		ASSERT_GT(w.cordSeparation(), 1e-3) << "the test needs a cord Bullet's solver left apart";
		btRigidBody& host = *w.links.back();
		const btQuaternionHingeStabilizerStats& stats = stabilizer.stabilize(&w.scene.world(), kTimeStep);
		EXPECT_EQ(stats.attachedConstraintsClosed, 1);
		EXPECT_EQ(stats.attachedBodiesMoved, carry ? 1 : 0);
		double separation = 0, misalignment = 0;
		w.scene.jointErrors(separation, misalignment);
		EXPECT_LE(separation, kSeparationTolerance);
		EXPECT_LE(w.cordSeparation(), kSeparationTolerance) << (carry ? "carried" : "not carried");
		const btVector3 pivot = host.getCenterOfMassTransform() * w.cord->getPivotInA();
		const double kStill = 1e-5;  // m/s: the pivots' relative velocity after the impulse (float rounding)
		EXPECT_LE(double((pointVelocity(*w.lamp, pivot) - pointVelocity(host, pivot)).length()), kStill);
	}
}

TEST(StabilizerAttached, ALampWithANonFiniteVelocityIsNotClosed)
{
	// a lamp handed a NaN velocity from outside: closing would carry the NaN into its pose (the impulse, then the
	// state), so it is left as it is and not counted; the chain is still projected
	ChainWithLamp w;
	btQuaternionHingeStabilizer stabilizer(carrying(false, true));
	for (int i = 0; i < 30; ++i) w.scene.world().stepSimulation(kTimeStep, 0, kTimeStep);
	w.lamp->setLinearVelocity(btVector3(std::numeric_limits<btScalar>::quiet_NaN(), 0, 0));
	const btTransform before = w.lamp->getCenterOfMassTransform();
	const btVector3 spin = w.lamp->getAngularVelocity();
	const btQuaternionHingeStabilizerStats& stats = stabilizer.stabilize(&w.scene.world(), kTimeStep);
	EXPECT_EQ(stats.attachedConstraintsClosed, 0);
	EXPECT_TRUE(w.lamp->getCenterOfMassTransform() == before);
	EXPECT_TRUE(w.lamp->getAngularVelocity() == spin);
	double separation = 0, misalignment = 0;
	w.scene.jointErrors(separation, misalignment);
	EXPECT_LE(separation, kSeparationTolerance);
}

TEST(StabilizerAttached, AWeldAndASixDofWithItsOffsetLockedHoldWhenClosed)
{
	// Two other forms, on the same 4-link chain over 1 s at 60 Hz: a tool welded to the last link by a btFixedConstraint
	// whose body A is the tool (the host is B: the other side of the code), and a weight on a btGeneric6DofSpring2Constraint
	// with its three linear axes locked at an offset of 0.2 m along frame A's y and its angles free (low > high, Bullet's
	// "free"): a point at that offset. Closed, both hold like the hinges; without the stabilizer they part by more
	// than a millimetre
	const auto run = [](bool stabilize) {
		StabilizerScene scene;
		std::vector<btRigidBody*> links = scene.chain(4);
		btRigidBody& end = *links.back();
		const btVector3 tip = end.getCenterOfMassTransform() * btVector3(kLink / 2, 0, 0);
		btRigidBody* tool = scene.box(btVector3(btScalar(0.2), btScalar(0.05), btScalar(0.05)), btScalar(0.4),
									  tip + btVector3(btScalar(0.2), 0, 0));
		btTransform inTool(btMatrix3x3::getIdentity(), btVector3(btScalar(-0.2), 0, 0));
		btTransform inEnd(btMatrix3x3::getIdentity(), btVector3(kLink / 2, 0, 0));
		auto* weld = new btFixedConstraint(*tool, end, inTool, inEnd);
		scene.addConstraint(weld);
		btRigidBody* weight = scene.box(btVector3(btScalar(0.05), btScalar(0.05), btScalar(0.05)), btScalar(0.3),
										end.getCenterOfMassPosition() + btVector3(0, btScalar(0.2), 0));
		btTransform atCentre;
		atCentre.setIdentity();
		auto* six = new btGeneric6DofSpring2Constraint(end, *weight, atCentre, atCentre);
		six->setLinearLowerLimit(btVector3(0, btScalar(0.2), 0));
		six->setLinearUpperLimit(btVector3(0, btScalar(0.2), 0));
		six->setAngularLowerLimit(btVector3(1, 1, 1));
		six->setAngularUpperLimit(btVector3(-1, -1, -1));
		scene.addConstraint(six);
		btQuaternionHingeStabilizer stabilizer(carrying(true, true));
		if (stabilize) scene.addAction(&stabilizer);
		double weldWorst = 0, weldTurn = 0, sixWorst = 0;
		int closed = 0;
		for (int i = 0; i < 60; ++i)
		{
			scene.world().stepSimulation(kTimeStep, 0, kTimeStep);
			const btTransform a = tool->getCenterOfMassTransform() * inTool, b = end.getCenterOfMassTransform() * inEnd;
			weldWorst = std::max(weldWorst, double((a.getOrigin() - b.getOrigin()).length()));
			weldTurn = std::max(weldTurn, turnBetween(a.getRotation(), b.getRotation()));
			const btVector3 offset = end.getCenterOfMassTransform().getBasis().transpose() *
									 (weight->getCenterOfMassPosition() - end.getCenterOfMassPosition());
			sixWorst = std::max(sixWorst, double((offset - btVector3(0, btScalar(0.2), 0)).length()));
			closed = stabilizer.getLastStats().attachedConstraintsClosed;
		}
		if (stabilize) scene.world().removeAction(&stabilizer);
		return std::vector<double>{weldWorst, weldTurn, sixWorst, double(closed)};
	};
	const std::vector<double> bare = run(false), held = run(true);
	std::printf(
		"[ measured ] weld apart / turned, 6-dof off its offset, max over 1 s: no stabilizer %.3g m, %.3g rad, "
		"%.3g m; closed %.3g m, %.3g rad, %.3g m\n",
		bare[0], bare[1], bare[2], held[0], held[1], held[2]);
	ASSERT_GT(bare[0], 1e-3) << "the test needs a weld Bullet's solver leaves apart";
	ASSERT_GT(bare[2], 1e-3) << "the test needs a 6-dof Bullet's solver leaves off its offset";
	EXPECT_EQ(held[3], 2);
	EXPECT_LE(held[0], kSeparationTolerance);
	EXPECT_LE(held[1], kSeparationTolerance);  // rad
	EXPECT_LE(held[2], kSeparationTolerance);
}

TEST(StabilizerAttached, OverARunTheCordHoldsAsWithoutTheStabilizer)
{
	// 3 s at 60 Hz as a world action: the cord's largest separation with the carried lamp is within 1.2 × the world
	// without a stabilizer (plus 1 mm); left behind, it is several times that; closed, it holds like the hinges
	const auto run = [](int mode) {  // 0: no stabilizer, 1: stabilizer, 2: carrying the lamp, 3: closing its cord
		ChainWithLamp w;
		btQuaternionHingeStabilizer stabilizer(carrying(mode == 2, mode == 3));
		if (mode > 0) w.scene.addAction(&stabilizer);
		double worst = 0;
		for (int i = 0; i < 180; ++i)
		{
			w.scene.world().stepSimulation(kTimeStep, 0, kTimeStep);
			worst = std::max(worst, w.cordSeparation());
		}
		if (mode > 0) w.scene.world().removeAction(&stabilizer);
		return worst;
	};
	const double bare = run(0), leftBehind = run(1), carried = run(2), closed = run(3);
	std::printf(
		"[ measured ] cord separation, max over 3 s: no stabilizer %.3g m, stabilizer %.3g m, carried %.3g m, "
		"closed %.3g m\n",
		bare, leftBehind, carried, closed);
	EXPECT_LE(carried, 1.2 * bare + 1e-3);
	EXPECT_GT(leftBehind, carried);
	EXPECT_LE(closed, kSeparationTolerance);
}

#if defined(QUATHINGE_HAVE_SCENES) && defined(QUATHINGE_HAVE_URDF)  // panda.urdf (urdfdom is optional)
TEST(StabilizerAttached, PandasFingersAreNotLeftBehindByTheStabilizer)
{
	// Bullet's Franka Panda (demos/models): its fingers hang from the hand by prismatic joints (6-dof sliders, not
	// projected); 3 s at 60 Hz, 10 iterations. Measured in float: the fingers off their slide line by 5.3e-2 m with
	// the stabilizer, 1.7e-2 m with it carrying them, 7.7e-8 m carrying them and closing their sliders; 1.1e-2 m in
	// the bare quaternion world, whose arm Bullet's solver leaves 0.58 m apart (another motion: printed, and only
	// the closed fingers, which hold like the hinges, are asserted against it)
	using namespace quathinge::scenes;
	const SceneSpec panda = makeScene("panda");
	ASSERT_TRUE(panda.unavailable.empty()) << panda.unavailable;
	ASSERT_EQ(panda.sliders.size(), 2u);
	const auto run = [&](Kind kind, bool carry, bool close = false) {
		const qh_test::SliderRunErrors e = qh_test::runWithSliders(panda, kind, carrying(carry, close));
		return std::make_pair(e.sliders, e.hinges);
	};
	const auto bare = run(Kind::Quaternion, false);
	const auto leftBehind = run(Kind::QuaternionStabilized, false);
	const auto carried = run(Kind::QuaternionStabilized, true);
	const auto closed = run(Kind::QuaternionStabilized, true, true);
	std::printf(
		"[ measured ] panda fingers off their slides: bare %.3g m, stabilizer %.3g m, carried %.3g m, "
		"closed %.3g m (hinges %.3g, %.3g, %.3g, %.3g m)\n",
		bare.first, leftBehind.first, carried.first, closed.first, bare.second, leftBehind.second,
		carried.second, closed.second);
	EXPECT_LE(carried.second, 1e-4);  // m: the stabilizer still holds every hinge (the scene test's bound)
	EXPECT_GT(leftBehind.first, 2 * carried.first) << "carrying them at least halves how far they are left behind";
	// closed, the fingers hold their slide line like the projected hinges (the scene test's bound), far inside the
	// bare world's, and the hinges still hold
	EXPECT_LE(closed.first, 1e-4);
	EXPECT_LT(closed.first, bare.first);
	EXPECT_LE(closed.second, 1e-4);
}
#endif
#endif
