// The hinges an app already has, as the stabilizer reads them with no class swapped (projectStockHinges,
// projectDofHinges: on by default; plugin/stabilizer/StockHingeRows.h): btHingeConstraint and the 6-dofs set up as
// hinges (btGeneric6DofSpring2Constraint in every rotation order, its free axis x, y or z; btGeneric6DofConstraint).
// Their rows are the exact derivative of their C and of the limit variable (finite differences); the limit variable is
// the joint's own angle and acts exactly where the joint's own limit test acts (low > high free, a range of 2π or more
// never, the wrapped angle). Worlds of them: tests/test_stabilizer_stock_worlds.cpp.
#ifdef QUATHINGE_HAVE_STABILIZER
#include "StockHingeRows.h"
#include "support/RowDerivatives.h"
#include "support/StockHinges.h"
#include "support/World.h"

#include <btBulletDynamicsCommon.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

using namespace qh_test;
using quathinge::stabilizer::FrameHinge;
using quathinge::stabilizer::FrameHingeKind;
using quathinge::stabilizer::frameHingeLimitVariable;
using quathinge::stabilizer::frameHingePositionRows;
using quathinge::stabilizer::readFrameHinge;
using quathinge::stabilizer::refreshFrameHinge;
using quathinge::stabilizer::setDofHingeShape;

TEST(StabilizerStock, RowsAndLimitVariableAreTheDerivatives)
{
	// Central differences of C and of the limit variable v under small translations and rotations of either body
	// against J's columns and v's gradient (±g on ω_A, ω_B), over seeded random frames and poses near the hinge and up
	// to 1 rad off it, for every kind (support/RowDerivatives.h: the step and the tolerance).
	std::mt19937 rng(11);
	std::uniform_real_distribution<double> u(-1, 1);
	auto vec = [&](double s) { return btVector3(btScalar(s * u(rng)), btScalar(s * u(rng)), btScalar(s * u(rng))); };
	btBoxShape shape(btVector3(btScalar(0.2), btScalar(0.1), btScalar(0.1)));
	btRigidBody a(1, nullptr, &shape), b(1, nullptr, &shape);
	int checked = 0;
	for (const Kind& kind : kinds())
		for (int n = 0; n < 12; ++n)
		{
			const btTransform fa(randomUnit(rng), vec(0.3)), fb(randomUnit(rng), vec(0.3));
			std::unique_ptr<btTypedConstraint> c(kind.make(a, b, fa, fb, -1, 1));
			FrameHinge hinge;
			ASSERT_NE(readFrameHinge(*c, true, true, &hinge), FrameHingeKind::None) << kind.name;
			btTransform tA, tB;
			const double reach = n % 2 ? 0.05 : 1.0;
			placeFrames(rng, fa, fb, kind.axis, 2 * u(rng), vec(0.1), expRotation(vec(reach / std::sqrt(3.0))), tA, tB);
			btScalar C[5], J[60], v;
			btVector3 g;
			ASSERT_EQ(frameHingePositionRows(hinge, tA, tB, C, J, 0, v, g), 5);
			// the five rows, then v continued from its value here
			auto values = [&](const btTransform& ta, const btTransform& tb, double* out) {
				btScalar Cx[5], Jx[60], vx;
				btVector3 gx;
				frameHingePositionRows(hinge, ta, tb, Cx, Jx, v, vx, gx);
				for (int r = 0; r < 5; ++r) out[r] = double(Cx[r]);
				out[5] = double(vx);
			};
			auto derivative = [&](int r, int column) {
				if (r < 5) return double(J[12 * r + column]);
				const int k = column % 6;
				return k < 3 ? 0.0 : double(column < 6 ? -g[k - 3] : g[k - 3]);
			};
			expectRowDerivatives(values, derivative, tA, tB, 6, kind.name + " configuration " + std::to_string(n));
			++checked;
		}
	EXPECT_EQ(checked, 12 * int(kinds().size()));
}

