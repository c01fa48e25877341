// projectLockedConstraints: the stabilizer also projects 6-dofs whose angles are locked at 0 — sliders and welds —
// as rows of the hinges' islands (plugin/stabilizer/LockedRows.h). Their rows are the exact derivative of their C
// (finite differences), the projection holds them with the hinges and leaves a slider's free axis alone (momentum
// along it and every body's momentum in sum conserved), an island at rest is replayed until a locked value changes,
// and Bullet's Panda keeps its fingers on their slides.
#ifdef QUATHINGE_HAVE_STABILIZER
#include "LockedRows.h"
#include "support/LockedDofError.h"
#include "support/RandomPoses.h"
#include "support/RowDerivatives.h"
#include "support/StabilizerScene.h"
#include "support/World.h"

#ifdef QUATHINGE_HAVE_SCENES
#include "JointKinds.h"
#include "SceneSpec.h"
#include "Simulation.h"
#include "support/SliderRuns.h"
#endif

#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

using namespace qh_test;

namespace
{
const btScalar kLink = btScalar(0.5);  // m, link length

// A slider along frame A's x (y, z locked at `offsetY`, 0; x free between ±0.2 m), angles locked: a prismatic joint as
// pybullet builds it.
btGeneric6DofSpring2Constraint* slider(btRigidBody& a, btRigidBody& b, const btTransform& fa, const btTransform& fb,
									   btScalar offsetY = 0)
{
	auto* s = new btGeneric6DofSpring2Constraint(a, b, fa, fb);
	s->setLinearLowerLimit(btVector3(btScalar(-0.2), offsetY, 0));
	s->setLinearUpperLimit(btVector3(btScalar(0.2), offsetY, 0));
	s->setAngularLowerLimit(btVector3(0, 0, 0));
	s->setAngularUpperLimit(btVector3(0, 0, 0));
	return s;
}

// A locked 6-dof's error, measured here from its frames independently of LockedRows.h: the largest distance (m) of B's
// pivot from where its locked axes put it (A's pivot plus the locked values, free axes as they are), and the angle
// (rad) between the two frames.
void lockedError(btGeneric6DofSpring2Constraint& c, double& distance, double& angle)
{
	btVector3 low, high;
	c.getLinearLowerLimit(low);
	c.getLinearUpperLimit(high);
	const btTransform fa = c.getRigidBodyA().getCenterOfMassTransform() * c.getFrameOffsetA();
	const btTransform fb = c.getRigidBodyB().getCenterOfMassTransform() * c.getFrameOffsetB();
	const btVector3 local = fa.getBasis().transpose() * (fb.getOrigin() - fa.getOrigin());
	btVector3 off(0, 0, 0);
	for (int i = 0; i < 3; ++i)
		if (low[i] == high[i]) off[i] = local[i] - low[i];
	distance = double(off.length());
	btQuaternion qa, qb;
	fa.getBasis().getRotation(qa);
	fb.getBasis().getRotation(qb);
	// 2 atan2(|q_v|, |w|) of the relative rotation: exact for small angles (acos of the dot product loses half the
	// digits there)
	const btQuaternion q = qa.inverse() * qb;
	angle = 2 * std::atan2(std::sqrt(double(q.x()) * q.x() + double(q.y()) * q.y() + double(q.z()) * q.z()),
						   std::fabs(double(q.w())));
}

// A 6-dof of either family locked as a slider or weld: linear axis i at lock[i] where bit i of `pattern` is set, else
// free; the angles at 0.
template <class Dof>
void lockAxes(Dof& c, const btVector3& lock, int pattern)
{
	btVector3 low(1, 1, 1), high(-1, -1, -1);
	for (int i = 0; i < 3; ++i)
		if (pattern & (1 << i)) low[i] = high[i] = lock[i];
	c.setLinearLowerLimit(low);
	c.setLinearUpperLimit(high);
	c.setAngularLowerLimit(btVector3(0, 0, 0));
	c.setAngularUpperLimit(btVector3(0, 0, 0));
}

}  // namespace

