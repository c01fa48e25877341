// 6-dofs with some of their Euler angles locked, as Bullet builds its universal joint (btUniversalConstraint: linear
// axes and angle x locked), its btHinge2Constraint (linear x and y, angle y) and a cylindrical joint (a
// btGeneric6DofSpring2Constraint with linear and angular x free, or a btSliderConstraint free to turn): with the
// defaults the stabilizer holds each whole by its locked rows (plugin/stabilizer/LockedRows.h; docs/MATH.md, "Some
// angles locked"). Their rows are the exact derivative of their C (finite differences), their C is the
// 6-dof's own reading (getAngle, getRelativePivotPosition; the slider's getAngularPos), and a chain of them holds.
#ifdef QUATHINGE_HAVE_STABILIZER
#include "LockedRows.h"
#include "support/LockedDofError.h"
#include "support/RandomPoses.h"
#include "support/RowDerivatives.h"
#include "support/StabilizerScene.h"
#include "support/World.h"

#include "BulletDynamics/ConstraintSolver/btHinge2Constraint.h"
#include "BulletDynamics/ConstraintSolver/btUniversalConstraint.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

using namespace qh_test;
namespace qs = quathinge::stabilizer;

namespace
{
const btScalar kLink = btScalar(0.5);  // m, link length

// A 6-dof of either family with linear axis i locked at linear[i] where bit i of `linearBits` is set and Euler angle
// i at angles[i] where bit i of `angularBits` is; every other axis free (low > high).
template <class Dof>
void lock(Dof& c, const btVector3& linear, int linearBits, const btVector3& angles, int angularBits)
{
	btVector3 low(1, 1, 1), high(-1, -1, -1), angularLow(1, 1, 1), angularHigh(-1, -1, -1);
	for (int i = 0; i < 3; ++i)
	{
		if (linearBits & (1 << i)) low[i] = high[i] = linear[i];
		if (angularBits & (1 << i)) angularLow[i] = angularHigh[i] = angles[i];
	}
	c.setLinearLowerLimit(low);
	c.setLinearUpperLimit(high);
	c.setAngularLowerLimit(angularLow);
	c.setAngularUpperLimit(angularHigh);
}

int bits(int pattern) { return (pattern & 1) + ((pattern >> 1) & 1) + ((pattern >> 2) & 1); }

// A random configuration of a 6-dof of class Dof: frames, locks (some angle always locked, not all at 0) and the
// bodies' transforms, B's frame turned from A's by up to `reach` rad.
template <class Dof>
struct Configuration
{
	std::unique_ptr<Dof> c;
	btVector3 linear, angles;
	int linearBits, angularBits;
	btTransform tA, tB;
	Configuration(RandomPoses& p, int n, double reach)
	{
		const btTransform fa(p.unit(), p.vec(0.3)), fb(p.unit(), p.vec(0.3));
		c.reset(new Dof(p.a, p.b, fa, fb, n % 2 == 0));
		linear = p.vec(0.1);
		angles = p.vec(1.0);
		linearBits = n % 8;
		angularBits = 1 + (n / 8) % 7;  // 1–7: x, y, z and their mixes
		lock(*c, linear, linearBits, angles, angularBits);
		tA = btTransform(p.unit(), p.vec(2));
		const btTransform frameAWorld = tA * fa;
		const btTransform frameBWorld(expRotation(p.vec(reach / std::sqrt(3.0))) * frameAWorld.getRotation(),
									  frameAWorld.getOrigin() + p.vec(0.2));
		tB = frameBWorld * fb.inverse();
	}
};

template <class Dof>
void checkDerivatives(unsigned seed, const char* family)
{
	// B's frame within 0.3 rad of A's (near) or up to 2 rad off it (far); where Euler angle y is within 0.2 rad of
	// ±π/2 or an error a − a₀ or c − c₀ is within 0.1 rad of ±π (where C wraps) there is no derivative to take
	RandomPoses p(seed);
	int checked = 0;
	for (int n = 0; n < 224; ++n)
	{
		Configuration<Dof> k(p, n, n % 2 ? 0.3 : 2.0);
		ASSERT_TRUE(qs::hasLockedRows(qs::dofLocks(*k.c))) << family << " configuration " << n;
		btScalar C[6], J[72];
		const int rows = qs::lockedPositionRows(*k.c, k.tA, k.tB, C, J);
		ASSERT_EQ(rows, bits(k.linearBits) + bits(k.angularBits)) << family << " configuration " << n;
		k.c->calculateTransforms(k.tA, k.tB);
		const double y = double(k.c->getAngle(1));
		const double ex = std::fabs(double(btNormalizeAngle(k.c->getAngle(0) - k.angles[0])));
		const double ez = std::fabs(double(btNormalizeAngle(k.c->getAngle(2) - k.angles[2])));
		if (std::fabs(y) > M_PI / 2 - 0.2 || ex > M_PI - 0.1 || ez > M_PI - 0.1) continue;
		auto values = [&](const btTransform& ta, const btTransform& tb, double* out) {
			btScalar Cx[6], Jx[72];
			qs::lockedPositionRows(*k.c, ta, tb, Cx, Jx);
			for (int r = 0; r < rows; ++r) out[r] = double(Cx[r]);
		};
		auto derivative = [&](int r, int column) { return double(J[12 * r + column]); };
		expectRowDerivatives(values, derivative, k.tA, k.tB, rows, std::string(family) + " configuration " + std::to_string(n));
		++checked;
	}
	EXPECT_GT(checked, 150) << family;
}

template <class Dof>
void checkMeaning(unsigned seed, const char* family)
{
	// Each row's C against the 6-dof's own reading at the same transforms (calculateTransforms): a locked linear
	// axis's is getRelativePivotPosition less its value; angle y's, getAngle(1) less its value; x's and z's, their
	// getAngle less the value (wrapped), times cos y (LockedRows.h: those rows are scaled so they stay bounded where
	// y = ±π/2). Bullet computes y as asin, the rows as atan2 of the same sine: equal to rounding amplified by 1/cos y.
	RandomPoses p(seed);
	const double tolerance = kDouble ? 1e-11 : 1e-5;  // m or rad, coordinates up to a few metres
	for (int n = 0; n < 112; ++n)
	{
		Configuration<Dof> k(p, n, 2.0);
		btScalar C[6], J[72];
		qs::lockedPositionRows(*k.c, k.tA, k.tB, C, J);
		k.c->calculateTransforms(k.tA, k.tB);
		const double cosY = std::cos(double(k.c->getAngle(1)));
		if (cosY < 0.1) continue;
		int r = 0;
		for (int i = 0; i < 3; ++i)
			if (k.linearBits & (1 << i))
			{
				EXPECT_NEAR(double(C[r]), double(k.c->getRelativePivotPosition(i) - k.linear[i]), tolerance)
					<< family << " configuration " << n << ", linear axis " << i;
				++r;
			}
		for (int i = 0; i < 3; ++i)
			if (k.angularBits & (1 << i))
			{
				const double error = double(btNormalizeAngle(k.c->getAngle(i) - k.angles[i]));
				EXPECT_NEAR(double(C[r]), i == 1 ? error : cosY * error, tolerance / cosY)
					<< family << " configuration " << n << ", angle " << i;
				++r;
			}
	}
}
}  // namespace