TEST(StabilizerStock, LimitVariableIsTheJointsOwnAngleAndActsWhereItsTestActs)
{
	// On the hinge, at seeded random angles and limits (low > high, ranges of 2π or more, ranges across ±π included),
	// the limit variable and its stops say what the joint's own limit test says: stock's testLimit (getSolveLimit,
	// getLimitSign), a 6-dof's getInfo1 (its limit motor's current position, which it tests against its limits). Cases
	// within kEdge of a stop are skipped (the two compute the angle in different roundings).
	const double kEdge = 1e-4;                             // rad
	const double kAngleTolerance = kDouble ? 1e-9 : 2e-5;  // rad: the same angle, computed two ways
	std::mt19937 rng(5);
	std::uniform_real_distribution<double> u(-1, 1);
	btBoxShape shape(btVector3(btScalar(0.2), btScalar(0.1), btScalar(0.1)));
	btRigidBody a(1, nullptr, &shape), b(1, nullptr, &shape);
	int acting = 0, free = 0, compared = 0;
	for (const Kind& kind : kinds())
		for (int n = 0; n < 60; ++n)
		{
			const btTransform fa(randomUnit(rng), btVector3(0, btScalar(0.1), 0)), fb(randomUnit(rng), btVector3(0, 0, 0));
			// limits: a third narrow, a third wide (up to 10 rad: a range of 2π or more, or wrapped ends), a third
			// reversed (low > high: free)
			double lo = 3 * u(rng), hi = lo + 2 * std::fabs(u(rng));
			if (n % 3 == 1) hi = lo + 10 * std::fabs(u(rng));
			if (n % 3 == 2) std::swap(lo, hi);
			std::unique_ptr<btTypedConstraint> c(kind.make(a, b, fa, fb, btScalar(lo), btScalar(hi)));
			const double reach = middleAxis(kind) ? 0.45 * kPi : kPi;  // the middle axis's asin reaches ±90°
			btTransform tA, tB;
			placeFrames(rng, fa, fb, kind.axis, reach * u(rng), btVector3(0, 0, 0), btQuaternion::getIdentity(), tA, tB);
			FrameHinge hinge;
			bool limit = false;
			ASSERT_NE(readFrameHinge(*c, true, true, &hinge, &limit), FrameHingeKind::None);
			ASSERT_EQ(limit, hinge.limit);
			const double v = double(frameHingeLimitVariable(*c, hinge, tA, tB));
			bool ownActs, ownLower;
			double ownPosition = v;
			if (kind.name == "stock")
			{
				auto& stock = static_cast<btHingeConstraint&>(*c);
				stock.testLimit(tA, tB);
				ownActs = stock.getSolveLimit() != 0;
				ownLower = stock.getLimitSign() > 0;
				// the variable is the joint's angle less the range's centre, wrapped
				const double ownAngle = double(stock.getHingeAngle(tA, tB));
				const double centre = double(hinge.center);
				EXPECT_NEAR(std::remainder(ownAngle - centre - v, 2 * kPi), 0.0, kAngleTolerance) << kind.name;
			}
			else
			{
				a.setCenterOfMassTransform(tA);
				b.setCenterOfMassTransform(tB);
				btTypedConstraint::btConstraintInfo1 info;
				c->getInfo1(&info);
				btScalar low, high;
				if (c->getConstraintType() == D6_SPRING_2_CONSTRAINT_TYPE)
				{
					auto* motor = static_cast<btGeneric6DofSpring2Constraint&>(*c).getRotationalLimitMotor(kind.axis);
					ownPosition = double(motor->m_currentPosition);
					low = motor->m_loLimit;
					high = motor->m_hiLimit;
				}
				else
				{
					auto* motor = static_cast<btGeneric6DofConstraint&>(*c).getRotationalLimitMotor(kind.axis);
					ownPosition = double(motor->m_currentPosition);
					low = motor->m_loLimit;
					high = motor->m_hiLimit;
				}
				EXPECT_NEAR(v, ownPosition, kAngleTolerance) << kind.name << " lo " << lo << " hi " << hi;
				ownActs = low <= high && (ownPosition < low || ownPosition > high);
				ownLower = ownPosition < low;
			}
			if (std::fabs(v - double(hinge.low)) < kEdge || std::fabs(v - double(hinge.high)) < kEdge) continue;
			const bool acts = hinge.limit && (v < hinge.low || v > hinge.high);
			EXPECT_EQ(acts, ownActs) << kind.name << " lo " << lo << " hi " << hi << " v " << v;
			if (acts && ownActs)
			{
				EXPECT_EQ(v < hinge.low, ownLower) << kind.name << " lo " << lo << " hi " << hi;
			}
			acting += acts;
			free += !hinge.limit;
			++compared;
		}
	EXPECT_GT(acting, 100);
	EXPECT_GT(free, 100);
	EXPECT_GT(compared, 1000);
}