TEST(StabilizerLocked, RowsAreTheDerivativeOfC)
{
	// Central differences of C under small translations and rotations of either body against J's columns, over seeded
	// random bodies, frames and locks: near the locked pose and up to 2 rad off it (support/RowDerivatives.h: the step
	// and the tolerance).
	RandomPoses p(7);
	int checked = 0;
	for (int n = 0; n < 200; ++n)
	{
		const btTransform fa(p.unit(), p.vec(0.3)), fb(p.unit(), p.vec(0.3));
		std::unique_ptr<btGeneric6DofSpring2Constraint> c(new btGeneric6DofSpring2Constraint(p.a, p.b, fa, fb));
		const btVector3 lock = p.vec(0.1);
		const int pattern = n % 8;  // which linear axes are locked
		lockAxes(*c, lock, pattern);
		ASSERT_TRUE(quathinge::stabilizer::hasLockedRows(quathinge::stabilizer::dofLocks(*c)));
		// B placed so its frame is within 0.3 rad of A's (near) or anywhere up to 2 rad (far), 0.2 m off
		const btTransform tA(p.unit(), p.vec(2));
		const double reach = n % 2 ? 0.3 : 2.0;
		const btQuaternion turn = expRotation(p.vec(reach / std::sqrt(3.0)));
		const btTransform frameAWorld = tA * fa;
		const btTransform frameBWorld(turn * frameAWorld.getRotation(), frameAWorld.getOrigin() + p.vec(0.2));
		const btTransform tB = frameBWorld * fb.inverse();
		btScalar C[6], J[72];
		const int rows = quathinge::stabilizer::lockedPositionRows(*c, tA, tB, C, J);
		ASSERT_EQ(rows, 3 + (pattern & 1) + ((pattern >> 1) & 1) + ((pattern >> 2) & 1));
		// the rotation's w near 0 switches the sign of C (w ≥ 0 is taken): no derivative there
		btQuaternion rel = frameAWorld.getRotation().inverse() * frameBWorld.getRotation();
		if (std::fabs(double(rel.getW())) < 0.2) continue;
		auto values = [&](const btTransform& ta, const btTransform& tb, double* out) {
			btScalar Cx[6], Jx[72];
			quathinge::stabilizer::lockedPositionRows(*c, ta, tb, Cx, Jx);
			for (int r = 0; r < rows; ++r) out[r] = double(Cx[r]);
		};
		auto derivative = [&](int r, int column) { return double(J[12 * r + column]); };
		expectRowDerivatives(values, derivative, tA, tB, rows, "configuration " + std::to_string(n));
		++checked;
	}
	EXPECT_GT(checked, 150);
}

namespace
{
// A 4-link chain released horizontally at 10 m: hinge (z) to the world, a slider along the chain (x free), a hinge
// (y), and a weld (btFixedConstraint) to a small tool.
struct SliderChain
{
	StabilizerScene scene;
	btGeneric6DofSpring2Constraint* slide;
	btFixedConstraint* weld;
	SliderChain()
	{
		std::vector<btRigidBody*> links;
		for (int i = 0; i < 3; ++i)
			links.push_back(scene.box(btVector3(kLink / 2, btScalar(0.05), btScalar(0.05)), 1,
									  btVector3(kLink * (btScalar(i) + btScalar(0.5)), 10, 0)));
		const btVector3 left(-kLink / 2, 0, 0), right(kLink / 2, 0, 0);
		scene.hingeToWorld(*links[0], left, btVector3(0, 0, 1));
		btTransform fa = btTransform::getIdentity(), fb = btTransform::getIdentity();
		fa.setOrigin(right);
		fb.setOrigin(left);
		slide = slider(*links[0], *links[1], fa, fb);
		scene.addConstraint(slide);
		scene.hinge(*links[1], *links[2], right, left, btVector3(0, 1, 0), btVector3(0, 1, 0));
		btRigidBody* tool = scene.box(btVector3(btScalar(0.05), btScalar(0.05), btScalar(0.05)), btScalar(0.2),
									  btVector3(3 * kLink + btScalar(0.05), 10, 0));
		btTransform ta = btTransform::getIdentity(), tb = btTransform::getIdentity();
		ta.setOrigin(right);
		tb.setOrigin(btVector3(btScalar(-0.05), 0, 0));
		weld = new btFixedConstraint(*links[2], *tool, ta, tb);
		scene.addConstraint(weld);
	}
	// Steps 2 s: the largest hinge separation and locked distance (m) and angle (rad) after any step.
	void run(double& hinges, double& distance, double& angle)
	{
		hinges = distance = angle = 0;
		for (int i = 0; i < 120; ++i)
		{
			scene.world().stepSimulation(kTimeStep, 0);
			double separation, misalignment, d, a;
			scene.jointErrors(separation, misalignment);
			hinges = std::max(hinges, separation);
			for (btGeneric6DofSpring2Constraint* c : {slide, static_cast<btGeneric6DofSpring2Constraint*>(weld)})
			{
				lockedError(*c, d, a);
				distance = std::max(distance, d);
				angle = std::max(angle, a);
			}
		}
	}
};

btQuaternionHingeStabilizerSettings withLocked()
{
	btQuaternionHingeStabilizerSettings s = hingesOnly();
	s.projectLockedConstraints = true;
	return s;
}
}  // namespace