TEST(StabilizerEulerLocks, RowsAreTheDerivativeOfC)
{
	// Central differences of C under small translations and rotations of either body against J's columns
	// (support/RowDerivatives.h: the step and the tolerance), over seeded random frames, locks (every mix of linear
	// axes with every mix of angles) and poses, both 6-dof families.
	checkDerivatives<Dof2>(21, "btGeneric6DofSpring2Constraint");
	checkDerivatives<btGeneric6DofConstraint>(22, "btGeneric6DofConstraint");
}

TEST(StabilizerEulerLocks, LocksMeanWhatBulletMeasures)
{
	checkMeaning<Dof2>(23, "btGeneric6DofSpring2Constraint");
	checkMeaning<btGeneric6DofConstraint>(24, "btGeneric6DofConstraint");
}

TEST(StabilizerEulerLocks, OtherRotationOrdersKeepTheirPointAndAreNotSkipped)
{
	// A btGeneric6DofSpring2Constraint in another rotation order has other Euler angles: with some of them locked and
	// its linear axes locked it is held by its pivot (a point constraint), not by rows of angles it does not use.
	RandomPoses p(25);
	const btTransform fa(p.unit(), p.vec(0.3)), fb(p.unit(), p.vec(0.3));
	btGeneric6DofSpring2Constraint c(p.a, p.b, fa, fb, RO_ZYX);
	lock(c, btVector3(0, 0, 0), 7, btVector3(0, btScalar(0.2), 0), 2);
	const qs::DofLocks locks = qs::dofLocks(c);
	EXPECT_FALSE(locks.eulerXYZ);
	EXPECT_FALSE(qs::hasLockedRows(locks));
	EXPECT_TRUE(qs::hasPointRows(c, locks));
	c.setRotationOrder(RO_XYZ);
	EXPECT_TRUE(qs::hasLockedRows(qs::dofLocks(c)));
}

