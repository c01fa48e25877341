// Argument checks shared by every constructor and setter. Each returns true when the value is valid. When it is
// not, the message names the function and the parameter, e.g. "btQuaternionHingeConstraint::setLimit: low (nan) must
// not be NaN", and goes out as the build says (quathinge/btQuaternionHingeErrors.h): thrown as
// std::invalid_argument with exceptions, else handed to the error callback and false returned — the caller then
// returns before it stores anything. Either way a bad value never reaches the stored settings or the solver. Call
// sites read `if (!check::finite(fn, "x", x)) return;`.
#ifndef QUATHINGE_INPUT_CHECKS_H
#define QUATHINGE_INPUT_CHECKS_H

#include "LinearMath/btTransform.h"
#include "LinearMath/btVector3.h"

namespace quathinge
{
namespace check
{
/// Refuses with "<fn>: <param> (<value>) <what>": throws, or reports and returns false.
bool fail(const char* fn, const char* param, const char* what, btScalar value);
bool fail(const char* fn, const char* message);
/// How many refusals this thread has reported (without exceptions: a composite call, such as the constructor from
/// settings, tells from it whether one of the setters it called refused).
unsigned refusals();

bool finite(const char* fn, const char* param, btScalar value);
bool finite(const char* fn, const char* param, const btVector3& value);
/// A pivot (m, in a body's frame): finite and within kMaxPivotDistance of the body's centre of mass.
bool pivot(const char* fn, const char* param, const btVector3& value);
/// A direction: finite and non-zero, of any length (as stock accepts any axis; Godot scales it by the body's scale);
/// `normalized` receives it at unit length.
bool direction(const char* fn, const char* param, const btVector3& axis, btVector3& normalized);
/// Origin a valid pivot, orthonormal right-handed basis (within kUnitTolerance).
bool rigidFrame(const char* fn, const char* param, const btTransform& frame);
bool isRigidFrame(const btTransform& frame);
/// lo ≤ value ≤ hi (the inclusive flags say whether each end is allowed).
bool inRange(const char* fn, const char* param, btScalar value, btScalar lo, bool loIncluded, btScalar hi,
			 bool hiIncluded);
bool nonNegative(const char* fn, const char* param, btScalar value);        // ≥ 0, may be +∞
bool finiteNonNegative(const char* fn, const char* param, btScalar value);  // finite and ≥ 0 (an impulse)
bool positive(const char* fn, const char* param, btScalar value);           // > 0, may be +∞

/// How far from unit a given frame column may be: 1e-4 (relative), about 800 float ulps, so frames typed as decimals
/// or normalized in float pass and a sheared or scaled one does not.
const btScalar kUnitTolerance = btScalar(1e-4);
/// How far a pivot may be from its body's centre of mass: 1e6 m. Farther, the solver's products (r × ω, J·v) leave
/// float range (found by the fuzzer with a pivot at 3e38 m), and no Bullet scene is that large.
const btScalar kMaxPivotDistance = btScalar(1e6);
/// The largest angle a limit, target or rest angle may have: 1e6 rad (160 000 turns). Beyond it a spring or servo
/// asks for velocities outside float range (the fuzzer found a rest angle of 1e26 rad throwing a body to 1e27 rad/s).
const btScalar kMaxAngle = btScalar(1e6);
/// How far a limit's range may be from one turn (rad) to mean one turn (setLimit(−π, π): a free joint, as stock): a few
/// float ulps of 2π, enough for ends converted from degrees.
const btScalar kOneTurnTolerance = btScalar(4e-6);
/// An angle (rad): finite and |angle| ≤ kMaxAngle.
bool angle(const char* fn, const char* param, btScalar value);
/// The largest magnitude of a limit's bias or relaxation factor: 1e3. Stock stores any number and documents both as
/// fractions (bias 0.3, relaxation 1; Godot's editor offers relaxation up to 16); a factor scales the limit row's
/// velocity error (bias × stop ERP × fps × distance, relaxation × rate), and past this it throws a body out of float
/// range (the fuzzer found a bias of -2.6e38 turning a body's angular velocity infinite in one step).
const btScalar kMaxLimitFactor = btScalar(1e3);
/// A limit factor: finite and |value| ≤ kMaxLimitFactor.
bool limitFactor(const char* fn, const char* param, btScalar value);
/// The highest spring frequency: 1e6 Hz (ω² must stay far inside float range).
const btScalar kMaxSpringFrequency = btScalar(1e6);
}  // namespace check
}  // namespace quathinge

#endif