TEST(StabilizerLocked, SliderAndWeldHoldWithTheHingesWithTheOptionAndNotWithout)
{
	SliderChain on, off;
	btQuaternionHingeStabilizer locked(withLocked()), hingesOnly(qh_test::hingesOnly());
	on.scene.addAction(&locked);
	off.scene.addAction(&hingesOnly);
	double onHinges, onDistance, onAngle, offHinges, offDistance, offAngle;
	on.run(onHinges, onDistance, onAngle);
	off.run(offHinges, offDistance, offAngle);
	std::printf(
		"[ figures  ] slider chain, largest error: option on hinges %.2e m, locked %.2e m %.2e rad; off hinges "
		"%.2e m, locked %.2e m %.2e rad\n",
		onHinges, onDistance, onAngle, offHinges, offDistance, offAngle);
	EXPECT_EQ(locked.getLastStats().joints, 4);
	EXPECT_EQ(locked.getLastStats().islands, 1);
	EXPECT_EQ(hingesOnly.getLastStats().joints, 2);
	EXPECT_LE(onHinges, kSeparationTolerance);
	EXPECT_LE(onDistance, kSeparationTolerance);
	EXPECT_LE(onAngle, 10 * kSeparationTolerance);       // rad: the tolerance of an angular row (float: 1e-5 m ↔ 1e-4 rad)
	EXPECT_GT(offDistance, 100 * kSeparationTolerance);  // the solver alone leaves them apart
	EXPECT_EQ(locked.getLastStats().numericalIssues, 0);
	ASSERT_TRUE(on.scene.allFinite());
}

TEST(StabilizerLocked, OlderSixDofLocksMeanWhatBulletMeasures)
{
	// The rows of a btGeneric6DofConstraint (and so of btGeneric6DofSpringConstraint) weld or slider, against the
	// older 6-dof's own measure at the same transforms (calculateTransforms): each locked linear row's C is Bullet's
	// getRelativePivotPosition less the locked value, to rounding, whichever frame its rows are built along; the three
	// angular rows' C (2 q_v, frame A's coordinates) is its Euler angles (getAngle) to first order, so within the
	// square of the turn near the lock, with the opposite sign (the older 6-dof reads its relative rotation's elements
	// transposed, btGetMatrixElem: B turned by +θ about frame A's x reads −θ; only the locks at 0 are taken, which mean
	// the same either way). Seeded random frames, locks and poses within 0.01 rad and 1 cm of the lock.
	RandomPoses p(11);
	const double linearTolerance = kDouble ? 1e-12 : 2e-6;  // m: rounding of coordinates up to a few metres
	for (int n = 0; n < 100; ++n)
	{
		const btTransform fa(p.unit(), p.vec(0.3)), fb(p.unit(), p.vec(0.3));
		std::unique_ptr<btGeneric6DofConstraint> c(new btGeneric6DofConstraint(p.a, p.b, fa, fb, n % 2 == 0));
		const btVector3 lock = p.vec(0.1);
		const int pattern = n % 8;  // which linear axes are locked
		lockAxes(*c, lock, pattern);
		const quathinge::stabilizer::DofLocks locks = quathinge::stabilizer::dofLocks(*c);
		ASSERT_TRUE(quathinge::stabilizer::hasLockedRows(locks));
		// B where the locks put it, then turned by up to 0.01 rad and moved by up to 1 cm
		const btTransform tA(p.unit(), p.vec(2));
		const btTransform frameAWorld = tA * fa;
		const btVector3 turn = p.vec(0.01 / std::sqrt(3.0));
		const btTransform frameBWorld(expRotation(turn) * frameAWorld.getRotation(),
									  frameAWorld * btVector3(lock.x() * (pattern & 1), lock.y() * ((pattern >> 1) & 1),
															  lock.z() * ((pattern >> 2) & 1)) +
										  p.vec(0.01));
		const btTransform tB = frameBWorld * fb.inverse();
		btScalar C[6], J[72];
		const int rows = quathinge::stabilizer::lockedPositionRows(*c, tA, tB, C, J);
		ASSERT_EQ(rows, 3 + (pattern & 1) + ((pattern >> 1) & 1) + ((pattern >> 2) & 1));
		c->calculateTransforms(tA, tB);
		int r = 0;
		for (int i = 0; i < 3; ++i)
			if (pattern & (1 << i))
			{
				EXPECT_NEAR(double(C[r]), double(c->getRelativePivotPosition(i) - lock[i]), linearTolerance)
					<< "configuration " << n << ", linear axis " << i;
				++r;
			}
		const double turned = double(turn.length());
		for (int i = 0; i < 3; ++i)
			EXPECT_NEAR(double(C[r + i]), -double(c->getAngle(i)), turned * turned + (kDouble ? 1e-12 : 1e-6))
				<< "configuration " << n << ", angle " << i;
	}
}