TEST(StabilizerEulerLocks, SliderFreeToTurnOrLockedAtAnAngleMeansWhatBulletMeasures)
{
	// A btSliderConstraint free to turn about its axis (a cylindrical joint) has four rows: B's origin on the slide
	// line and the two frames' x axes together (Euler angles y and z at 0); with its turn locked at an angle θ₀ ≠ 0,
	// a fifth: the turn, getAngularPos, minus the Euler angle x (with useLinearReferenceFrameA or without: only the
	// slide is measured the other way without it). B is put turned by θ about frame A's x, slid along it, then turned and moved off by up to
	// 0.01 rad and 1 cm: the turn row's C is getAngularPos − θ₀ (with that sign) to first order.
	RandomPoses p(26);
	for (int n = 0; n < 100; ++n)
	{
		const btTransform fa(p.unit(), p.vec(0.3)), fb(p.unit(), p.vec(0.3));
		const bool referenceA = n % 2 == 0, turnLocked = n % 4 < 2;
		std::unique_ptr<btSliderConstraint> c(new btSliderConstraint(p.a, p.b, fa, fb, referenceA));
		c->setLowerLinLimit(btScalar(-0.2));
		c->setUpperLinLimit(btScalar(0.2));
		const btScalar turnLock = btScalar(0.5 * p.number());
		c->setLowerAngLimit(turnLocked ? turnLock : btScalar(1));
		c->setUpperAngLimit(turnLocked ? turnLock : btScalar(-1));
		const qs::DofLocks locks = qs::dofLocks(*c);
		ASSERT_TRUE(qs::hasLockedRows(locks));
		const btTransform tA(p.unit(), p.vec(2));
		const btTransform frameAWorld = tA * fa;
		const btScalar theta = btScalar(1.5 * p.number());
		const btVector3 turn = p.vec(0.01 / std::sqrt(3.0));
		const btQuaternion aboutX(frameAWorld.getBasis().getColumn(0), theta);
		const btTransform frameBWorld(expRotation(turn) * aboutX * frameAWorld.getRotation(),
									  frameAWorld * btVector3(btScalar(0.1 * p.number()), 0, 0) + p.vec(0.01));
		const btTransform tB = frameBWorld * fb.inverse();
		btScalar C[6], J[72];
		const int rows = qs::lockedPositionRows(*c, tA, tB, C, J);
		ASSERT_EQ(rows, turnLocked ? 5 : 4);
		c->calculateTransforms(tA, tB);
		c->testAngLimits();
		const double turned = double(turn.length()) + 0.01;  // rad, m: how far B is from the exact pose
		// rows: linear y, z (B's origin off the line), then angle x if locked, y, z (the x axes apart)
		const btVector3 xA = frameAWorld.getBasis().getColumn(0), xB = frameBWorld.getBasis().getColumn(0);
		const double apart = double(xA.cross(xB).length());
		const int angular = 2;
		if (turnLocked)
		{
			EXPECT_NEAR(double(C[angular]), -double(btNormalizeAngle(c->getAngularPos() - turnLock)),
						4 * turned * turned + (kDouble ? 1e-12 : 1e-5))
				<< "configuration " << n;
		}
		const int firstSwing = turnLocked ? 3 : 2;
		const double swing = std::hypot(double(C[firstSwing]), double(C[firstSwing + 1]));
		EXPECT_NEAR(swing, apart, 4 * turned * turned + (kDouble ? 1e-12 : 1e-5)) << "configuration " << n;
	}
}

