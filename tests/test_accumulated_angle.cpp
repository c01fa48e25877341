// btQuaternionHingeAccumulatedAngleConstraint, the drop-in for stock's btHingeAccumulatedAngleConstraint: an app that
// swaps the class name keeps its count of turns, setAccumulatedHingeAngle keeps stock's meaning, and
// btReplaceHingeConstraints carries the count of an existing stock one over.
#include "quathinge/btQuaternionHingeConstraint.h"
#include "support/Refusal.h"
#include "support/World.h"

#include "BulletDynamics/ConstraintSolver/btHingeConstraint.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

namespace
{
// The reference for a free spin: a bar spinning about its own principal axis z with no gravity, contact or damping
// turns at a constant rate, so after t seconds the hinge has turned rate·t (rad; stock's sign: −, the hinge angle being
// minus B's turn relative to A). Both classes count it within this tolerance (rad): float round-off of 60 Hz
// integration over a few seconds (measured: below 1e-4 for either class).
const double kCountTol = 1e-3;
// The two classes compared on the same pose (rad): their joints leave residuals of about 1e-6 rad on a free spin.
const double kSameTol = 1e-4;

const double kDt = 1.0 / 60;

// A bar of 1 kg on a static base, hinged about z through its centre.
template <class Hinge>
struct Spinner
{
	qh_test::World world{qh_test::SolverKind::SequentialImpulse, btVector3(0, 0, 0)};
	btRigidBody* base;
	btRigidBody* bar;
	Hinge* hinge;
	Spinner()
	{
		base = world.addBox(0, btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)), btTransform::getIdentity());
		bar = world.addBox(1, btVector3(btScalar(0.5), btScalar(0.05), btScalar(0.05)), btTransform::getIdentity());
		for (btRigidBody* b : {base, bar})
			b->setCollisionFlags(b->getCollisionFlags() | btCollisionObject::CF_NO_CONTACT_RESPONSE);
		const btVector3 o(0, 0, 0), z(0, 0, 1);
		hinge = world.add(new Hinge(*base, *bar, o, o, z, z));
	}
	// Spins the bar at `rate` rad/s about +z for `steps` steps of 60 Hz, reading the count every step as an app would.
	void spin(double rate, int steps)
	{
		bar->activate(true);
		bar->setAngularVelocity(btVector3(0, 0, btScalar(rate)));
		for (int i = 0; i < steps; ++i)
		{
			world.step(1);
			hinge->getAccumulatedHingeAngle();
		}
	}
};
using Stock = Spinner<btHingeAccumulatedAngleConstraint>;
using Quat = Spinner<btQuaternionHingeAccumulatedAngleConstraint>;
}  // namespace

TEST(AccumulatedAngle, CountsTurnsAsStockDoes)
{
	// 3 rad/s for 3 s: 9 rad, one and a half turns, at 0.05 rad per step (well inside stock's 0.3 rad per update).
	Stock s;
	Quat q;
	EXPECT_NEAR(q.hinge->getAccumulatedHingeAngle(), s.hinge->getAccumulatedHingeAngle(), kSameTol);  // both 0
	s.spin(3, 180);
	q.spin(3, 180);
	const double expected = -3.0 * 180 * kDt;
	std::printf("[ figures  ] 3 rad/s for 3 s: stock %.6f, quaternion %.6f, reference %.6f rad\n",
				double(s.hinge->getAccumulatedHingeAngle()), double(q.hinge->getAccumulatedHingeAngle()), expected);
	EXPECT_NEAR(s.hinge->getAccumulatedHingeAngle(), expected, kCountTol);
	EXPECT_NEAR(q.hinge->getAccumulatedHingeAngle(), expected, kCountTol);
	EXPECT_NEAR(q.hinge->getAccumulatedHingeAngle(), s.hinge->getAccumulatedHingeAngle(), kSameTol);
	// the same number getMultiTurnAngle gives, and the wrapped angle stock's getHingeAngle gives
	EXPECT_EQ(q.hinge->getAccumulatedHingeAngle(), q.hinge->getMultiTurnAngle());
	EXPECT_NEAR(std::remainder(double(q.hinge->getAccumulatedHingeAngle()), 2 * M_PI), s.hinge->getHingeAngle(),
				kSameTol);
}

TEST(AccumulatedAngle, CountsFromConstructionWithoutBeingAsked)
{
	// As stock's, the count runs from construction on: an app that reads it only at the end still gets every turn.
	Stock s;
	Quat q;
	s.bar->setAngularVelocity(btVector3(0, 0, 2));
	q.bar->setAngularVelocity(btVector3(0, 0, 2));
	s.world.step(240);  // 8 rad, never read in between
	q.world.step(240);
	const double expected = -2.0 * 240 * kDt;
	EXPECT_NEAR(s.hinge->getAccumulatedHingeAngle(), expected, kCountTol);
	EXPECT_NEAR(q.hinge->getAccumulatedHingeAngle(), expected, kCountTol);
}