namespace
{
// A 4-link chain released horizontally at 10 m, its joints from Bullet's older 6-dof family, as apps made them before
// btGeneric6DofSpring2Constraint: a quaternion hinge (z) to the world, then a btGeneric6DofConstraint weld held 2 cm
// off along its frame's y, a btGeneric6DofSpringConstraint slider (x free within ±0.2 m, a spring on it), and a
// btGeneric6DofConstraint ball (angles free) whose rows Bullet builds along frame B (useLinearReferenceFrameA false).
struct OldDofChain
{
	StabilizerScene scene;
	btGeneric6DofConstraint *weld, *ball;
	btGeneric6DofSpringConstraint* slide;
	OldDofChain()
	{
		std::vector<btRigidBody*> links;
		for (int i = 0; i < 4; ++i)
			links.push_back(scene.box(btVector3(kLink / 2, btScalar(0.05), btScalar(0.05)), 1,
									  btVector3(kLink * (btScalar(i) + btScalar(0.5)), btScalar(10) + (i >= 2 ? btScalar(0.02) : 0), 0)));
		const btVector3 left(-kLink / 2, 0, 0), right(kLink / 2, 0, 0);
		scene.hingeToWorld(*links[0], left, btVector3(0, 0, 1));
		btTransform fa = btTransform::getIdentity(), fb = btTransform::getIdentity();
		fa.setOrigin(right);
		fb.setOrigin(left);
		weld = new btGeneric6DofConstraint(*links[0], *links[1], fa, fb, true);
		weld->setLinearLowerLimit(btVector3(0, 0, 0));
		weld->setLinearUpperLimit(btVector3(0, 0, 0));
		weld->setAngularLowerLimit(btVector3(0, 0, 0));
		weld->setAngularUpperLimit(btVector3(0, 0, 0));
		scene.addConstraint(weld);
		// (links 2 and 3 start 2 cm up: the weld above holds link 1 level, the slider's y lock is at 2 cm)
		slide = new btGeneric6DofSpringConstraint(*links[1], *links[2], fa, fb, true);
		slide->setLinearLowerLimit(btVector3(btScalar(-0.2), btScalar(0.02), 0));
		slide->setLinearUpperLimit(btVector3(btScalar(0.2), btScalar(0.02), 0));
		slide->setAngularLowerLimit(btVector3(0, 0, 0));
		slide->setAngularUpperLimit(btVector3(0, 0, 0));
		slide->enableSpring(0, true);
		slide->setStiffness(0, 50);
		scene.addConstraint(slide);
		ball = new btGeneric6DofConstraint(*links[2], *links[3], fa, fb, false);
		ball->setLinearLowerLimit(btVector3(0, 0, 0));
		ball->setLinearUpperLimit(btVector3(0, 0, 0));
		ball->setAngularLowerLimit(btVector3(1, 1, 1));  // low > high: free
		ball->setAngularUpperLimit(btVector3(-1, -1, -1));
		scene.addConstraint(ball);
		links[3]->setAngularVelocity(btVector3(3, 0, 2));  // rad/s: the last link whips out of the plane
	}
	// Steps 2 s: the largest error (m, rad) of the three 6-dofs after any step, as Bullet's 6-dof measures it itself
	// (calculateTransforms: getRelativePivotPosition, frame A's axes · (p_B − p_A), against each locked value; getAngle,
	// its Euler angles, against the locks at 0), and the largest hinge separation (m).
	void run(double& hinge, double& distance, double& angle)
	{
		hinge = distance = angle = 0;
		for (int i = 0; i < 120; ++i)
		{
			scene.world().stepSimulation(kTimeStep, 0);
			double separation, misalignment;
			scene.jointErrors(separation, misalignment);
			hinge = std::max(hinge, separation);
			for (btGeneric6DofConstraint* c : {weld, static_cast<btGeneric6DofConstraint*>(slide), ball})
				lockedDofError(*c, distance, angle);
		}
	}
};
}  // namespace

