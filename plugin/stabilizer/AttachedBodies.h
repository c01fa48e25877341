// Bodies attached to an island by constraints the stabilizer does not project (settings.moveAttachedBodies): a
// gripper's finger on its slider, a lamp on a point-to-point. The projection moves the island's body and, unless
// they follow, leaves such bodies behind, so their own constraint's error grows by the correction (Bullet's Panda: its
// fingers 5.3e-2 m off their slide line with the stabilizer, 1.7e-2 m when carried;
// tests/test_stabilizer_attached.cpp). A body whose every enabled
// constraint goes to one and the same island body (its host), that is dynamic, awake and in no island, is carried
// rigidly with its host: its pose and velocity relative to the host are what they were before the projection, so its
// constraints' error and relative velocity stay as Bullet's solver left them.
// Closing (settings.closeAttachedConstraints): a body attached by exactly one constraint of a form known here is then
// put on that constraint, the host held fixed (a light finger on a heavy hand: the host takes none of the correction):
//   - a point (btPoint2PointConstraint, the pivot of a btConeTwistConstraint that is not angular-only, a
//     6-dof (PointRows.h's DofLocks) or btFixedConstraint with its three linear axes locked): the body is moved along
//     so the pivots meet (the locked offset, for the 6-dof), and the impulse at its pivot that takes the pivots'
//     relative velocity out is applied to it alone (its 3×3 effective mass: M-metric, so it takes energy out, never in);
//   - a slider or weld (a 6-dof or btFixedConstraint with its three angular axes locked at 0):
//     the body is turned to the host's frame and moved along its locked linear axes to their locked values (free and
//     limited axes keep their offset), its spin set to the host's and its velocity along the locked axes to the host's
//     point's.
// Other forms (a hinge, a 6-dof with an angle free or limited and a linear axis not locked, a body with a second
// constraint) are not closed (only carried, with moveAttachedBodies).
#ifndef QUATHINGE_STABILIZER_ATTACHED_BODIES_H
#define QUATHINGE_STABILIZER_ATTACHED_BODIES_H

#include "BulletAllocator.h"
#include "StabilizerIsland.h"

#include "LinearMath/btTransform.h"


class btCollisionObject;
class btRigidBody;
class btTypedConstraint;

namespace quathinge
{
namespace stabilizer
{

struct AttachedBody
{
	btRigidBody* host;  // the island's body
	btRigidBody* body;  // the body carried with it
	btTransform hostBefore;
	btVector3 hostLinearVelocity, hostAngularVelocity;  // before the projection
	const btTypedConstraint* only;                      // the body's one enabled constraint, or null when it has several
};

/// Appends to `out` every body attached to `host` (an island body), with the host's state now. A body in an island
/// (`islandBodies`) is never carried; one already in `out` is not added again.
void findAttachedBodies(btRigidBody& host, const IslandBodyMap& islandBodies, Array<AttachedBody>& out);
/// Moves each attached body by its host's change since findAttachedBodies; returns how many moved.
int carryAttachedBodies(const Array<AttachedBody>& attached);
/// Puts each attached body whose one constraint has a known form on it (see above); returns how many it closed.
int closeAttachedConstraints(const Array<AttachedBody>& attached);

}  // namespace stabilizer
}  // namespace quathinge

#endif
