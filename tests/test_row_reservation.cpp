// Row reservation (issue 14, item 3): getInfo2 and getInfo2NonVirtual never write a row getInfo1 / getInfo1NonVirtual
// did not reserve. The solver sizes its row buffer by getInfo1's count; here each row array holds exactly the
// reserved rows on the heap (AddressSanitizer reports a write past them) followed, in a second run, by guard rows
// filled with a sentinel that must come back untouched (a check that fails without ASan too).
#include "quathinge/btQuaternionHingeConstraint.h"

#include "BulletCollision/CollisionShapes/btBoxShape.h"
#include "BulletDynamics/Dynamics/btRigidBody.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace
{
const int kSkip = 8;  // the row stride (Bullet's is sizeof(btSolverConstraint)/sizeof(btScalar); any stride ≥ 3 works)

// Row arrays of `rows` rows plus `guard` guard rows, each array its own heap block of exactly that size.
struct RowBuffers
{
	int rows, guard;
	std::vector<btScalar> j1lin, j1ang, j2lin, j2ang, error, cfm, lower, upper;
	btTypedConstraint::btConstraintInfo2 info;
	RowBuffers(int reserved, int guardRows) : rows(reserved), guard(guardRows)
	{
		const size_t n = size_t((reserved + guardRows) * kSkip);
		const btScalar sentinel = std::numeric_limits<btScalar>::quiet_NaN();
		for (auto* v : {&j1lin, &j1ang, &j2lin, &j2ang, &error, &cfm, &lower, &upper})
		{
			v->assign(n, 0);
			v->shrink_to_fit();
			for (size_t i = size_t(reserved * kSkip); i < n; ++i) (*v)[i] = sentinel;
		}
		for (int i = 0; i < reserved * kSkip; ++i)
		{
			lower[size_t(i)] = -SIMD_INFINITY;
			upper[size_t(i)] = SIMD_INFINITY;
		}
		info.fps = 60;
		info.erp = btScalar(0.2);
		info.m_J1linearAxis = j1lin.data();
		info.m_J1angularAxis = j1ang.data();
		info.m_J2linearAxis = j2lin.data();
		info.m_J2angularAxis = j2ang.data();
		info.rowskip = kSkip;
		info.m_constraintError = error.data();
		info.cfm = cfm.data();
		info.m_lowerLimit = lower.data();
		info.m_upperLimit = upper.data();
		info.m_numIterations = 10;
		info.m_damping = 1;
	}
	/// Guard rows untouched (still NaN everywhere).
	bool guardIntact() const
	{
		for (const auto* v : {&j1lin, &j1ang, &j2lin, &j2ang, &error, &cfm, &lower, &upper})
			for (size_t i = size_t(rows * kSkip); i < v->size(); ++i)
				if (!std::isnan((*v)[i])) return false;
		return true;
	}
	/// How many reserved rows carry a non-zero Jacobian entry (rows written).
	int written() const
	{
		int n = 0;
		for (int r = 0; r < rows; ++r)
		{
			bool any = false;
			for (const auto* v : {&j1lin, &j1ang, &j2lin, &j2ang})
				for (int k = 0; k < 3; ++k) any = any || (*v)[size_t(r * kSkip + k)] != 0;
			n += any;
		}
		return n;
	}
};

struct Pair
{
	btBoxShape shape{btVector3(1, 1, 1)};
	btRigidBody base{0, nullptr, &shape, btVector3(0, 0, 0)};
	btRigidBody wheel{1, nullptr, &shape, btVector3(1, 1, 1)};
	btQuaternionHingeConstraint hinge{base, wheel, btTransform::getIdentity(), btTransform::getIdentity(), true};
};

btTransform turned(double angle) { return btTransform(btQuaternion(btVector3(0, 0, 1), btScalar(angle))); }
}  // namespace

TEST(RowReservation, LimitActivatingBetweenInfo1AndInfo2StaysInsideTheReservation)
{
	// getInfo1NonVirtual at a free pose (angle 0, limit ±1 with softness 1: no row needed there), then
	// getInfo2NonVirtual at transforms past the upper stop (1.3 rad): the limit row is written, inside the reservation.
	for (int guard : {0, 2})  // 0: exactly the reserved rows (ASan), 2: guard rows checked
		for (bool motor : {false, true})
		{
			Pair p;
			p.hinge.setLimit(-1, 1, 1);
			if (motor) p.hinge.enableAngularMotor(true, 1, 2);
			btTypedConstraint::btConstraintInfo1 info1;
			p.hinge.getInfo1(&info1);
			ASSERT_EQ(info1.m_numConstraintRows, motor ? 6 : 5);  // the virtual path: exactly the rows needed now
			p.hinge.getInfo1NonVirtual(&info1);
			EXPECT_EQ(info1.m_numConstraintRows, motor ? 7 : 6);  // the non-virtual path: the limit row reserved
			RowBuffers rows(info1.m_numConstraintRows, guard);
			p.hinge.getInfo2NonVirtual(&rows.info, btTransform::getIdentity(), turned(1.3), btVector3(0, 0, 0),
									   btVector3(0, 0, 0));
			EXPECT_TRUE(rows.guardIntact()) << "motor " << motor;
			EXPECT_EQ(rows.written(), info1.m_numConstraintRows) << "motor " << motor;  // the limit row is there
			EXPECT_EQ(p.hinge.getLimitSign(), -1);                                      // at the upper stop
			const int last = info1.m_numConstraintRows - 1;                             // the limit row comes last
			EXPECT_EQ(rows.upper[size_t(last * kSkip)], 0);                             // upper stop: impulse ≤ 0
		}
}