TEST(StabilizerLocked, OlderSixDofWeldSliderAndBallHoldWithTheDefaults)
{
	// btGeneric6DofConstraint and btGeneric6DofSpringConstraint lock an axis as btGeneric6DofSpring2Constraint does (low
	// == high) and measure a locked linear axis the same way (frame A's axes), so with the defaults a weld and a slider
	// are locked constraints and a ball a point constraint, as the newer class's are; none is skipped as unexpressible
	// (the weld was, before). Bullet's own measure of each 6-dof's error is the reference.
	OldDofChain bare, held;
	btQuaternionHingeStabilizer stabilizer;  // the defaults
	held.scene.addAction(&stabilizer);
	double bareHinge, bareDistance, bareAngle, hinge, distance, angle;
	bare.run(bareHinge, bareDistance, bareAngle);
	held.run(hinge, distance, angle);
	std::printf(
		"[ figures  ] older 6-dofs (weld, slider, ball), largest error over 2 s: stabilized %.2e m %.2e rad (hinge "
		"%.2e m); bare %.2e m %.2e rad (hinge %.2e m)\n",
		distance, angle, hinge, bareDistance, bareAngle, bareHinge);
	const btQuaternionHingeStabilizerStats& stats = stabilizer.getLastStats();
	EXPECT_EQ(stats.skippedUnexpressible, 0);
	EXPECT_EQ(stats.skippedByOption, 0);
	EXPECT_EQ(stats.lockedConstraints, 2);  // the weld and the slider
	EXPECT_EQ(stats.pointConstraints, 1);   // the ball
	EXPECT_EQ(stats.joints, 4);
	EXPECT_EQ(stats.islands, 1);
	EXPECT_LE(distance, kSeparationTolerance);
	EXPECT_LE(angle, 10 * kSeparationTolerance);  // rad, as above
	EXPECT_LE(hinge, kSeparationTolerance);
	EXPECT_GT(bareDistance, 100 * kSeparationTolerance);  // Bullet's solver alone leaves them apart
	EXPECT_EQ(stats.numericalIssues, 0);
	ASSERT_TRUE(held.scene.allFinite());
}

TEST(StabilizerLocked, SliderConstraintLocksMeanWhatBulletMeasures)
{
	// A btSliderConstraint with its turn locked at 0 (Bullet's default) is projected as a 6-dof slider: its rows' C
	// against the slider's own measure at the same transforms (calculateTransforms, testLinLimits, testAngLimits):
	// the slide, where locked, is getLinearPos less the locked value (measured from B's origin to A's without
	// useLinearReferenceFrameA, so with the other sign), B's origin off the slide line is 0 in Bullet's calculated
	// frame A, and the turn about the axis is getAngularPos to first order. Seeded random frames and poses within
	// 0.01 rad and 1 cm of the lock.
	RandomPoses p(13);
	const double linearTolerance = kDouble ? 1e-12 : 2e-6;  // m, as above
	for (int n = 0; n < 100; ++n)
	{
		const btTransform fa(p.unit(), p.vec(0.3)), fb(p.unit(), p.vec(0.3));
		const bool referenceA = n % 2 == 0, slideLocked = n % 4 < 2;
		std::unique_ptr<btSliderConstraint> c(new btSliderConstraint(p.a, p.b, fa, fb, referenceA));
		const btScalar lock = btScalar(0.1 * p.number());
		if (slideLocked)
		{
			c->setLowerLinLimit(lock);
			c->setUpperLinLimit(lock);
		}
		const quathinge::stabilizer::DofLocks locks = quathinge::stabilizer::dofLocks(*c);
		ASSERT_TRUE(quathinge::stabilizer::hasLockedRows(locks));
		const btTransform tA(p.unit(), p.vec(2));
		const btTransform frameAWorld = tA * fa;
		const btVector3 turn = p.vec(0.01 / std::sqrt(3.0));
		const btScalar along = slideLocked ? (referenceA ? lock : -lock) : btScalar(0.2 * p.number());
		const btTransform frameBWorld(expRotation(turn) * frameAWorld.getRotation(),
									  frameAWorld * btVector3(along, 0, 0) + p.vec(0.01));
		const btTransform tB = frameBWorld * fb.inverse();
		btScalar C[6], J[72];
		const int rows = quathinge::stabilizer::lockedPositionRows(*c, tA, tB, C, J);
		ASSERT_EQ(rows, slideLocked ? 6 : 5);
		c->calculateTransforms(tA, tB);
		c->testLinLimits();
		c->testAngLimits();
		int r = 0;
		if (slideLocked)
		{
			EXPECT_NEAR(double(C[r]), (referenceA ? 1 : -1) * double(c->getLinearPos() - lock), linearTolerance)
				<< "configuration " << n;
			++r;
		}
		const btTransform& ca = c->getCalculatedTransformA();
		const btVector3 d = c->getCalculatedTransformB().getOrigin() - ca.getOrigin();
		for (int i = 1; i < 3; ++i, ++r)
			EXPECT_NEAR(double(C[r]), double(d.dot(ca.getBasis().getColumn(i))), linearTolerance)
				<< "configuration " << n << ", axis " << i;
		const double turned = double(turn.length());
		EXPECT_NEAR(double(C[r]), double(c->getAngularPos()), turned * turned + (kDouble ? 1e-12 : 1e-6))
			<< "configuration " << n;
	}
}