namespace
{
// A 5-link chain released horizontally at 2 m: a quaternion hinge (z) to the world, then Bullet's
// btUniversalConstraint (axes z and y), its btHinge2Constraint (axes y and x, its suspension spring on y), a
// cylindrical btGeneric6DofSpring2Constraint (x free, linear and angular) and a btSliderConstraint free to turn,
// both of those slides within ±0.2 m; the last link is spun about the chain.
struct EulerChain
{
	StabilizerScene scene;
	btUniversalConstraint* universal;
	btHinge2Constraint* hinge2;
	btGeneric6DofSpring2Constraint* cylinder;
	btSliderConstraint* slider;
	EulerChain()
	{
		std::vector<btRigidBody*> links;
		for (int i = 0; i < 5; ++i)
			links.push_back(scene.box(btVector3(kLink / 2, btScalar(0.05), btScalar(0.05)), 1,
									  btVector3(kLink * (btScalar(i) + btScalar(0.5)), 2, 0)));
		const btVector3 left(-kLink / 2, 0, 0), right(kLink / 2, 0, 0);
		scene.hingeToWorld(*links[0], left, btVector3(0, 0, 1));
		universal = new btUniversalConstraint(*links[0], *links[1], btVector3(kLink, 2, 0), btVector3(0, 0, 1),
											  btVector3(0, 1, 0));
		scene.addConstraint(universal);
		btVector3 anchor(2 * kLink, 2, 0), axis1(0, 1, 0), axis2(1, 0, 0);
		hinge2 = new btHinge2Constraint(*links[1], *links[2], anchor, axis1, axis2);
		scene.addConstraint(hinge2);
		btTransform fa = btTransform::getIdentity(), fb = btTransform::getIdentity();
		fa.setOrigin(right);
		fb.setOrigin(left);
		cylinder = new btGeneric6DofSpring2Constraint(*links[2], *links[3], fa, fb);
		lock(*cylinder, btVector3(0, 0, 0), 6, btVector3(0, 0, 0), 6);
		cylinder->setLimit(0, btScalar(-0.2), btScalar(0.2));
		scene.addConstraint(cylinder);
		slider = new btSliderConstraint(*links[3], *links[4], fa, fb, true);
		slider->setLowerLinLimit(btScalar(-0.2));
		slider->setUpperLinLimit(btScalar(0.2));
		slider->setLowerAngLimit(1);  // lower > upper: free to turn
		slider->setUpperAngLimit(-1);
		scene.addConstraint(slider);
		links[4]->setAngularVelocity(btVector3(4, 0, 0));  // rad/s: the slider's link spins about its axis
		links[2]->setAngularVelocity(btVector3(2, 0, 0));  // and the wheel of the hinge-2 about its axle
	}
	// The largest error over the 6-dofs' locked axes as they read it themselves (lockedDofError: m and rad), and the
	// slider's (B's origin off the slide line, m; the x axes apart, rad).
	void errors(double& distance, double& angle)
	{
		lockedDofError(static_cast<btGeneric6DofConstraint&>(*universal), distance, angle);
		lockedDofError(static_cast<btGeneric6DofSpring2Constraint&>(*hinge2), distance, angle);
		lockedDofError(*cylinder, distance, angle);
		slider->calculateTransforms(slider->getRigidBodyA().getCenterOfMassTransform(),
									slider->getRigidBodyB().getCenterOfMassTransform());
		const btTransform& ca = slider->getCalculatedTransformA();
		const btVector3 d = slider->getCalculatedTransformB().getOrigin() - ca.getOrigin();
		const btVector3 xA = ca.getBasis().getColumn(0), xB = slider->getCalculatedTransformB().getBasis().getColumn(0);
		distance = std::max(distance, double((d - xA * d.dot(xA)).length()));
		angle = std::max(angle, double(xA.cross(xB).length()));
	}
	// How far the joints are past their limits as they read it themselves (limitedDofPast: the universal joint's
	// angles y and z, the hinge-2's suspension and steering, the cylinder's slide; the slider's getLinearPos), m and rad.
	void past(double& distance, double& angle)
	{
		limitedDofPast(static_cast<btGeneric6DofConstraint&>(*universal), distance, angle);
		limitedDofPast(static_cast<btGeneric6DofSpring2Constraint&>(*hinge2), distance, angle);
		limitedDofPast(*cylinder, distance, angle);
		slider->testLinLimits();  // after errors()' calculateTransforms
		const double x = double(slider->getLinearPos());
		distance = std::max({distance, double(slider->getLowerLinLimit()) - x, x - double(slider->getUpperLinLimit())});
	}
	// Steps 2 s: the largest errors after any step, and the largest hinge separation (m); how far past a limit (m, rad).
	void run(double& hinge, double& distance, double& angle, double* pastLimits = nullptr)
	{
		hinge = distance = angle = 0;
		if (pastLimits) pastLimits[0] = pastLimits[1] = 0;
		for (int i = 0; i < 120; ++i)
		{
			scene.world().stepSimulation(kTimeStep, 0);
			double separation, misalignment;
			scene.jointErrors(separation, misalignment);
			hinge = std::max(hinge, separation);
			errors(distance, angle);
			if (pastLimits) past(pastLimits[0], pastLimits[1]);
		}
	}
};
}  // namespace

