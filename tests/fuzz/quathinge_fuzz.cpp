// libFuzzer target for btQuaternionHingeConstraint (tests/fuzz/run_fuzz.sh builds and runs it; make_corpus.py writes
// the hand-made seeds; FINDINGS.md lists what it found).
// The input bytes decode into three bodies (masses, zero included; poses; velocities; now and then a raw float: NaN,
// ±Inf, huge, denormal), one or two joints built through every entry point (the four stock constructors, the
// settings constructor, the conversion from a stock btHingeConstraint; a refusal, std::invalid_argument, is fine),
// a sequence of setters (limit, motor, servo, spring, friction, ERP/CFM, frames, axis, multi-turn angle, frame
// edits through the non-const reference, ...), optionally a serialize → corrupt → deserialize round trip, then
// getInfo1/getInfo2 on scratch rows and a few world steps (with the post-stabilizer when it is built), with more
// setters between the steps. It aborts — libFuzzer saves the input — when:
//   - getInfo1 reports a row count outside [0, kMaxRows], or getNumRowsLastStep() disagrees with it;
//   - a joint without a fault has a frame that is not rigid (rotation; pivot within 1e6 m on a dynamic body), or
//     any joint a negative or NaN breaking impulse threshold (the harness sets valid ones: only the deserializer
//     can);
//   - a step hangs (libFuzzer's -timeout: run_fuzz.sh gives an input 20 s);
//   - a body's state is non-finite and the joint still reports rows (README: 0 rows, the joint disables itself);
//   - getInfo2 writes a non-finite Jacobian entry, error or CFM, a negative CFM, a NaN or inverted bound, or touches
//     any entry of a row past getInfo1's count (those rows belong to the next constraint in the solver);
//   - a joint that is not faulted has angular rows of rank < 2 (relative Gram determinant ≤ kMinGram);
//   - computePositionRows gives a non-finite C or J, or debugDraw a non-finite line, for a joint without a fault;
//   - a world step turns a body non-finite that was finite and sane and joined only to sane bodies, or to NaN ones
//     (a NaN body must not spread through the joint);
//   - AddressSanitizer or UndefinedBehaviorSanitizer report anything (the whole build is instrumented).
// The decoding reads the bytes in argument-evaluation order in places (f(in.value(), in.value())): a saved input
// reproduces with the clang build that found it (run_fuzz.sh), which is the only build of this target.
#include "quathinge/btQuaternionHingeConstraint.h"
#include "quathinge/btQuaternionHingeSerialization.h"
#ifdef QUATHINGE_HAVE_STABILIZER
#include "quathinge/btQuaternionHingeStabilizer.h"
#endif

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <vector>