TEST(StabilizerLocked, SliderConstraintHoldsWithTheDefaults)
{
	// The 4-link chain above with a btSliderConstraint (Bullet's default: the turn locked at 0; the slide within ±0.2
	// m) in place of the weld: held with the defaults, not skipped; its error as Bullet's slider measures it (B's
	// origin off the slide line and the turn about it, getAngularPos; the two frames' x axes apart).
	auto build = [](OldDofChain& chain) {
		chain.scene.world().removeConstraint(chain.weld);
		btTransform fa = btTransform::getIdentity(), fb = btTransform::getIdentity();
		fa.setOrigin(btVector3(kLink / 2, 0, 0));
		fb.setOrigin(btVector3(-kLink / 2, 0, 0));
		auto* s = new btSliderConstraint(chain.weld->getRigidBodyA(), chain.weld->getRigidBodyB(), fa, fb, true);
		s->setLowerLinLimit(btScalar(-0.2));
		s->setUpperLinLimit(btScalar(0.2));
		chain.scene.addConstraint(s);
		return s;
	};
	OldDofChain bare, held;
	btSliderConstraint* bareSlider = build(bare);
	btSliderConstraint* heldSlider = build(held);
	btQuaternionHingeStabilizer stabilizer;  // the defaults
	held.scene.addAction(&stabilizer);
	auto sliderError = [](btSliderConstraint& s, double& off, double& angle) {
		s.calculateTransforms(s.getRigidBodyA().getCenterOfMassTransform(), s.getRigidBodyB().getCenterOfMassTransform());
		s.testAngLimits();
		const btTransform& ca = s.getCalculatedTransformA();
		const btVector3 d = s.getCalculatedTransformB().getOrigin() - ca.getOrigin();
		const btVector3 xA = ca.getBasis().getColumn(0), xB = s.getCalculatedTransformB().getBasis().getColumn(0);
		off = std::max(off, double((d - xA * d.dot(xA)).length()));
		angle = std::max(angle, std::max(std::fabs(double(s.getAngularPos())), double(xA.cross(xB).length())));
	};
	double bareOff = 0, bareAngle = 0, off = 0, angle = 0;
	for (int i = 0; i < 120; ++i)
	{
		bare.scene.world().stepSimulation(kTimeStep, 0);
		held.scene.world().stepSimulation(kTimeStep, 0);
		sliderError(*bareSlider, bareOff, bareAngle);
		sliderError(*heldSlider, off, angle);
	}
	std::printf(
		"[ figures  ] btSliderConstraint in the chain, largest error over 2 s: stabilized %.2e m %.2e rad; bare "
		"%.2e m %.2e rad\n",
		off, angle, bareOff, bareAngle);
	const btQuaternionHingeStabilizerStats& stats = stabilizer.getLastStats();
	EXPECT_EQ(stats.skippedUnexpressible, 0);
	EXPECT_EQ(stats.lockedConstraints, 2);  // the two sliders
	EXPECT_EQ(stats.joints, 4);
	EXPECT_LE(off, kSeparationTolerance);
	EXPECT_LE(angle, 10 * kSeparationTolerance);  // rad, as above
	EXPECT_GT(bareOff + bareAngle, 100 * kSeparationTolerance);
	ASSERT_TRUE(held.scene.allFinite());
}

