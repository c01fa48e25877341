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
/// Finite, non-zero and of unit length within kUnitTolerance; returns it normalized exactly.
btVector3 unitAxis(const char* fn, const char* param, const btVector3& axis);
/// Finite origin, orthonormal right-handed basis (within kUnitTolerance).
void rigidFrame(const char* fn, const char* param, const btTransform& frame);
bool isRigidFrame(const btTransform& frame);
/// lo ≤ value ≤ hi (the inclusive flags say whether each end is allowed).
void inRange(const char* fn, const char* param, btScalar value, btScalar lo, bool loIncluded, btScalar hi,
			 bool hiIncluded);
void nonNegative(const char* fn, const char* param, btScalar value);  // ≥ 0, may be +∞
void positive(const char* fn, const char* param, btScalar value);     // > 0, may be +∞

/// How far from unit a given axis or frame column may be: 1e-4 (relative), about 800 float ulps, so axes typed as
/// decimals or normalized in float pass and a wrong axis (a scaled or unnormalized one) does not.
const btScalar kUnitTolerance = btScalar(1e-4);
}  // namespace check
}  // namespace quathinge

#endif
