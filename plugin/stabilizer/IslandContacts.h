// Contacts as rows of the projection (btQuaternionHingeStabilizerSettings::projectContacts; docs/MATH.md, "Contacts in
// the projection"). Without them the projection closes the joints and does not see the ground: Bullet's next
// 10-iteration solve then leaves its unconverged residual in the contacts, and resting ragdolls sink deeper than in the
// world without the stabilizer (README, "Mixed ragdolls").
//
// Slots: an island body that touches fixed partners (static or kinematic rigid bodies or plain btCollisionObjects, as
// RagdollDemo's ground; rigid bodies asleep: Bullet sets a kinematic object's pose before its internal steps, so it
// stands still while the projection runs, and its velocity enters the velocity rows: ContactRow::partnerVelocity) gets
// one contact slot for them all, a joint of R rows (the island's block size) to a fixed side: a leaf edge, so a tree
// stays a tree (eliminated first) and BlockLDLT factorizes it without fill. A sphere or capsule whose manifold with a
// box or plane fixed partner has no point yet (the broadphase pair exists: Bullet's AABBs include the step's motion)
// gets its slot too, with rows on the face under its spheres' centres: Bullet's narrow phase found no point this
// step, the integration may still carry the body into the partner, and without a row a call sank such parts up to
// 1.1e-2 m (double; 2.6e-2 m float), now 3.7e-15 m (2.2e-8 m; tests/test_stabilizer_mixed.cpp, 16 spins). Two island bodies that touch get a pair
// slot, a joint between them: it joins their islands and usually closes a loop (then SparseLDLT solves the island).
// Which slots exist is part of the signature: a body that starts or stops touching rebuilds its island (keeping a
// slot while its manifold lasts, points or none, for every pair was measured: fewer rebuilds, but the idle slots and
// their loops cost more than the rebuilds saved, 1.4 s against 0.95 s on the ragdolls of
// tests/test_stabilizer_mixed.cpp; the rounded bodies' slots above are leaves, no loop). Contacts with
// movable bodies that no projected joint holds are not rows, nor contacts Bullet's solver does not respond to: with a
// ghost object, with CF_NO_CONTACT_RESPONSE, between two static or kinematic objects.
// Rows: at the step's start a slot takes its bodies' deepest manifold points (at most R), held for the step: row r is
// C_r = s_r n_r·(p_r − q_r) (p_r on the slot's body A, q_r on its body B or the fixed partner, n_r Bullet's normal on
// the manifold's body B, or the face normal of a box or plane partner when Bullet's is within 2.6° of it: Bullet's
// float normals are tilted up to 1e-3 rad, IslandContacts.cpp; s_r +1 when the slot's body A is the manifold's body
// A), Bullet's distance, negative when penetrating, with J_r = s_r (n_r, a_r × n_r | −n_r, −b_r × n_r), a_r, b_r the points' arms in world. A sphere or
// capsule on a fixed partner takes its spheres' centres c instead of the manifold's points: C = s n·(c − q) − r, the
// depth of its deepest point towards the contact plane whatever its turn (q the partner's point, r the radius; the
// manifold's points are material points, and a turn of the body sinks another part of it than they hold); with no
// manifold point yet, q and n are those of the box face (or plane) the centre lies over (none when it is beside the
// box: its face's plane is no surface there).
// One-sided, by an active set: a row enters the system once its point penetrates by more than its tolerance and then
// holds C_r = 0 in the position stage and n·v_rel = 0 (relative to a kinematic partner's velocity) in the velocity stage (which removes the approach and the push-out
// velocity Bullet's solver gave a penetration the projection has already removed); after a solve, a row whose
// multiplier pulls (λ_r < 0: the other rows would lift the body off) leaves the system and K is factorized again
// (releasePullingContacts). It comes back only if its point sinks deeper than the step's start found it, and then
// holds it at that depth (C_r = min(0, C_r at the start): never worse than Bullet left it). Back, it may pull and be
// taken out once more (two such rows near a joint's pivot, a knee on the ground, are nearly one row held at two
// depths: measured, a pile of 20 under MinGW, λ ~4e3 and a step ended at maxIterations with a hinge 2.4e-5 m apart);
// back a second time, it stays (taken out any number of times, rows cycled: the pile with projectConeTwistLimits,
// double, had a step of 40 Newton iterations end 1.7e-4 from converged).
// Before, a row taken out stayed out: four RagdollDemo ragdolls dropped on the ground had calls that sank a contact
// 1.1e-2 m (double; 2.0e-3 m float) as the rest of the correction moved its body. Rows the fallback drops
// (releaseContactSlots) stay out. Inactive rows are zero rows with s on K's diagonal. Their linear part is
// n, not the point rows' ±I: the assembly and the deltas take the general product for contact slots (IslandSystem.h).
#ifndef QUATHINGE_STABILIZER_ISLAND_CONTACTS_H
#define QUATHINGE_STABILIZER_ISLAND_CONTACTS_H

