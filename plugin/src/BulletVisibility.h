// Force-included first into every QuatHinge source (plugin/CMakeLists.txt: quathinge_bullet_visibility), so that
// Bullet's btTypedConstraint is declared with default visibility although these libraries build with
// -fvisibility=hidden (only the public API is exported from a shared QuatHinge).
//
// Why: Bullet's solver compares a constraint's vtable entries with the addresses of btTypedConstraint's empty inline
// virtuals (solveConstraintObsolete in every iteration, buildJacobian in every step) and skips the call when they
// match, as they do for its own hinge. A hidden copy of such an inline in this library has another address than the
// one Bullet's shared library resolves to, so the solver called the empty solveConstraintObsolete for every quaternion
// hinge in every iteration (about 11 instructions each: 7 M of a 100-link chain's 1.04 G over the benchmark's steps).
// With default visibility every copy resolves to one address: the program exports its copy (the linker does so for a
// symbol a shared library also defines), or a shared QuatHinge does.
#ifndef QUATHINGE_BULLET_VISIBILITY_H
#define QUATHINGE_BULLET_VISIBILITY_H

// With what it includes (btRigidBody.h declares btTypedConstraint first, and a class's first declaration sets its
// visibility): the math types, btCollisionObject and btRigidBody keep default visibility too, as in Bullet itself.
#if defined(__GNUC__)
#pragma GCC visibility push(default)
#endif
#include "BulletDynamics/ConstraintSolver/btTypedConstraint.h"
#if defined(__GNUC__)
#pragma GCC visibility pop
#endif

#endif  // QUATHINGE_BULLET_VISIBILITY_H
