// libFuzzer target: random frames, body states (zero masses, NaN and Inf included) and joint parameters go through
// the constructors and setters (a refusal is fine), then getInfo1/getInfo2 and a few world steps. It aborts when:
//   - getInfo2 writes a non-finite row or error while the bodies' states are finite,
//   - a non-faulted joint's two angular rows are not of rank 2 (Gram determinant ≤ kMinGram),
//   - the rows filled differ from getInfo1's count (the scratch rows beyond it are checked untouched),
//   - a world step turns finite bodies non-finite.
#include "quathinge/btQuaternionHingeConstraint.h"

#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

namespace
{
// Gram determinant of the two angular rows: c² ≥ ½ in the Q7 region, ≈ 1 in the log region (QuaternionHingeRows.h),
// scaled by |rows|²; anything below this is a rank loss.
const double kMinGram = 1e-3;

struct Bytes
{
	const uint8_t* data;
	size_t size;
	size_t at = 0;
	uint8_t byte() { return at < size ? data[at++] : 0; }
	float raw()
	{
		float f = 0;
		if (at + 4 <= size) std::memcpy(&f, data + at, 4);
		at += 4;
		return f;
	}
	// mostly a sane value in [lo, hi]; now and then a raw float (NaN, Inf, huge)
	btScalar value(float lo, float hi)
	{
		const uint8_t mode = byte();
		if (mode < 16) return btScalar(raw());
		return btScalar(lo + (hi - lo) * (byte() / 255.0f));
	}
	btVector3 vec(float lo, float hi) { return btVector3(value(lo, hi), value(lo, hi), value(lo, hi)); }
	btQuaternion rotation()
	{
		btQuaternion q(value(-1, 1), value(-1, 1), value(-1, 1), value(-1, 1));
		const btScalar n = q.length();
		return std::isfinite(n) && n > btScalar(1e-3) ? q / n : btQuaternion::getIdentity();
	}
};

bool finite(const btVector3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

bool finiteBody(const btRigidBody& b)
{
	const btTransform& t = b.getCenterOfMassTransform();
	return finite(t.getOrigin()) && finite(t.getBasis()[0]) && finite(t.getBasis()[1]) && finite(t.getBasis()[2]) &&
		   finite(b.getLinearVelocity()) && finite(b.getAngularVelocity());
}

void check(bool ok, const char* what)
{
	if (!ok)
	{
		std::fprintf(stderr, "quathinge_fuzz: %s\n", what);
		std::abort();
	}
}

btTransform frame(Bytes& in) { return btTransform(in.rotation(), in.vec(-2, 2)); }
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	Bytes in{data, size};
	btBoxShape shape(btVector3(btScalar(0.2), btScalar(0.5), btScalar(0.2)));
	const btScalar massA = in.byte() < 64 ? 0 : in.value(btScalar(0.01), 100);
	const btScalar massB = in.byte() < 32 ? 0 : in.value(btScalar(0.01), 100);
	btVector3 inertiaA(0, 0, 0), inertiaB(0, 0, 0);
	if (std::isfinite(massA) && massA > 0) shape.calculateLocalInertia(massA, inertiaA);
	if (std::isfinite(massB) && massB > 0) shape.calculateLocalInertia(massB, inertiaB);
	btRigidBody a(std::isfinite(massA) && massA > 0 ? massA : 0, nullptr, &shape, inertiaA);
	btRigidBody b(std::isfinite(massB) && massB > 0 ? massB : 0, nullptr, &shape, inertiaB);
	a.setWorldTransform(btTransform(in.rotation(), in.vec(-3, 3)));
	b.setWorldTransform(btTransform(in.rotation(), in.vec(-3, 3)));
	a.setLinearVelocity(in.vec(-20, 20));
	a.setAngularVelocity(in.vec(-50, 50));
	b.setLinearVelocity(in.vec(-20, 20));
	b.setAngularVelocity(in.vec(-50, 50));

	btQuaternionHingeConstraint* joint = nullptr;
	try
	{
		switch (in.byte() % 4)
		{
			case 0: joint = new btQuaternionHingeConstraint(a, b, in.vec(-1, 1), in.vec(-1, 1), in.vec(-1, 1), in.vec(-1, 1), in.byte() & 1); break;
			case 1: joint = new btQuaternionHingeConstraint(a, in.vec(-1, 1), in.vec(-1, 1), in.byte() & 1); break;
			case 2: joint = new btQuaternionHingeConstraint(a, b, frame(in), frame(in), in.byte() & 1); break;
			default: joint = new btQuaternionHingeConstraint(a, frame(in), in.byte() & 1); break;
		}
	}
	catch (const std::invalid_argument&)
	{
		return 0;  // refused: nothing reached the solver
	}
	for (int k = 0, n = in.byte() % 8; k < n; ++k)
	{
		try
		{
			switch (in.byte() % 10)
			{
				case 0: joint->setLimit(in.value(-20, 20), in.value(-20, 20), in.value(0, 1), in.value(0, 1), in.value(0, 1)); break;
				case 1: joint->enableAngularMotor(in.byte() & 1, in.value(-50, 50), in.value(-1, 10)); break;
				case 2: joint->setServoTarget(in.value(-20, 20), in.value(-1, 50), in.value(-1, 100)); break;
				case 3: joint->setSpring(in.value(-5, 5), in.value(-1, 30), in.value(-1, 3)); break;
				case 4: joint->setMaxFrictionTorque(in.value(-1, 10)); break;
				case 5: joint->setParam(1 + in.byte() % 5, in.value(-0.5f, 1.5f), int(in.byte() % 8) - 1); break;
				case 6: joint->setAngularOnly(in.byte() & 1); break;
				case 7: joint->removeLimit(); break;
				case 8: joint->setMotorTarget(in.value(-10, 10), in.value(-0.1f, 0.1f)); break;
				default: joint->setFrames(frame(in), frame(in)); break;
			}
		}
		catch (const std::invalid_argument&)
		{
		}
	}

	const bool finiteInput = finiteBody(a) && finiteBody(b);
	btTypedConstraint::btConstraintInfo1 info1;
	joint->getInfo1(&info1);
	check(info1.m_numConstraintRows >= 0 && info1.m_numConstraintRows <= 8, "row count out of range");
	const int kStride = 16, kRows = 9;
	static btScalar rows[6][kRows * kStride];
	for (auto& r : rows)
		for (btScalar& v : r) v = btScalar(1234.5);  // sentinel: rows past the count must stay untouched
	for (int r = 0; r < kRows; ++r)
		for (int k = 0; k < 3; ++k) rows[0][r * kStride + k] = rows[1][r * kStride + k] = rows[2][r * kStride + k] = rows[3][r * kStride + k] = 0;
	btTypedConstraint::btConstraintInfo2 info;
	info.fps = 60;
	info.erp = btScalar(0.2);
	info.m_J1linearAxis = rows[0];
	info.m_J1angularAxis = rows[1];
	info.m_J2linearAxis = rows[2];
	info.m_J2angularAxis = rows[3];
	info.m_constraintError = rows[4];
	info.cfm = rows[5];
	static btScalar lower[kRows * kStride], upper[kRows * kStride];
	info.m_lowerLimit = lower;
	info.m_upperLimit = upper;
	info.rowskip = kStride;
	info.m_numIterations = 10;
	info.m_damping = 1;
	const int n = info1.m_numConstraintRows;
	for (int r = 0; r < n; ++r) rows[4][r * kStride] = 0;
	joint->getInfo2(&info);
	if (finiteInput && n > 0)
	{
		for (int r = 0; r < n; ++r)
		{
			for (int m = 0; m < 4; ++m)
				for (int k = 0; k < 3; ++k) check(std::isfinite(rows[m][r * kStride + k]), "non-finite Jacobian entry");
			check(std::isfinite(rows[4][r * kStride]), "non-finite constraint error");
		}
		for (int r = n; r < kRows; ++r) check(rows[4][r * kStride] == btScalar(1234.5), "a row beyond getInfo1's count was written");
		const int first = joint->getAngularOnly() ? 0 : 3;
		const btVector3 u(rows[3][first * kStride], rows[3][first * kStride + 1], rows[3][first * kStride + 2]);
		const btVector3 v(rows[3][(first + 1) * kStride], rows[3][(first + 1) * kStride + 1], rows[3][(first + 1) * kStride + 2]);
		const double gram = double(u.length2()) * v.length2() - double(u.dot(v)) * u.dot(v);
		check(gram > kMinGram * std::max(1.0, double(u.length2()) * v.length2()), "angular rows lost rank");
	}

	// A few steps in a world.
	if (finiteInput && joint->getFault() == BT_QHINGE_FAULT_NONE)
	{
		btDefaultCollisionConfiguration config;
		btCollisionDispatcher dispatcher(&config);
		btDbvtBroadphase broadphase;
		btSequentialImpulseConstraintSolver solver;
		btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
		world.addRigidBody(&a, 0, 0);
		world.addRigidBody(&b, 0, 0);
		world.addConstraint(joint, true);
		// Bullet's own integrator overflows on absurd inputs (|ω|² of 1e34 rad/s, or m·g of a 1e37 kg body, is infinite
		// in float): only speeds below kSaneSpeed (m/s, rad/s) and masses below kSaneMass (kg) must stay finite; beyond
		// them the joint is not the source (its rows were checked finite above). kSaneMass bounds mass and inverse mass.
		const double kSaneSpeed = 1e6, kSaneMass = 1e6;
		auto saneMass = [&](const btRigidBody& x) {
			return x.getInvMass() == 0 || (1.0 / double(x.getInvMass()) < kSaneMass && double(x.getInvMass()) < kSaneMass);
		};
		const bool sane = a.getLinearVelocity().length() < kSaneSpeed && b.getLinearVelocity().length() < kSaneSpeed &&
						  a.getAngularVelocity().length() < kSaneSpeed && b.getAngularVelocity().length() < kSaneSpeed &&
						  saneMass(a) && saneMass(b);
		for (int i = 0; i < 3; ++i) world.stepSimulation(btScalar(1) / 60, 0, btScalar(1) / 60);
		if (sane) check(finiteBody(a) && finiteBody(b), "a step turned finite bodies non-finite");
		world.removeConstraint(joint);
		world.removeRigidBody(&a);
		world.removeRigidBody(&b);
	}
	delete joint;
	return 0;
}