TEST(AccumulatedAngle, KeepsTheCountWhereStocksUpdateLosesIt)
{
	// The documented difference: at 30 rad/s (0.5 rad per 60 Hz step) stock's update starts again from the wrapped
	// angle at every step; the multi-turn angle follows any turn of less than π per step.
	Stock s;
	Quat q;
	s.spin(30, 60);
	q.spin(30, 60);
	const double expected = -30.0 * 60 * kDt;
	std::printf("[ figures  ] 30 rad/s for 1 s: stock %.4f, quaternion %.4f, reference %.4f rad\n",
				double(s.hinge->getAccumulatedHingeAngle()), double(q.hinge->getAccumulatedHingeAngle()), expected);
	EXPECT_NEAR(q.hinge->getAccumulatedHingeAngle(), expected, kCountTol);
	EXPECT_LE(std::fabs(s.hinge->getAccumulatedHingeAngle()), M_PI + 1e-6);  // stock: wrapped, turns lost
}

TEST(AccumulatedAngle, SetKeepsStocksMeaning)
{
	// Stock stores any value; its next update takes the current pose's angle plus the whole turns nearest the value
	// when that is within 0.3 rad of it, else the wrapped angle. The quaternion hinge applies the same rule at once.
	Stock s;
	Quat q;
	s.spin(1, 60);  // about −1 rad
	q.spin(1, 60);
	const double raw = s.hinge->getHingeAngle();
	const double values[] = {raw + 4 * M_PI + 0.1, raw - 2 * M_PI - 0.25, raw + 6 * M_PI + 0.5, raw - 1.0, raw};
	for (double v : values)
	{
		s.hinge->setAccumulatedHingeAngle(btScalar(v));
		q.hinge->setAccumulatedHingeAngle(btScalar(v));
		const double stockRead = s.hinge->getAccumulatedHingeAngle();
		EXPECT_NEAR(q.hinge->getAccumulatedHingeAngle(), stockRead, kSameTol) << "set " << v - raw << " from the pose";
		// and the count goes on from there
		s.spin(1, 30);
		q.spin(1, 30);
		EXPECT_NEAR(q.hinge->getAccumulatedHingeAngle(), s.hinge->getAccumulatedHingeAngle(), kSameTol)
			<< "half a second after setting " << v - raw << " from the pose";
	}
}

TEST(AccumulatedAngle, MeaninglessValueIsRefusedAndChangesNothing)
{
	Quat q;
	q.spin(2, 200);  // about −6.7 rad: more than a turn
	const btScalar before = q.hinge->getAccumulatedHingeAngle();
	EXPECT_REFUSED(q.hinge->setAccumulatedHingeAngle(btScalar(NAN)), "accAngle");
	EXPECT_REFUSED(q.hinge->setAccumulatedHingeAngle(SIMD_INFINITY), "accAngle");
	EXPECT_REFUSED(q.hinge->setAccumulatedHingeAngle(btScalar(1e7)), "accAngle");  // beyond ±1e6 rad
	EXPECT_EQ(q.hinge->getAccumulatedHingeAngle(), before);
}

TEST(AccumulatedAngle, ReplaceHingeConstraintsCarriesTheCountOver)
{
	// A world with one stock accumulated hinge that has turned 8 rad and one plain stock hinge: the first becomes a
	// btQuaternionHingeAccumulatedAngleConstraint with the same count, the second a plain quaternion hinge.
	Stock s;
	btRigidBody* other =
		s.world.addBox(1, btVector3(1, 1, 1), btTransform(btQuaternion::getIdentity(), btVector3(0, -5, 0)));
	other->setCollisionFlags(other->getCollisionFlags() | btCollisionObject::CF_NO_CONTACT_RESPONSE);
	s.world.add(new btHingeConstraint(*s.base, *other, btVector3(0, -1, 0), btVector3(0, 1, 0), btVector3(0, 0, 1),
									  btVector3(0, 0, 1)));
	s.spin(2, 240);
	const double count = s.hinge->getAccumulatedHingeAngle();
	ASSERT_NEAR(count, -8.0, kCountTol);
	btAlignedObjectArray<btQuaternionHingeConstraint*> added;
	ASSERT_EQ(btReplaceHingeConstraints(&s.world.world(), &added), 2);
	std::unique_ptr<btQuaternionHingeConstraint> first(added[0]), second(added[1]);
	auto* counted = dynamic_cast<btQuaternionHingeAccumulatedAngleConstraint*>(first.get());
	ASSERT_NE(counted, nullptr);
	EXPECT_EQ(dynamic_cast<btQuaternionHingeAccumulatedAngleConstraint*>(second.get()), nullptr);
	EXPECT_NEAR(counted->getAccumulatedHingeAngle(), count, kSameTol);
	// the count goes on: one more second at 2 rad/s, read only at the end
	s.world.step(60);
	EXPECT_NEAR(counted->getAccumulatedHingeAngle(), -10.0, kCountTol);
	s.world.world().removeConstraint(first.get());
	s.world.world().removeConstraint(second.get());
}