TEST(RowReservation, SettersBetweenInfo1AndInfo2NeverOverrunTheReservation)
{
	// Whatever a caller changes between getInfo1 and getInfo2 (a motor, friction, a limit, angular-only off), the
	// rows written stay within what getInfo1 reserved.
	for (int change = 0; change < 4; ++change)
	{
		Pair p;
		p.hinge.setAngularOnly(change == 3);
		p.wheel.setCenterOfMassTransform(turned(1.3));
		btTypedConstraint::btConstraintInfo1 info1;
		p.hinge.getInfo1(&info1);
		const int reserved = info1.m_numConstraintRows;
		ASSERT_EQ(reserved, change == 3 ? 2 : 5);
		switch (change)
		{
			case 0: p.hinge.enableAngularMotor(true, 1, 2); break;
			case 1: p.hinge.setMaxFrictionTorque(3); break;
			case 2: p.hinge.setLimit(-1, 1, 1); break;
			case 3: p.hinge.setAngularOnly(false); break;
		}
		RowBuffers rows(reserved, 2);
		p.hinge.getInfo2(&rows.info);
		EXPECT_TRUE(rows.guardIntact()) << "change " << change;
		EXPECT_LE(rows.written(), reserved) << "change " << change;
	}
}

TEST(RowReservation, StocksInternalRowFormsWriteWhatGetInfo2NonVirtualWrites)
{
	// getInfo2Internal and getInfo2InternalUsingFrameOffset (stock's two formulations, here kept for source
	// compatibility): the same rows, bit for bit, as getInfo2NonVirtual at the same arguments, inside the same
	// reservation, at a free pose and past a stop.
	for (double angle : {0.3, 1.3})
	{
		Pair reference, internal, offset;
		for (Pair* p : {&reference, &internal, &offset})
		{
			p->hinge.setLimit(-1, 1, 1);
			p->hinge.enableAngularMotor(true, 1, 2);
		}
		btTypedConstraint::btConstraintInfo1 info1;
		for (Pair* p : {&internal, &offset, &reference}) p->hinge.getInfo1NonVirtual(&info1);  // as the solver does
		RowBuffers r(info1.m_numConstraintRows, 2), i(info1.m_numConstraintRows, 2), o(info1.m_numConstraintRows, 2);
		const btVector3 w0(0, 0, 0), w1(0, 0, btScalar(0.5));
		reference.hinge.getInfo2NonVirtual(&r.info, btTransform::getIdentity(), turned(angle), w0, w1);
		internal.hinge.getInfo2Internal(&i.info, btTransform::getIdentity(), turned(angle), w0, w1);
		offset.hinge.getInfo2InternalUsingFrameOffset(&o.info, btTransform::getIdentity(), turned(angle), w0, w1);
		for (const RowBuffers* b : {&i, &o})
		{
			EXPECT_TRUE(b->guardIntact()) << "angle " << angle;
			EXPECT_EQ(b->written(), r.written()) << "angle " << angle;
			// every array, the guard rows' sentinels (NaN) included
			auto same = [](const std::vector<btScalar>& x, const std::vector<btScalar>& y) {
				return std::equal(x.begin(), x.end(), y.begin(), y.end(),
								  [](btScalar u, btScalar v) { return u == v || (std::isnan(u) && std::isnan(v)); });
			};
			EXPECT_TRUE(same(b->j1lin, r.j1lin) && same(b->j1ang, r.j1ang) && same(b->j2lin, r.j2lin) &&
						same(b->j2ang, r.j2ang))
				<< "angle " << angle;
			EXPECT_TRUE(same(b->error, r.error) && same(b->cfm, r.cfm)) << "angle " << angle;
			EXPECT_TRUE(same(b->lower, r.lower) && same(b->upper, r.upper)) << "angle " << angle;
		}
		EXPECT_EQ(r.written(), angle > 1 ? info1.m_numConstraintRows : info1.m_numConstraintRows - 1);
	}
}