TEST(StabilizerStock, LimitMeaningsOfAStockHinge)
{
	btBoxShape shape(btVector3(btScalar(0.2), btScalar(0.1), btScalar(0.1)));
	btRigidBody a(1, nullptr, &shape), b(1, nullptr, &shape);
	btHingeConstraint h(a, b, btTransform::getIdentity(), btTransform::getIdentity(), false);
	FrameHinge hinge;
	bool limit = true;
	h.setLimit(1, -1);  // low > high: free
	readFrameHinge(h, true, true, &hinge, &limit);
	EXPECT_FALSE(limit);
	h.setLimit(-4, 4);  // a range of 2π or more never acts (its ends wrap to 2.28 > −2.28)
	readFrameHinge(h, true, true, &hinge, &limit);
	EXPECT_FALSE(limit);
	h.setLimit(btScalar(-kPi), btScalar(kPi));
	readFrameHinge(h, true, true, &hinge, &limit);
	EXPECT_FALSE(limit);
	h.setLimit(btScalar(0.5), btScalar(0.5));  // a zero range locks (btAngularLimit::test: h ≥ 0)
	readFrameHinge(h, true, true, &hinge, &limit);
	EXPECT_TRUE(limit);
	EXPECT_EQ(hinge.low, 0);
	h.setLimit(btScalar(2.5), btScalar(3.8));  // across π: the stops are 0.65 rad either side of 3.15
	readFrameHinge(h, true, true, &hinge, &limit);
	EXPECT_TRUE(limit);
	EXPECT_NEAR(double(hinge.high), 0.65, 1e-6);
	// a 6-dof's whole turn never acts; reversed limits are free; a locked pair that is not at 0 is no hinge
	auto d = std::unique_ptr<btGeneric6DofSpring2Constraint>(dofHinge(a, b, btTransform::getIdentity(),
																	  btTransform::getIdentity(), 2, RO_XYZ,
																	  btScalar(-kPi), btScalar(kPi)));
	EXPECT_EQ(readFrameHinge(*d, true, true, &hinge, &limit), FrameHingeKind::Dof);
	EXPECT_FALSE(limit);
	d->setAngularLowerLimit(btVector3(0, btScalar(0.1), 1));
	d->setAngularUpperLimit(btVector3(0, btScalar(0.1), -1));
	EXPECT_EQ(readFrameHinge(*d, true, true, &hinge, &limit), FrameHingeKind::None);
	d->setAngularLowerLimit(btVector3(0, 1, 1));  // two free axes: a universal joint
	d->setAngularUpperLimit(btVector3(0, -1, -1));
	EXPECT_EQ(readFrameHinge(*d, true, true, &hinge, &limit), FrameHingeKind::None);
	EXPECT_EQ(readFrameHinge(h, false, true, &hinge, &limit), FrameHingeKind::None);  // kinds not asked for
}

namespace
{
// The fields of two FrameHinges, bit for bit.
void expectSameHinge(const FrameHinge& x, const FrameHinge& y, const std::string& label)
{
	for (int r = 0; r < 3; ++r)
	{
		EXPECT_EQ(std::memcmp(&x.frameA.getBasis()[r], &y.frameA.getBasis()[r], 3 * sizeof(btScalar)), 0) << label;
		EXPECT_EQ(std::memcmp(&x.frameB.getBasis()[r], &y.frameB.getBasis()[r], 3 * sizeof(btScalar)), 0) << label;
	}
	EXPECT_EQ(std::memcmp(&x.frameA.getOrigin(), &y.frameA.getOrigin(), 3 * sizeof(btScalar)), 0) << label;
	EXPECT_EQ(std::memcmp(&x.frameB.getOrigin(), &y.frameB.getOrigin(), 3 * sizeof(btScalar)), 0) << label;
	EXPECT_EQ(x.angularOnly, y.angularOnly) << label;
	EXPECT_EQ(x.sign, y.sign) << label;
	EXPECT_EQ(x.limit, y.limit) << label;
	EXPECT_EQ(x.adjustToLimits, y.adjustToLimits) << label;
	EXPECT_EQ(x.dofAxis, y.dofAxis) << label;
	EXPECT_EQ(x.center, y.center) << label;
	EXPECT_EQ(x.low, y.low) << label;
	EXPECT_EQ(x.high, y.high) << label;
}
}  // namespace