namespace
{
// Relative Gram determinant of the two angular rows, det([u v]ᵀ[u v]) / (|u|²|v|²) = sin² of the angle between them:
// the rows are orthogonal on the hinge and stay well apart everywhere (QuaternionHingeRows.h: c² ≥ ½ in the Q7
// region, ≈ 1 in the log region); below this they have lost rank. (The brief's absolute bound, 1e-6, is implied:
// a row has unit length on the hinge, MATH.md Q9.)
const double kMinGram = 1e-3;
// The most rows a joint reports: 3 linear + 2 angular + drive + friction + limit.
const int kMaxRows = 8;
// Beyond these a body is not "sane" and the world-step check does not apply to it: speeds (m/s, rad/s) whose square
// overflows float in Bullet's own integrator, masses (kg) and inverse masses whose products with g do. The joint
// itself faults bodies beyond 1e15 (finiteBodyState in btQuaternionHingeConstraint.cpp).
const double kSaneSpeed = 1e6;
const double kSaneMass = 1e6;
const double kSanePosition = 1e6;  // m
// rad per step: a body spinning faster than this (|ω|·dt) is not sane either. Bullet's implicit gyroscopic step
// (BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY, on by default) can diverge on its own there: a lone body with no joint,
// inverse inertia (8.7, 31.6, 8.7), at 1.5e5 rad/s and 0.1 s steps (1.5e4 rad per step) reached NaN in six steps
// (FINDINGS.md, bullet-gyroscopic-spin). 200 lone bodies with random inertia ratios up to 100 stayed finite up to
// 3e4 rad per step, so this bound is fifteen times below the one divergence seen.
const double kSaneTurnPerStep = 1e3;
// A drive the input set to absurd but finite values (a motor's target velocity of 1e30 rad/s with an impulse of 1e30
// N·m·s) throws its bodies out of float range in one step, in stock Bullet's btHingeConstraint as in this joint, which
// keeps stock's meaning for every finite value (FINDINGS.md, drive-beyond-float-range). The world-step check does not
// hold a body to finiteness once a drive of its group can make it turn faster than kSaneSpeed, or more than
// kSaneTurnPerStep in a step (driveSpeedBound).
// Joint frames: the pivot bound the joint enforces (InputChecks.h, kMaxPivotDistance, m) and how far from orthonormal
// a frame may be (10x the 1e-4 the joint accepts from a user).
const btScalar kMaxPivot = btScalar(1e6);
const btScalar kFrameTolerance = btScalar(1e-3);
// Scratch rows: the solver's row stride is at least 8 entries; a wider stride shows writes past a row's three.
const int kStride = 16;
const int kScratchRows = kMaxRows + 2;
const btScalar kSentinel = btScalar(1234.5);

void check(bool ok, const char* what)
{
	if (!ok)
	{
		std::fprintf(stderr, "quathinge_fuzz: %s\n", what);
		std::abort();
	}
}

// QUATHINGE_FUZZ_VERBOSE=1 quathinge_fuzz <input>: prints the decoded scene, the rows and the bodies after every
// step (%.9g: enough to rebuild a finding as a plain test).
const bool kVerbose = std::getenv("QUATHINGE_FUZZ_VERBOSE") != nullptr;

// A transform as C++ with exact (hexadecimal) floats, to paste into a plain test.
void traceTransform(const char* what, const btTransform& t)
{
	const btMatrix3x3& m = t.getBasis();
	const btVector3& o = t.getOrigin();
	std::fprintf(stderr, "  %s = btTransform(btMatrix3x3(%a, %a, %a, %a, %a, %a, %a, %a, %a), btVector3(%a, %a, %a))\n",
				 what, double(m[0][0]), double(m[0][1]), double(m[0][2]), double(m[1][0]), double(m[1][1]),
				 double(m[1][2]), double(m[2][0]), double(m[2][1]), double(m[2][2]), double(o.x()), double(o.y()),
				 double(o.z()));
}

void traceBody(const char* when, int i, const btRigidBody& b)
{
	if (!kVerbose) return;
	const btVector3 p = b.getCenterOfMassPosition(), v = b.getLinearVelocity(), w = b.getAngularVelocity();
	traceTransform("transform", b.getCenterOfMassTransform());
	const btVector3 lv = b.getLinearVelocity(), av = b.getAngularVelocity();
	std::fprintf(stderr, "  velocities = btVector3(%a, %a, %a), btVector3(%a, %a, %a)\n", double(lv.x()), double(lv.y()),
				 double(lv.z()), double(av.x()), double(av.y()), double(av.z()));
	std::fprintf(stderr,
				 "%s body %d: inv mass %.9g, inv inertia (%.9g %.9g %.9g), x (%.9g %.9g %.9g), v (%.9g %.9g %.9g), "
				 "w (%.9g %.9g %.9g)\n",
				 when, i, double(b.getInvMass()), double(b.getInvInertiaDiagLocal().x()),
				 double(b.getInvInertiaDiagLocal().y()), double(b.getInvInertiaDiagLocal().z()), double(p.x()),
				 double(p.y()), double(p.z()), double(v.x()), double(v.y()), double(v.z()), double(w.x()), double(w.y()),
				 double(w.z()));
}

void traceJoint(const char* when, const btQuaternionHingeConstraint& j)
{
	if (!kVerbose) return;
	traceTransform("frameInA", j.getSettings().frameInA);
	traceTransform("frameInB", j.getSettings().frameInB);
	const btQuaternionHingeSettings& s = j.getSettings();
	const btVector3 pA = s.frameInA.getOrigin(), pB = s.frameInB.getOrigin();
	const btVector3 hA = s.frameInA.getBasis().getColumn(2), hB = s.frameInB.getBasis().getColumn(2);
	std::fprintf(stderr,
				 "%s joint: pivots (%.9g %.9g %.9g) (%.9g %.9g %.9g), axes (%.9g %.9g %.9g) (%.9g %.9g %.9g), refA %d, "
				 "angular-only %d, "
				 "limit %d [%g, %g] soft %g bias %g relax %g, drive %d (motor %g, %g; servo %g, %g, %g; spring %g, %g "
				 "Hz, %g), friction %g, flags 0x%x, erp (%g %g %g %g %g %g) cfm (%g %g %g %g %g %g) stop %g %g, "
				 "enabled %d, fault %d, rows %d, breaking impulse %g, solver iterations override %d\n",
				 when, double(pA.x()), double(pA.y()), double(pA.z()), double(pB.x()), double(pB.y()), double(pB.z()),
				 double(hA.x()), double(hA.y()), double(hA.z()), double(hB.x()), double(hB.y()), double(hB.z()),
				 int(s.useReferenceFrameA), int(s.angularOnly), int(s.hasLimit), double(s.lowerLimit),
				 double(s.upperLimit), double(s.limitSoftness), double(s.limitBiasFactor),
				 double(s.limitRelaxationFactor), int(s.driveMode), double(s.motorTargetVelocity),
				 double(s.maxMotorImpulse), double(s.servoTargetAngle), double(s.servoMaxSpeed),
				 double(s.servoMaxTorque), double(s.springRestAngle), double(s.springFrequency),
				 double(s.springDampingRatio), double(s.maxFrictionTorque), unsigned(s.flags), double(s.rowErp[0]),
				 double(s.rowErp[1]), double(s.rowErp[2]), double(s.rowErp[3]), double(s.rowErp[4]),
				 double(s.rowErp[5]), double(s.rowCfm[0]), double(s.rowCfm[1]), double(s.rowCfm[2]),
				 double(s.rowCfm[3]), double(s.rowCfm[4]), double(s.rowCfm[5]), double(s.stopErp), double(s.stopCfm),
				 int(j.isEnabled()), int(j.getFault()), j.getNumRowsLastStep(), double(j.getBreakingImpulseThreshold()),
				 j.getOverrideNumSolverIterations());
}

bool finite(btScalar v) { return std::isfinite(v); }
bool finite(const btVector3& v) { return finite(v.x()) && finite(v.y()) && finite(v.z()); }
bool finite(const btTransform& t)
{
	return finite(t.getOrigin()) && finite(t.getBasis()[0]) && finite(t.getBasis()[1]) && finite(t.getBasis()[2]);
}
bool finiteBody(const btRigidBody& b)
{
	return finite(b.getCenterOfMassTransform()) && finite(b.getLinearVelocity()) && finite(b.getAngularVelocity());
}
// A body the world step must keep finite: finite, inside kSane*, with a finite non-negative inverse mass.
bool saneBody(const btRigidBody& b)
{
	const double invMass = b.getInvMass();
	const bool massOk = invMass == 0 || (std::isfinite(invMass) && invMass > 0 && invMass < kSaneMass &&
										 1 / invMass < kSaneMass && finite(b.getInvInertiaDiagLocal()) &&
										 b.getInvInertiaDiagLocal().length() < kSaneMass);
	return finiteBody(b) && massOk && b.getCenterOfMassPosition().length() < kSanePosition &&
		   b.getLinearVelocity().length() < kSaneSpeed && b.getAngularVelocity().length() < kSaneSpeed;
}

// The fastest relative turn (rad/s) the joint's drive may ask for in a step of dt s: a motor's target velocity, a servo's
// capped by its maximum speed, a servo's or spring's distance to its target over the step (both close it at most in
// one step: Bullet's implicit rows); 0 without a drive, or a motor without impulse.
double driveSpeedBound(const btQuaternionHingeConstraint& joint, btScalar dt)
{
	const btQuaternionHingeSettings& s = joint.getSettings();
	const double angle = std::fabs(double(joint.getHingeAngle()));
	switch (s.driveMode)
	{
		case BT_QHINGE_DRIVE_VELOCITY:
			return s.maxMotorImpulse > 0 ? std::fabs(double(s.motorTargetVelocity)) : 0;
		case BT_QHINGE_DRIVE_SERVO:
			return std::min(double(s.servoMaxSpeed), (std::fabs(double(s.servoTargetAngle)) + angle) / double(dt));
		case BT_QHINGE_DRIVE_SPRING:
			return (std::fabs(double(s.springRestAngle)) + angle) / double(dt);
		default:
			return 0;
	}
}

// The input as a stream of decisions and values.
class Input
{
public:
	Input(const uint8_t* data, size_t size) : m_data(data), m_size(size) {}
	uint8_t byte() { return m_at < m_size ? m_data[m_at++] : 0; }
	bool flag() { return byte() & 1; }
	int pick(int n) { return byte() % n; }
	float raw()
	{
		float f = 0;
		if (m_at + 4 <= m_size) std::memcpy(&f, m_data + m_at, 4);
		m_at += 4;
		return f;
	}
	int rawInt()
	{
		int32_t i = 0;
		if (m_at + 4 <= m_size) std::memcpy(&i, m_data + m_at, 4);
		m_at += 4;
		return i;
	}
	// Mostly a value in [lo, hi] (both ends reachable, and 0 when the range holds it); now and then a raw float.
	btScalar value(float lo, float hi)
	{
		const uint8_t mode = byte();
		if (mode < 16) return btScalar(raw());
		if (mode < 24 && lo <= 0 && hi >= 0) return 0;
		return btScalar(lo + (hi - lo) * (byte() / 255.0f));
	}
	btVector3 vec(float lo, float hi) { return btVector3(value(lo, hi), value(lo, hi), value(lo, hi)); }
	// A unit axis (a coordinate axis, a random direction, or one off unit by a little, across the 1e-4 tolerance);
	// now and then a raw vector (zero, NaN, huge).
	btVector3 axis()
	{
		const uint8_t mode = byte();
		if (mode < 16) return btVector3(raw(), raw(), raw());
		if (mode < 64) return coordinate(mode);
		btVector3 v = vec(-1, 1);
		if (!(v.length2() > btScalar(1e-6)) || !finite(v)) return btVector3(0, 0, 1);
		v.normalize();
		if (mode >= 240) v *= btScalar(1) + btScalar(int(mode) - 247) * btScalar(2e-5);  // ±1.4e-4
		return v;
	}
	btQuaternion rotation()
	{
		btQuaternion q(value(-1, 1), value(-1, 1), value(-1, 1), value(-1, 1));
		const btScalar n = q.length();
		return finite(n) && n > btScalar(1e-3) ? q / n : btQuaternion::getIdentity();
	}
	// A rigid frame; now and then one whose basis is raw (sheared, scaled, mirrored, NaN).
	btTransform frame()
	{
		if (byte() < 16)
		{
			btMatrix3x3 m;
			for (int r = 0; r < 3; ++r) m[r] = vec(-1.5f, 1.5f);
			return btTransform(m, vec(-2, 2));
		}
		return btTransform(rotation(), vec(-2, 2));
	}
	btVector3 pivot() { return vec(-2, 2); }

private:
	btVector3 coordinate(uint8_t mode)
	{
		btVector3 v(0, 0, 0);
		v[mode % 3] = (mode & 8) ? btScalar(-1) : btScalar(1);
		return v;
	}
	const uint8_t* m_data;
	size_t m_size;
	size_t m_at = 0;
};

std::unique_ptr<btRigidBody> makeBody(Input& in, btCollisionShape& shape)
{
	const uint8_t kind = in.byte();
	btScalar mass = 0;  // static
	if (kind >= 48) mass = kind < 240 ? in.value(btScalar(0.01), 100) : btScalar(in.raw());
	btVector3 inertia(0, 0, 0);
	if (finite(mass) && mass > 0) shape.calculateLocalInertia(mass, inertia);
	std::unique_ptr<btRigidBody> body(new btRigidBody(mass, nullptr, &shape, inertia));
	body->setWorldTransform(btTransform(in.rotation(), in.vec(-3, 3)));
	body->setLinearVelocity(in.vec(-20, 20));
	body->setAngularVelocity(in.vec(-50, 50));
	body->setActivationState(DISABLE_DEACTIVATION);
	return body;
}

btQuaternionHingeSettings makeSettings(Input& in)
{
	btQuaternionHingeSettings s;
	s.frameInA = in.frame();
	s.frameInB = in.frame();
	s.useReferenceFrameA = in.flag();
	s.angularOnly = in.byte() < 32;
	s.useFrameOffset = in.flag();
	s.hasLimit = in.flag();
	s.lowerLimit = in.value(-20, 20);
	s.upperLimit = in.value(-20, 20);
	s.limitSoftness = in.value(0, 1);
	s.limitBiasFactor = in.value(0, 1);
	s.limitRelaxationFactor = in.value(0, 1);
	s.driveMode = btQuaternionHingeDriveMode(in.pick(6) - 1);  // -1 and 4: not a mode
	s.motorTargetVelocity = in.value(-50, 50);
	s.maxMotorImpulse = in.value(-1, 10);
	s.servoTargetAngle = in.value(-20, 20);
	s.servoMaxSpeed = in.value(-1, 50);
	s.servoMaxTorque = in.value(-1, 100);
	s.springRestAngle = in.value(-5, 5);
	s.springFrequency = in.value(-1, 30);
	s.springDampingRatio = in.value(-1, 3);
	s.maxFrictionTorque = in.value(-1, 10);
	for (int i = 0; i < 6; ++i)
	{
		s.rowErp[i] = in.value(-0.5f, 1.5f);
		s.rowCfm[i] = in.value(-0.5f, 1.5f);
	}
	s.stopErp = in.value(-0.5f, 1.5f);
	s.stopCfm = in.value(-0.5f, 1.5f);
	const int low = in.byte(), high = in.byte();
	s.flags = low | high << 8;
	if (in.byte() < 8) s.flags = in.rawInt();  // bits no flag has, negative values
	return s;
}

// One joint between a and b (b == nullptr: to the world), through the entry point the input picks. Throws
// std::invalid_argument when the arguments are refused.
btQuaternionHingeConstraint* makeJoint(Input& in, btRigidBody& a, btRigidBody* b)
{
	const bool refA = in.flag();
	switch (in.pick(6))
	{
		case 0:
			if (b)
			{
				const btVector3 pA = in.pivot(), pB = in.pivot(), axA = in.axis(), axB = in.axis();
				return new btQuaternionHingeConstraint(a, *b, pA, pB, axA, axB, refA);
			}
			// fall through
		case 1:
		{
			const btVector3 p = in.pivot(), ax = in.axis();
			return new btQuaternionHingeConstraint(a, p, ax, refA);
		}
		case 2:
			if (b)
			{
				const btTransform fA = in.frame(), fB = in.frame();
				return new btQuaternionHingeConstraint(a, *b, fA, fB, refA);
			}
			// fall through
		case 3: return new btQuaternionHingeConstraint(a, in.frame(), refA);
		case 4: return new btQuaternionHingeConstraint(a, b ? *b : btTypedConstraint::getFixedBody(), makeSettings(in));
		default:
		{
			// Stock accepts anything (NaN axes, low > high, negative impulses): the conversion must refuse or repair.
			btVector3 pA = in.pivot(), pB = in.pivot(), axA = in.axis(), axB = in.axis();
			std::unique_ptr<btHingeConstraint> stock(
				b ? new btHingeConstraint(a, *b, pA, pB, axA, axB, refA) : new btHingeConstraint(a, pA, axA, refA));
			if (in.flag())
				stock->setLimit(in.value(-4, 4), in.value(-4, 4), in.value(-1, 2), in.value(-1, 2), in.value(-1, 2));
			if (in.flag()) stock->enableAngularMotor(in.flag(), in.value(-50, 50), in.value(-1, 10));
			for (int k = 0, n = in.pick(3); k < n; ++k)
			{
				// stock takes axis -1 or 5 only (it asserts on the others in debug builds)
				const int num = 1 + in.pick(4), axis = in.flag() ? -1 : 5;
				stock->setParam(num, in.value(-0.5f, 1.5f), axis);
			}
			stock->setAngularOnly(in.byte() < 32);
			return new btQuaternionHingeConstraint(*stock);
		}
	}
}

// A transform of the frame edited through getFrameOffsetA/B: a rigid change (allowed) or a raw entry (not rigid).
void editFrame(Input& in, btTransform& frame)
{
	switch (in.pick(3))
	{
		case 0: frame.getOrigin() = in.pivot(); break;
		case 1: frame.setRotation(in.rotation()); break;
		default: frame.getBasis()[in.pick(3)][in.pick(3)] = in.value(-2, 2); break;
	}
}

// One setter (or getter with a side effect) the input picks; a refusal is fine.
void applySetter(Input& in, btQuaternionHingeConstraint& j)
{
	try
	{
		switch (in.pick(20))
		{
			case 0: j.setLimit(in.value(-20, 20), in.value(-20, 20), in.value(0, 1), in.value(0, 1), in.value(0, 1)); break;
			case 1: j.enableAngularMotor(in.flag(), in.value(-50, 50), in.value(-1, 10)); break;
			case 2: j.setServoTarget(in.value(-20, 20), in.value(-1, 50), in.value(-1, 100)); break;
			case 3: j.setSpring(in.value(-5, 5), in.value(-1, 30), in.value(-1, 3)); break;
			case 4: j.setMaxFrictionTorque(in.value(-1, 10)); break;
			case 5: j.setParam(1 + in.pick(5), in.value(-0.5f, 1.5f), in.pick(8) - 1); break;
			case 6: j.setAngularOnly(in.byte() < 64); break;
			case 7: j.removeLimit(); break;
			case 8: j.setMotorTarget(in.value(-10, 10), in.value(-0.1f, 0.1f)); break;
			case 9:
			{
				const btTransform fA = in.frame(), fB = in.frame();
				j.setFrames(fA, fB);
				break;
			}
			case 10:
			{
				btVector3 axis = in.axis();
				j.setAxis(axis);
				break;
			}
			case 11:
			{
				// the current angle plus whole turns (accepted), off by a little (refused past 1e-3 rad), or raw
				const btScalar turns = btScalar(int(in.pick(9)) - 4) * SIMD_2_PI;
				j.setMultiTurnAngle(j.getHingeAngle() + turns + in.value(-0.002f, 0.002f));
				break;
			}
			case 12:
				j.setMotorTarget(btQuaternion(in.value(-1, 1), in.value(-1, 1), in.value(-1, 1), in.value(-1, 1)),
								 in.value(-0.1f, 0.1f));
				break;
			case 13:
				if (in.flag()) j.disableDrive();
				else j.enableMotor(in.flag());
				break;
			case 14:
				if (in.flag()) j.setMaxMotorImpulse(in.value(-1, 10));
				else j.setMotorTargetVelocity(in.value(-50, 50));
				break;
			case 15:
				if (in.flag()) j.setUseReferenceFrameA(in.flag());
				else j.setUseFrameOffset(in.flag());
				break;
			case 16: editFrame(in, in.flag() ? j.getFrameOffsetA() : j.getFrameOffsetB()); break;
			case 17:
				(void)j.getMultiTurnAngle();  // turns the tracking on
				if (in.flag()) j.clearFault();
				break;
			case 18:
				// btTypedConstraint's own setters (Bullet's, not the joint's: not checked, so kept to valid values; a
				// negative threshold inverts every row's bounds in Bullet's solver, stock hinge or not). The
				// deserializer sets them from the file, where anything goes.
				if (in.flag()) j.setEnabled(in.byte() >= 16);
				else j.setBreakingImpulseThreshold(in.byte() < 16 ? SIMD_INFINITY : btScalar(in.byte()));
				break;
			default: (void)j.getParam(1 + in.pick(5), in.pick(8) - 1); break;
		}
	}
	catch (const std::invalid_argument&)
	{
	}
}

// Serializes the joint (its QuatHinge chunk), overwrites a few bytes of it as the input says, and reads it back: a refusal keeps
// the original joint, an acceptance replaces it.
btQuaternionHingeConstraint* roundTrip(Input& in, btQuaternionHingeConstraint* joint)
{
	btQuaternionHingeChunkData chunk;
	btQuaternionHingeFillChunk(*joint, chunk);  // the QuatHinge chunk serialize() writes
	std::vector<unsigned char> buffer(sizeof chunk);
	std::memcpy(buffer.data(), &chunk, sizeof chunk);
	for (int k = 0, n = in.pick(6); k < n; ++k)
	{
		const size_t high = in.byte(), low = in.byte();
		const size_t at = (high << 8 | low) % buffer.size();
		const int width = 1 << in.pick(4);  // 1, 2, 4 or 8 bytes from the input
		for (int i = 0; i < width && at + i < buffer.size(); ++i) buffer[at + i] = in.byte();
	}
	try
	{
		btQuaternionHingeConstraint* copy =
			btQuaternionHingeDeserialize(buffer.data(), buffer.size(), joint->getRigidBodyA(), joint->getRigidBodyB());
		delete joint;
		return copy;
	}
	catch (const std::invalid_argument&)
	{
		return joint;
	}
}

// Scratch rows as the solver lays them out: rows [0, n) prepared as the solver prepares them (Jacobians, error and
// CFM zero, bounds ±∞), rows from n on filled with a sentinel that must survive.
struct Scratch
{
	btScalar j[4][kScratchRows * kStride];  // J1 linear, J1 angular, J2 linear, J2 angular
	btScalar error[kScratchRows * kStride], cfm[kScratchRows * kStride];
	btScalar lower[kScratchRows * kStride], upper[kScratchRows * kStride];
	btTypedConstraint::btConstraintInfo2 info;