TEST(StabilizerLocked, ProjectionLeavesTheSlidersFreeAxisAndTheMomentumAlone)
{
	// Two boxes on a slider (x free), no gravity, put 3 cm and 0.1 rad off it and moving apart along x at 1 m/s and
	// across it at 0.5 m/s: one projection closes the locked axes and the angles, takes the velocity across out,
	// keeps the velocity along x (the free axis) and the sum of the momenta (its rows are internal: equal and
	// opposite impulses).
	StabilizerScene scene;
	scene.world().setGravity(btVector3(0, 0, 0));
	btRigidBody* a = scene.box(btVector3(btScalar(0.2), btScalar(0.1), btScalar(0.1)), 2, btVector3(0, 0, 0));
	btRigidBody* b = scene.box(btVector3(btScalar(0.2), btScalar(0.1), btScalar(0.1)), 1, btVector3(btScalar(0.6), btScalar(0.03), 0),
							   btQuaternion(btVector3(0, 0, 1), btScalar(0.1)));
	btTransform fa = btTransform::getIdentity(), fb = btTransform::getIdentity();
	fa.setOrigin(btVector3(btScalar(0.3), 0, 0));
	fb.setOrigin(btVector3(btScalar(-0.3), 0, 0));
	btGeneric6DofSpring2Constraint* s = slider(*a, *b, fa, fb);
	s->setLinearLowerLimit(btVector3(1, 0, 0));  // x free: no stop in reach
	s->setLinearUpperLimit(btVector3(-1, 0, 0));
	scene.addConstraint(s);
	a->setLinearVelocity(btVector3(btScalar(-0.5), 0, 0));
	b->setLinearVelocity(btVector3(btScalar(0.5), btScalar(0.5), 0));
	const btVector3 momentumBefore = a->getLinearVelocity() * (1 / a->getInvMass()) + b->getLinearVelocity() * (1 / b->getInvMass());
	btQuaternionHingeStabilizer stabilizer(withLocked());
	stabilizer.stabilize(&scene.world(), kTimeStep);
	double distance, angle;
	lockedError(*s, distance, angle);
	EXPECT_EQ(stabilizer.getLastStats().joints, 1);
	EXPECT_LE(distance, kSeparationTolerance);
	EXPECT_LE(angle, 10 * kSeparationTolerance);
	// the rates of B's pivot's coordinates in frame A, d/dt (R_FAᵀ d) = R_FAᵀ (ḋ − ω_A × d): the locked y and z
	// still, x (the free axis) still moving apart at about 1 m/s
	const btTransform frameA = a->getCenterOfMassTransform() * fa, frameB = b->getCenterOfMassTransform() * fb;
	const btVector3 d = frameB.getOrigin() - frameA.getOrigin();
	const btVector3 dDot = b->getVelocityInLocalPoint(frameB.getOrigin() - b->getCenterOfMassPosition()) -
						   a->getVelocityInLocalPoint(frameA.getOrigin() - a->getCenterOfMassPosition());
	const btVector3 rates = frameA.getBasis().transpose() * (dDot - a->getAngularVelocity().cross(d));
	const double velocityTolerance = kDouble ? 1e-9 : 1e-4;  // m/s, and rad/s below
	EXPECT_NEAR(double(rates.y()), 0, velocityTolerance);
	EXPECT_NEAR(double(rates.z()), 0, velocityTolerance);
	EXPECT_GT(double(rates.x()), 0.9);  // the free axis: kept (1 m/s, turned by the 0.1 rad correction)
	EXPECT_NEAR(double((b->getAngularVelocity() - a->getAngularVelocity()).length()), 0, velocityTolerance);
	const btVector3 momentumAfter = a->getLinearVelocity() * (1 / a->getInvMass()) + b->getLinearVelocity() * (1 / b->getInvMass());
	EXPECT_NEAR(double((momentumAfter - momentumBefore).length()), 0, velocityTolerance);  // kg·m/s
}

