// Bodies attached to an island by constraints the stabilizer does not project (settings.moveAttachedBodies): a
// gripper's finger on its slider, a lamp on a point-to-point. The projection moves the island's body and, unless
// they follow, leaves such bodies behind, so their own constraint's error grows by the correction (Bullet's Panda: its
// fingers 5.6e-2 m off their slide line with the stabilizer, 1.7e-2 m when carried;
// tests/test_stabilizer_attached.cpp). A body whose every enabled
// constraint goes to one and the same island body (its host), that is dynamic, awake and in no island, is carried
// rigidly with its host: its pose and velocity relative to the host are what they were before the projection, so its
// constraints' error and relative velocity stay as Bullet's solver left them.
#ifndef QUATHINGE_STABILIZER_ATTACHED_BODIES_H
#define QUATHINGE_STABILIZER_ATTACHED_BODIES_H

#include "BulletAllocator.h"

#include "LinearMath/btTransform.h"

#include <unordered_map>
#include <utility>

class btCollisionObject;
class btRigidBody;

namespace quathinge
{
namespace stabilizer
{
struct Island;
struct IslandBody;
/// Every island body by its collision object, with its island.
using IslandBodyMap = std::unordered_map<const btCollisionObject*, std::pair<const Island*, IslandBody*>>;

struct AttachedBody
{
	btRigidBody* host;  // the island's body
	btRigidBody* body;  // the body carried with it
	btTransform hostBefore;
	btVector3 hostLinearVelocity, hostAngularVelocity;  // before the projection
};

/// Appends to `out` every body attached to `host` (an island body), with the host's state now. A body in an island
/// (`islandBodies`) is never carried; one already in `out` is not added again.
void findAttachedBodies(btRigidBody& host, const IslandBodyMap& islandBodies, Array<AttachedBody>& out);
/// Moves each attached body by its host's change since findAttachedBodies; returns how many moved.
int carryAttachedBodies(const Array<AttachedBody>& attached);

}  // namespace stabilizer
}  // namespace quathinge

#endif