	Scratch(int n, Input& in)
	{
		btScalar* all[] = {j[0], j[1], j[2], j[3], error, cfm, lower, upper};
		for (btScalar* a : all) std::fill(a, a + kScratchRows * kStride, kSentinel);
		for (int r = 0; r < n; ++r)
		{
			for (auto& m : j) std::fill(m + r * kStride, m + r * kStride + 3, btScalar(0));
			error[r * kStride] = 0;
			cfm[r * kStride] = 0;
			lower[r * kStride] = -SIMD_INFINITY;
			upper[r * kStride] = SIMD_INFINITY;
		}
		const btScalar rates[] = {60, 30, 240, 1000};
		info.fps = rates[in.pick(4)];
		info.erp = btScalar(in.byte()) / 255;  // the solver's global ERP (Bullet's own setting: not fuzzed beyond [0, 1])
		info.m_J1linearAxis = j[0];
		info.m_J1angularAxis = j[1];
		info.m_J2linearAxis = j[2];
		info.m_J2angularAxis = j[3];
		info.m_constraintError = error;
		info.cfm = cfm;
		info.m_lowerLimit = lower;
		info.m_upperLimit = upper;
		info.rowskip = kStride;
		info.m_numIterations = 10;
		info.m_damping = 1;
	}
	btVector3 row(int m, int r) const { return btVector3(j[m][r * kStride], j[m][r * kStride + 1], j[m][r * kStride + 2]); }
};

struct CheckingDrawer : btIDebugDraw
{
	int mode = DBG_DrawConstraints | DBG_DrawConstraintLimits;
	void drawLine(const btVector3& from, const btVector3& to, const btVector3&) override
	{
		check(finite(from) && finite(to), "debugDraw drew a non-finite line");
	}
	void drawContactPoint(const btVector3&, const btVector3&, btScalar, int, const btVector3&) override {}
	void reportErrorWarning(const char*) override {}
	void draw3dText(const btVector3&, const char*) override {}
	void setDebugMode(int m) override { mode = m; }
	int getDebugMode() const override { return mode; }
};

// A joint frame as the settings promise it: a rotation (unit, orthogonal columns within kFrameTolerance, right-handed)
// and a finite pivot, within kMaxPivot of the centre of mass on a dynamic body (where r × ω must stay in range; the
// world-side pivot of a joint to the world is where the body was, which may be anywhere).
bool rigidFrame(const btTransform& t, const btRigidBody& body)
{
	if (!finite(t) || (body.getInvMass() != 0 && t.getOrigin().length() > kMaxPivot)) return false;
	const btMatrix3x3& m = t.getBasis();
	for (int i = 0; i < 3; ++i)
		for (int j = 0; j < 3; ++j)
			if (btFabs(m.getColumn(i).dot(m.getColumn(j)) - (i == j ? 1 : 0)) > kFrameTolerance) return false;
	return m.determinant() > 0;
}

// getInfo1/getInfo2 on scratch rows and the other read-outs, with the checks listed at the top.
void checkJoint(Input& in, btQuaternionHingeConstraint& joint)
{
	const bool statesFinite = finiteBody(joint.getRigidBodyA()) && finiteBody(joint.getRigidBodyB());
	btTypedConstraint::btConstraintInfo1 info1;
	joint.getInfo1(&info1);
	const int n = info1.m_numConstraintRows;
	if (kVerbose)
		std::fprintf(stderr, "getInfo1: %d rows, fault %d\n", n, int(joint.getFault()));
	check(n >= 0 && n <= kMaxRows, "getInfo1: row count out of range");
	check(joint.getNumRowsLastStep() == n, "getNumRowsLastStep() differs from getInfo1's count");
	// getInfo1 has just validated any frame edited through the non-const references: a joint without a fault has both
	// frames as the settings promise them, however it was built or changed. (A faulted joint may hold a refused
	// frame, or one derived from an absurd body.)
	if (joint.getFault() == BT_QHINGE_FAULT_NONE)
		check(rigidFrame(joint.getSettings().frameInA, joint.getRigidBodyA()) &&
				  rigidFrame(joint.getSettings().frameInB, joint.getRigidBodyB()),
			  "a joint without a fault has a frame that is not a rigid transform");
	// The harness sets only valid thresholds; a negative one (every row's bounds inverted in Bullet's solver: the
	// body is thrown with |threshold|) can only come from the deserializer.
	check(joint.getBreakingImpulseThreshold() >= 0, "a joint has a negative or NaN breaking impulse threshold");
	if (!statesFinite)
	{
		check(n == 0, "rows reported for a body with a non-finite state");
		return;
	}
	if (n > 0)
	{
		std::unique_ptr<Scratch> s(new Scratch(n, in));
		joint.getInfo2(&s->info);
		if (kVerbose)
			for (int r = 0; r < n; ++r)
			{
				const btVector3 l1 = s->row(0, r), a1 = s->row(1, r), l2 = s->row(2, r), a2 = s->row(3, r);
				std::fprintf(stderr,
							 "row %d: J1 (%g %g %g | %g %g %g) J2 (%g %g %g | %g %g %g) error %g cfm %g bounds [%g, %g]\n",
							 r, double(l1.x()), double(l1.y()), double(l1.z()), double(a1.x()), double(a1.y()),
							 double(a1.z()), double(l2.x()), double(l2.y()), double(l2.z()), double(a2.x()),
							 double(a2.y()), double(a2.z()), double(s->error[r * kStride]), double(s->cfm[r * kStride]),
							 double(s->lower[r * kStride]), double(s->upper[r * kStride]));
			}
		for (int r = 0; r < n; ++r)
		{
			for (int m = 0; m < 4; ++m) check(finite(s->row(m, r)), "getInfo2: non-finite Jacobian entry");
			check(finite(s->error[r * kStride]), "getInfo2: non-finite constraint error");
			check(finite(s->cfm[r * kStride]) && s->cfm[r * kStride] >= 0, "getInfo2: non-finite or negative CFM");
			const btScalar lo = s->lower[r * kStride], hi = s->upper[r * kStride];
			check(!std::isnan(lo) && !std::isnan(hi) && lo <= hi, "getInfo2: NaN or inverted impulse bounds");
		}
		const btScalar* all[] = {s->j[0], s->j[1], s->j[2], s->j[3], s->error, s->cfm, s->lower, s->upper};
		for (const btScalar* a : all)
			for (int i = n * kStride; i < kScratchRows * kStride; ++i)
				check(a[i] == kSentinel, "getInfo2 wrote past getInfo1's row count");
		if (joint.getFault() == BT_QHINGE_FAULT_NONE && n >= (joint.getAngularOnly() ? 2 : 5))
		{
			const int first = joint.getAngularOnly() ? 0 : 3;
			const btVector3 u = s->row(3, first), v = s->row(3, first + 1);
			const double uu = u.length2(), vv = v.length2(), uv = u.dot(v);
			check(uu > 0 && vv > 0 && (uu * vv - uv * uv) > kMinGram * uu * vv, "angular rows lost rank");
		}
	}
	if (joint.getFault() == BT_QHINGE_FAULT_NONE)  // (a faulted joint's bodies or frames are outside its range)
	{
		btScalar C[5], J[60];
		const int rows = joint.computePositionRows(joint.getRigidBodyA().getCenterOfMassTransform(),
												   joint.getRigidBodyB().getCenterOfMassTransform(), C, J);
		check(rows == (joint.getAngularOnly() ? 2 : 5), "computePositionRows: unexpected row count");
		for (int i = 0; i < rows; ++i) check(finite(C[i]), "computePositionRows: non-finite C");
		for (int i = 0; i < 12 * rows; ++i) check(finite(J[i]), "computePositionRows: non-finite J");
		CheckingDrawer drawer;
		joint.debugDraw(&drawer, btScalar(in.byte()) / 128);  // the drawing size (m) is not an input under test
		(void)joint.getHingeAngle();
	}
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	Input in(data, size);
	btBoxShape shape(btVector3(btScalar(0.2), btScalar(0.5), btScalar(0.2)));
	std::unique_ptr<btRigidBody> bodies[3];
	for (auto& b : bodies) b = makeBody(in, shape);
	btRigidBody& a = *bodies[0];
	btRigidBody& b = *bodies[1];
	btRigidBody& c = *bodies[2];

	// One joint A–B (or A–world), and maybe a second one B–C (or C–world): a chain.
	std::vector<std::unique_ptr<btQuaternionHingeConstraint>> joints;
	const bool second = in.byte() < 96;
	for (int k = 0; k < (second ? 2 : 1); ++k)
	{
		btRigidBody& first = k == 0 ? a : c;
		btRigidBody* other = in.byte() < 32 ? nullptr : &b;
		btQuaternionHingeConstraint* joint = nullptr;
		try
		{
			joint = makeJoint(in, first, other);
		}
		catch (const std::invalid_argument&)
		{
			continue;  // refused: nothing reached the solver
		}
		for (int s = 0, n = in.pick(8); s < n; ++s) applySetter(in, *joint);
		if (in.byte() < 24) joint = roundTrip(in, joint);
		joints.emplace_back(joint);
	}
	if (joints.empty()) return 0;
	for (int i = 0; i < 3; ++i) traceBody("start", i, *bodies[i]);
	for (auto& j : joints) traceJoint("built", *j);
	for (auto& j : joints) checkJoint(in, *j);

	// A few steps in a world (no contacts: the joints and the solver only), with setters between them.
	// Which bodies must stay finite: sane ones whose joints connect them only to sane bodies (directly or through
	// others) or to non-finite ones (the joint refuses those: no rows, so nothing spreads). A sane body hinged to an
	// absurd but finite one (7e18 kg spinning at 1e10 rad/s) legitimately inherits the absurdity.
	int group[3] = {0, 1, 2};
	auto root = [&](int i) {
		while (group[i] != i) i = group[i];
		return i;
	};
	auto index = [&](const btRigidBody& body) {
		for (int i = 0; i < 3; ++i)
			if (bodies[i].get() == &body) return i;
		return -1;  // the world's fixed body
	};
	for (auto& j : joints)
	{
		const int x = index(j->getRigidBodyA()), y = index(j->getRigidBodyB());
		if (x >= 0 && y >= 0 && finiteBody(*bodies[x]) && finiteBody(*bodies[y])) group[root(x)] = root(y);
	}
	bool mustStayFinite[3];
	for (int i = 0; i < 3; ++i)
	{
		mustStayFinite[i] = true;
		for (int k = 0; k < 3; ++k)
			if (root(k) == root(i) && !saneBody(*bodies[k])) mustStayFinite[i] = false;
	}
	btDefaultCollisionConfiguration config;
	btCollisionDispatcher dispatcher(&config);
	btDbvtBroadphase broadphase;
	btSequentialImpulseConstraintSolver solver;
	btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
	world.getSolverInfo().m_numIterations = 1 + in.pick(20);
	if (kVerbose) std::fprintf(stderr, "world: %d iterations\n", world.getSolverInfo().m_numIterations);
	for (auto& body : bodies) world.addRigidBody(body.get(), 1, 0);
	for (auto& j : joints) world.addConstraint(j.get(), true);
	// (read either way: an input decodes the same with and without it; QUATHINGE_FUZZ_NO_STABILIZER=1 leaves it out,
	// to tell which side of a finding it is on)
	const bool stabilize = in.flag() && !std::getenv("QUATHINGE_FUZZ_NO_STABILIZER");
#ifdef QUATHINGE_HAVE_STABILIZER
	btQuaternionHingeStabilizer stabilizer;
	if (stabilize) world.addAction(&stabilizer);
#endif
	const btScalar steps[] = {btScalar(1) / 60, btScalar(1) / 240, btScalar(1) / 30, btScalar(0.1)};
	const btScalar dt = steps[in.pick(4)];
	if (kVerbose) std::fprintf(stderr, "world: dt %g, stabilizer %d\n", double(dt), int(stabilize));
	for (int i = 0; i < 3; ++i)
		for (int k = 0; k < 3; ++k)
			if (root(k) == root(i) && double(bodies[k]->getAngularVelocity().length()) * double(dt) > kSaneTurnPerStep)
				mustStayFinite[i] = false;
	for (int s = 0, n = 1 + in.pick(6); s < n; ++s)
	{
		if (in.byte() < 64) applySetter(in, *joints[in.pick(int(joints.size()))]);
		for (auto& j : joints)
		{
			const double speed = driveSpeedBound(*j, dt);
			if (!(speed <= kSaneSpeed && speed * double(dt) <= kSaneTurnPerStep))
			{
				const int x = index(j->getRigidBodyA()), y = index(j->getRigidBodyB());
				for (int i = 0; i < 3; ++i)
					if ((x >= 0 && root(i) == root(x)) || (y >= 0 && root(i) == root(y))) mustStayFinite[i] = false;
			}
		}
		world.stepSimulation(dt, 0, dt);
		for (auto& j : joints) traceJoint("step", *j);
		for (int i = 0; i < 3; ++i) traceBody("step", i, *bodies[i]);
		for (int i = 0; i < 3; ++i)
			if (mustStayFinite[i]) check(finiteBody(*bodies[i]), "a step turned a finite, sane body non-finite");
	}
	for (auto& j : joints) checkJoint(in, *j);
#ifdef QUATHINGE_HAVE_STABILIZER
	if (stabilize) world.removeAction(&stabilizer);
#endif
	for (auto& j : joints) world.removeConstraint(j.get());
	for (auto& body : bodies) world.removeRigidBody(body.get());
	return 0;
}