TEST(StabilizerLocked, ChainAtRestIsReplayedUntilALockedValueChanges)
{
	// Straight down from the world: hinge, slider (x level, free), hinge, weld. At rest it is replayed; the
	// slider's locked y value moved by 1 mm is a changed input: projected again, and held.
	StabilizerScene scene;
	const btVector3 top(0, btScalar(0.25), 0), bottom(0, btScalar(-0.25), 0);
	std::vector<btRigidBody*> links;
	for (int i = 0; i < 4; ++i)
		links.push_back(scene.box(btVector3(btScalar(0.05), btScalar(0.25), btScalar(0.05)), 1,
								  btVector3(0, btScalar(-0.25 - 0.5 * i), 0)));
	scene.hingeToWorld(*links[0], top, btVector3(0, 0, 1));
	// the slider's x across the chain (world x, level: gravity does not load its free axis). Along the chain, the link
	// hanging at its stop, Bullet's stop row and the projection settle in float into a cycle of two states (replayed:
	// the rest cache keeps two), in double into none within 1200 steps (projected every step).
	btGeneric6DofSpring2Constraint* s =
		slider(*links[0], *links[1], btTransform(btQuaternion::getIdentity(), bottom), btTransform(btQuaternion::getIdentity(), top));
	s->setLinearLowerLimit(btVector3(btScalar(-0.05), 0, 0));  // x free within ±5 cm
	s->setLinearUpperLimit(btVector3(btScalar(0.05), 0, 0));
	scene.addConstraint(s);
	scene.hinge(*links[1], *links[2], bottom, top, btVector3(0, 0, 1), btVector3(0, 0, 1));
	btTransform wa = btTransform::getIdentity(), wb = btTransform::getIdentity();
	wa.setOrigin(bottom);
	wb.setOrigin(top);
	scene.addConstraint(new btFixedConstraint(*links[2], *links[3], wa, wb));
	btQuaternionHingeStabilizer stabilizer(withLocked());
	scene.addAction(&stabilizer);
	for (int i = 0; i < 120; ++i) scene.world().stepSimulation(kTimeStep, 0, kTimeStep);
	EXPECT_EQ(stabilizer.getLastStats().joints, 4);
	EXPECT_EQ(stabilizer.getLastStats().restingIslands, 1);
	EXPECT_EQ(stabilizer.getLastStats().factorizations, 0);
	const std::vector<btTransform> poses = scene.poses();
	auto putBack = [&] { scene.setPoses(poses); };
	stabilizer.stabilize(&scene.world(), kTimeStep);
	putBack();
	stabilizer.stabilize(&scene.world(), kTimeStep);
	EXPECT_EQ(stabilizer.getLastStats().restingIslands, 1);  // the control: nothing changed
	putBack();
	s->setLinearLowerLimit(btVector3(btScalar(-0.05), btScalar(1e-3), 0));
	s->setLinearUpperLimit(btVector3(btScalar(0.05), btScalar(1e-3), 0));
	stabilizer.stabilize(&scene.world(), kTimeStep);
	EXPECT_EQ(stabilizer.getLastStats().restingIslands, 0);
	EXPECT_GT(stabilizer.getLastStats().factorizations, 0);
	double distance, angle;
	lockedError(*s, distance, angle);
	EXPECT_LE(distance, kSeparationTolerance);
}

#if defined(QUATHINGE_HAVE_SCENES) && defined(QUATHINGE_HAVE_URDF)  // panda.urdf (urdfdom is optional)
TEST(StabilizerLocked, PandasFingersHoldTheirSlidesWithTheArm)
{
	// Bullet's Franka Panda (demos/models), 3 s at 60 Hz, 10 iterations: its fingers' prismatic joints (6-dof sliders)
	// projected with the arm's hinges hold like them; without the option they stray 5.3e-2 m (float;
	// StabilizerAttached.PandasFingersAreNotLeftBehindByTheStabilizer).
	using namespace quathinge::scenes;
	const SceneSpec panda = makeScene("panda");
	ASSERT_TRUE(panda.unavailable.empty()) << panda.unavailable;
	ASSERT_EQ(panda.sliders.size(), 2u);
	const SliderRunErrors e = runWithSliders(panda, Kind::QuaternionStabilized, withLocked());
	std::printf("[ figures  ] panda with its sliders projected: fingers %.2e m off their slides, hinges %.2e m\n",
				e.sliders, e.hinges);
	EXPECT_LE(e.sliders, kSeparationTolerance);
	EXPECT_LE(e.hinges, kSeparationTolerance);
}
#endif
#endif  // QUATHINGE_HAVE_STABILIZER