TEST(StabilizerEulerLocks, UniversalHinge2AndCylindricalJointsHoldWithTheDefaults)
{
	// With the defaults every joint of the chain is held whole (none skipped as unexpressible, as all four were
	// before): Bullet's own reading of each joint's locked axes is the reference.
	EulerChain bare, held;
	btQuaternionHingeStabilizer stabilizer;  // the defaults
	held.scene.addAction(&stabilizer);
	double bareHinge, bareDistance, bareAngle, hinge, distance, angle, barePast[2], past[2];
	bare.run(bareHinge, bareDistance, bareAngle, barePast);
	held.run(hinge, distance, angle, past);
	std::printf(
		"[ figures  ] universal, hinge-2, cylindrical 6-dof, slider free to turn; largest error over 2 s: stabilized "
		"%.2e m %.2e rad (hinge %.2e m), past a limit %.2e m %.2e rad; bare %.2e m %.2e rad (hinge %.2e m), past a "
		"limit %.2e m %.2e rad\n",
		distance, angle, hinge, past[0], past[1], bareDistance, bareAngle, bareHinge, barePast[0], barePast[1]);
	const btQuaternionHingeStabilizerStats& stats = stabilizer.getLastStats();
	EXPECT_EQ(stats.skippedUnexpressible, 0);
	EXPECT_EQ(stats.skippedByOption, 0);
	EXPECT_EQ(stats.lockedConstraints, 4);
	EXPECT_EQ(stats.joints, 5);
	EXPECT_EQ(stats.islands, 1);
	EXPECT_LE(distance, kSeparationTolerance);
	EXPECT_LE(angle, 10 * kSeparationTolerance);  // rad: float's rounding of the angles read from the frames
	EXPECT_LE(hinge, kSeparationTolerance);
	EXPECT_GT(bareDistance + bareAngle, 100 * kSeparationTolerance);  // Bullet's solver alone leaves them apart
	// their limits (LockedRows.h's limit rows): the issue's target, 1e-3 m or rad past a stop
	EXPECT_LE(past[0], 1e-3);
	EXPECT_LE(past[1], 1e-3);
	EXPECT_EQ(stats.numericalIssues, 0);
	ASSERT_TRUE(held.scene.allFinite());
}

TEST(StabilizerEulerLocks, WithoutTheLockedOptionAUniversalJointKeepsItsPoint)
{
	// projectLockedConstraints off: a universal joint (linear axes locked) is still a point constraint, the hinge-2,
	// the cylindrical joint and the slider are counted as skipped by that option, not as unexpressible.
	EulerChain chain;
	btQuaternionHingeStabilizerSettings settings;
	settings.projectLockedConstraints = false;
	btQuaternionHingeStabilizer stabilizer(settings);
	chain.scene.addAction(&stabilizer);
	chain.scene.world().stepSimulation(kTimeStep, 0);
	const btQuaternionHingeStabilizerStats& stats = stabilizer.getLastStats();
	EXPECT_EQ(stats.pointConstraints, 1);
	EXPECT_EQ(stats.lockedConstraints, 0);
	EXPECT_EQ(stats.skippedByOption, 3);
	EXPECT_EQ(stats.skippedUnexpressible, 0);
	chain.scene.world().removeAction(&stabilizer);
}
#endif