TEST(StabilizerStock, FramesAndLimitsReadEveryStepAreWhatTheJointSaysNow)
{
	// The stabilizer reads a 6-dof hinge's shape (free axis, angle's sign) when it builds the island and its frames
	// and limits every step (refreshFrameHinge). For every kind, at seeded random frames and limits, and again after
	// the joint's public API changed them (a stock hinge's setFrames and setLimit; a 6-dof's setFrames, the locked
	// linear values, the free axis's limits), the step's read is bit for bit a full read of the joint as it is then.
	std::mt19937 rng(17);
	std::uniform_real_distribution<double> u(-1, 1);
	auto vec = [&](double s) { return btVector3(btScalar(s * u(rng)), btScalar(s * u(rng)), btScalar(s * u(rng))); };
	btBoxShape shape(btVector3(btScalar(0.2), btScalar(0.1), btScalar(0.1)));
	btRigidBody a(1, nullptr, &shape), b(1, nullptr, &shape);
	int changed = 0;
	for (const Kind& kind : kinds())
		for (int n = 0; n < 4; ++n)
		{
			std::unique_ptr<btTypedConstraint> c(kind.make(a, b, btTransform(randomUnit(rng), vec(0.3)),
														   btTransform(randomUnit(rng), vec(0.3)), -1, 1));
			FrameHinge full, kept;
			unsigned shape = 0;
			const FrameHingeKind k = readFrameHinge(*c, true, true, &full, nullptr, &shape);
			ASSERT_NE(k, FrameHingeKind::None) << kind.name;
			if (k == FrameHingeKind::Dof) setDofHingeShape(shape, kept);
			refreshFrameHinge(*c, kept);
			expectSameHinge(kept, full, kind.name + " as built");
			// changed through the joint's API, its shape kept
			const btTransform fa(randomUnit(rng), vec(0.3)), fb(randomUnit(rng), vec(0.3));
			const btScalar lo = btScalar(-2 * std::fabs(u(rng))), hi = btScalar(2 * std::fabs(u(rng)));
			const btVector3 lock = vec(0.05);
			if (k == FrameHingeKind::Stock)
			{
				auto& h = static_cast<btHingeConstraint&>(*c);
				h.setFrames(fa, fb);
				h.setLimit(lo, hi);
			}
			else
			{
				btVector3 low(0, 0, 0), high(0, 0, 0);
				low[kind.axis] = lo;
				high[kind.axis] = hi;
				if (c->getConstraintType() == D6_SPRING_2_CONSTRAINT_TYPE)
				{
					auto& d = static_cast<btGeneric6DofSpring2Constraint&>(*c);
					d.setFrames(fa, fb);
					d.setLinearLowerLimit(lock);
					d.setLinearUpperLimit(lock);
					d.setAngularLowerLimit(low);
					d.setAngularUpperLimit(high);
				}
				else
				{
					auto& d = static_cast<btGeneric6DofConstraint&>(*c);
					d.setFrames(fa, fb);
					d.setLinearLowerLimit(lock);
					d.setLinearUpperLimit(lock);
					d.setAngularLowerLimit(low);
					d.setAngularUpperLimit(high);
				}
			}
			unsigned shapeNow = 0;
			ASSERT_EQ(readFrameHinge(*c, true, true, &full, nullptr, &shapeNow), k) << kind.name;
			ASSERT_EQ(shapeNow, shape) << kind.name;
			refreshFrameHinge(*c, kept);
			expectSameHinge(kept, full, kind.name + " changed");
			EXPECT_EQ(kept.low, k == FrameHingeKind::Dof ? lo : full.low) << kind.name;
			++changed;
		}
	EXPECT_EQ(changed, 4 * int(kinds().size()));
}

TEST(StabilizerStock, FrameAngleIsTheRowsAngleFromZero)
{
	// btQuaternionHingeConstraint::computeFrameAngle, a limit's starting angle without the rows, is bit for bit the
	// rows' angle continued from 0, over seeded random frames and poses at every angle and up to 1 rad off the hinge.
	std::mt19937 rng(23);
	std::uniform_real_distribution<double> u(-1, 1);
	auto vec = [&](double s) { return btVector3(btScalar(s * u(rng)), btScalar(s * u(rng)), btScalar(s * u(rng))); };
	for (int n = 0; n < 400; ++n)
	{
		const btTransform fa(randomUnit(rng), vec(0.3)), fb(randomUnit(rng), vec(0.3));
		btTransform tA, tB;
		placeFrames(rng, fa, fb, 2, kPi * u(rng), vec(0.1), expRotation(vec((n % 2 ? 0.05 : 1.0) / std::sqrt(3.0))), tA,
					tB);
		btScalar C[5], J[60], theta;
		btVector3 g;
		btQuaternionHingeConstraint::computeFramePositionRows(fa, fb, false, tA, tB, C, J, 0, theta, g);
		EXPECT_EQ(btQuaternionHingeConstraint::computeFrameAngle(fa, fb, tA, tB), theta) << "configuration " << n;
	}
}

#endif  // QUATHINGE_HAVE_STABILIZER