#include "StabilizerIsland.h"

#include "BulletDynamics/Dynamics/btRigidBody.h"

#include <utility>

class btCollisionWorld;
class btDispatcher;

namespace quathinge
{
namespace stabilizer
{
/// A sphere or capsule island body and a box or plane fixed partner it had no slot with, which a call's projection
/// sank it into (findSunkBodies): the call is done again with a slot for the pair, its rows on the face under the
/// body's spheres' centres. Lives for that call only (no pointer is kept across calls).
struct NearPair
{
	const btCollisionObject* body;
	const btCollisionObject* partner;
};

/// Appends the contact entries (SignatureEntry::kContact) to `scan`'s joints: a fixed-partner slot for every island
/// body with a manifold point against a fixed partner (or an empty manifold, a sphere or capsule against a box or
/// plane; or a `near` pair), a pair slot for every two island bodies with one, in the order of the bodies' first
/// appearance among the joints (not the dispatcher's order of manifolds, which changes). `index`: scratch, kept by
/// the caller (no allocation once it has grown).
void scanContacts(btDispatcher& dispatcher, const Array<NearPair>& near, Array<SignatureEntry>& scan,
				  Array<std::pair<const btRigidBody*, long long>>& index);

/// Fills every contact slot's ContactSet with its bodies' deepest manifold points (and the `near` pairs' face rows),
/// now.
void gatherContacts(btDispatcher& dispatcher, const Array<NearPair>& near, const Array<std::unique_ptr<Island>>& islands,
					const IslandBodyMap& bodyOf);

/// An island body's state at a call's start, put back when the call is done again (findSunkBodies).
struct CallStart
{
	btTransform transform, interpolation;
	btVector3 linear, angular;
};

/// Saves every island body's CallStart, in the islands' order of bodies, if some island body is one findSunkBodies
/// looks at (a sphere or capsule with no fixed-partner slot); false, saving nothing, if none is (chains, robots of
/// boxes and meshes: the call cannot be done again, and pays no copy).
bool saveCallStart(const Array<std::unique_ptr<Island>>& islands, Array<CallStart>& saved);

/// Puts every island body back to its CallStart (the islands those were saved from).
void restoreCallStart(const Array<std::unique_ptr<Island>>& islands, const Array<CallStart>& saved);

/// After the projection: the spheres and capsules of the islands with no fixed-partner slot (Bullet had no manifold
/// for them against a fixed partner) that the call moved into a box or plane fixed partner, by their own deepest point
/// deeper than at the call's start by more than `tolerance` (m). Appends each (body, partner) to `near`; true if any.
/// Only bodies that the step's integration and the call together moved by Bullet's contact threshold or more are
/// looked at: a body with no manifold against a partner was farther from it than that when Bullet's broadphase ran
/// (its AABBs are grown by gContactBreakingThreshold), so a smaller move cannot reach it.
bool findSunkBodies(btCollisionWorld& world, const Array<std::unique_ptr<Island>>& islands, const Array<CallStart>& saved,
					btScalar tolerance, btScalar timeStep, Array<NearPair>& near);

/// The contact slot's rows at its bodies' current transforms into C and J (rows of the block), growing the active set
/// with rows penetrating by more than `threshold` (a row taken out this step: deeper than at the step's start by
/// more than it). Returns the largest |C| of the active rows.
template <int R>
btScalar evaluateContactRows(const Island& island, JointSlot& js, JointBlock<R>& jb, btScalar threshold)
{
	const ContactSet& set = island.contacts[size_t(js.contact)];
	const btTransform& t = js.rigid[0]->getCenterOfMassTransform();
	const btTransform* tB = js.rigid[1] ? &js.rigid[1]->getCenterOfMassTransform() : nullptr;  // null: fixed partners
	btScalar worst = 0;
	for (int r = 0; r < R; ++r)
	{
		if (r < set.count)
		{
			const ContactRow& row = set.rows[r];
			const btVector3 arm = t.getBasis() * row.local;
			const btVector3 armB = tB ? tB->getBasis() * row.other : btVector3(0, 0, 0);
			const btVector3 onB = tB ? tB->getOrigin() + armB : row.other;
			const btScalar c = row.sign * row.normal.dot((t.getOrigin() + arm) - onB);
			if (!js.contactFloorSet) js.contactFloor[r] = btMin(c, btScalar(0));
			// a row taken out because it pulled comes back only to keep its point from sinking deeper than the step
			// found it, and then holds it there (never worse), not at C = 0
			const bool released = (js.contactReleased & (1u << r)) != 0;
			const btScalar target = released ? js.contactFloor[r] : btScalar(0);
			if (c < target - threshold) js.contactTouched |= 1u << r;
			if (js.contactTouched & (1u << r))
			{
				const btVector3 n = row.sign * row.normal, angular = arm.cross(n), angularB = armB.cross(n);
				for (int k = 0; k < 3; ++k)
				{
					jb.jacobian(r, k) = n[k];
					jb.jacobian(r, 3 + k) = angular[k];
					if (!tB) continue;
					jb.jacobian(r, 6 + k) = -n[k];
					jb.jacobian(r, 9 + k) = -angularB[k];
				}
				jb.c[r] = c - target;
				worst = btMax(worst, btFabs(c - target));
				continue;
			}
		}
		jb.jacobian.row(r).setZero();
		jb.c[r] = 0;
	}
	js.contactFloorSet = true;
	return worst;
}

/// Takes the contact rows of island.joints[j] whose bits are in `rows` out of the system (until they sink below
/// their floor: evaluateContactRows).
template <int R>
void releaseContactRows(BlockIsland<R>& island, size_t j, unsigned rows)
{
	JointSlot& js = island.joints[j];
	js.contactTouched &= ~rows;
	js.contactReleasedTwice |= js.contactReleased & rows;
	js.contactReleased |= rows;
	for (int r = 0; r < R; ++r)
		if (rows & (1u << r))
		{
			island.blocks[j].jacobian.row(r).setZero();
			island.blocks[j].c[r] = 0;
			island.blocks[j].jv[r] = 0;
		}
}

/// The rows of contact slot island.joints[j] in the system whose λ in the last solve pulls (λ < 0: the row would hold
/// its body down, the other rows lift it off) and that may still be taken out (not twice already), as bits.
template <int R>
unsigned pullingContactRows(const BlockIsland<R>& island, size_t j)
{
	const JointSlot& js = island.joints[j];
	unsigned pulling = 0;
	for (int r = 0; r < R; ++r)
		if ((js.contactTouched & ~js.contactReleasedTwice & (1u << r)) && island.lambda[j][r] < 0) pulling |= 1u << r;
	return pulling;
}

/// After a solve (λ in island.lambda): takes out of the system every contact row that pulls (pullingContactRows).
/// True if it took any out (then K must be factorized again and the solve repeated).
template <int R>
bool releasePullingContacts(BlockIsland<R>& island)
{
	bool released = false;
	for (size_t j = 0; j < island.joints.size(); ++j)
	{
		if (island.joints[j].contact < 0) continue;
		const unsigned pulling = pullingContactRows(island, j);
		if (pulling == 0) continue;
		releaseContactRows(island, j, pulling);
		released = true;
	}
	return released;
}

/// Which contact slots releaseContactSlots takes out: the pair slots' (contacts between two island bodies) or all.
enum class ContactSlots
{
	Pairs,
	All
};

/// Takes every contact row of `which` slots out of the system for the rest of the step (the position stage's
/// fallback when its Newton steps with them fail: IslandProjection.cpp). True if any was in the system (else nothing
/// changed: no retry).
template <int R>
bool releaseContactSlots(BlockIsland<R>& island, ContactSlots which)
{
	bool any = false;
	for (size_t j = 0; j < island.joints.size(); ++j)
	{
		const bool fixedPartner = island.joints[j].rigid[1] == nullptr;
		if (island.joints[j].contact < 0 || (which == ContactSlots::Pairs && fixedPartner)) continue;
		any = any || island.joints[j].contactTouched != 0;
		releaseContactRows(island, j, (1u << R) - 1);
		// for good: no depth brings them back this step (the joints alone, as without projectContacts)
		for (int r = 0; r < R; ++r) island.joints[j].contactFloor[r] = -SIMD_INFINITY;
	}
	return any;
}

}  // namespace stabilizer
}  // namespace quathinge

#endif
