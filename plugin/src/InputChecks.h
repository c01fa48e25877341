// Argument checks shared by every constructor and setter. Each throws std::invalid_argument whose message names the
// function and the parameter, e.g. "btQuaternionHingeConstraint::setLimit: low (2) > high (1)", so a bad value
// never reaches the stored settings or the solver.
#ifndef QUATHINGE_INPUT_CHECKS_H
#define QUATHINGE_INPUT_CHECKS_H

#include "LinearMath/btTransform.h"
#include "LinearMath/btVector3.h"

namespace quathinge
{
namespace check
{
/// Throws "<fn>: <param> <what>".
[[noreturn]] void fail(const char* fn, const char* param, const char* what, btScalar value);
[[noreturn]] void fail(const char* fn, const char* message);

void finite(const char* fn, const char* param, btScalar value);
void finite(const char* fn, const char* param, const btVector3& value);
/// A pivot (m, in a body's frame): finite and within kMaxPivotDistance of the body's centre of mass.
void pivot(const char* fn, const char* param, const btVector3& value);
/// A direction: finite and non-zero, of any length (as stock accepts any axis; Godot scales it by the body's scale);
/// returns it normalized.
btVector3 direction(const char* fn, const char* param, const btVector3& axis);
/// Origin a valid pivot, orthonormal right-handed basis (within kUnitTolerance).
void rigidFrame(const char* fn, const char* param, const btTransform& frame);
bool isRigidFrame(const btTransform& frame);
/// lo ≤ value ≤ hi (the inclusive flags say whether each end is allowed).
void inRange(const char* fn, const char* param, btScalar value, btScalar lo, bool loIncluded, btScalar hi,
			 bool hiIncluded);
void nonNegative(const char* fn, const char* param, btScalar value);  // ≥ 0, may be +∞
void positive(const char* fn, const char* param, btScalar value);     // > 0, may be +∞

/// How far from unit a given frame column may be: 1e-4 (relative), about 800 float ulps, so frames typed as decimals
/// or normalized in float pass and a sheared or scaled one does not.
const btScalar kUnitTolerance = btScalar(1e-4);
/// How far a pivot may be from its body's centre of mass: 1e6 m. Farther, the solver's products (r × ω, J·v) leave
/// float range (found by the fuzzer with a pivot at 3e38 m), and no Bullet scene is that large.
const btScalar kMaxPivotDistance = btScalar(1e6);
/// The largest angle a limit, target or rest angle may have: 1e6 rad (160 000 turns). Beyond it a spring or servo
/// asks for velocities outside float range (the fuzzer found a rest angle of 1e26 rad throwing a body to 1e27 rad/s).
const btScalar kMaxAngle = btScalar(1e6);
/// An angle (rad): finite and |angle| ≤ kMaxAngle.
void angle(const char* fn, const char* param, btScalar value);
/// The highest spring frequency: 1e6 Hz (ω² must stay far inside float range).
const btScalar kMaxSpringFrequency = btScalar(1e6);
}  // namespace check
}  // namespace quathinge

#endif
