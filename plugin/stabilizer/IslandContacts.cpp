// Contacts as rows of the projection: which bodies get a contact slot, and their points each step (IslandContacts.h).
#include "IslandContacts.h"

#include "BulletCollision/BroadphaseCollision/btBroadphaseInterface.h"
#include "BulletCollision/BroadphaseCollision/btDispatcher.h"
#include "BulletCollision/BroadphaseCollision/btOverlappingPairCache.h"
#include "BulletCollision/CollisionDispatch/btCollisionWorld.h"
#include "BulletCollision/CollisionShapes/btBoxShape.h"
#include "BulletCollision/CollisionShapes/btCapsuleShape.h"
#include "BulletCollision/CollisionShapes/btSphereShape.h"
#include "BulletCollision/CollisionShapes/btStaticPlaneShape.h"
#include "BulletCollision/NarrowPhaseCollision/btPersistentManifold.h"

#include <algorithm>

namespace quathinge
{
namespace stabilizer
{
namespace
{
// A collision object whose contacts Bullet's solver responds to: a rigid body or a plain btCollisionObject (a ghost, a
// soft body or another kind is not; nor is an object with CF_NO_CONTACT_RESPONSE).
bool responds(const btCollisionObject& o)
{
	const int type = o.getInternalType();
	return o.hasContactResponse() && (type == btCollisionObject::CO_RIGID_BODY || type == btCollisionObject::CO_COLLISION_OBJECT);
}

// The manifold's body as a movable rigid body (null for anything else: a partner, or no partner at all).
const btRigidBody* movableOf(const btCollisionObject* o)
{
	const btRigidBody* body = btRigidBody::upcast(o);
	return body && isMovable(*body) ? body : nullptr;
}

// A partner of infinite mass whose pose is fixed for the step: a static or kinematic rigid body or btCollisionObject
// (RagdollDemo's ground is a static btCollisionObject; Bullet sets a kinematic body's pose before its internal steps,
// and its velocity enters the velocity rows: partnerVelocity), or a rigid body asleep. A movable body is not one.
bool isFixedPartner(const btCollisionObject& o)
{
	const btRigidBody* body = btRigidBody::upcast(&o);
	return body ? !isMovable(*body) : true;
}

// The manifold's two objects, if it holds contacts Bullet's solver responds to (not with a ghost, not with
// CF_NO_CONTACT_RESPONSE, not between two static or kinematic objects).
bool respondingPair(const btPersistentManifold& manifold)
{
	const btCollisionObject& a = *manifold.getBody0();
	const btCollisionObject& b = *manifold.getBody1();
	return manifold.getNumContacts() > 0 && responds(a) && responds(b) &&
		   !(a.isStaticOrKinematicObject() && b.isStaticOrKinematicObject());
}

bool isRounded(const btCollisionObject& o)
{
	const btCollisionShape* shape = o.getCollisionShape();
	return shape && (shape->getShapeType() == SPHERE_SHAPE_PROXYTYPE || shape->getShapeType() == CAPSULE_SHAPE_PROXYTYPE);
}

// An island body a call may sink into a box or plane fixed partner it has no rows with (findSunkBodies looks at it, so
// saveCallStart saves the call's start for it): a responding sphere or capsule with no fixed-partner slot.
bool mayBeSunk(const IslandBody& b) { return b.contactSet < 0 && responds(*b.rigid) && isRounded(*b.rigid); }

bool isBoxOrPlane(const btCollisionObject& o)
{
	const btCollisionShape* shape = o.getCollisionShape();
	return shape && (shape->getShapeType() == BOX_SHAPE_PROXYTYPE || shape->getShapeType() == STATIC_PLANE_PROXYTYPE);
}

// A manifold with no point yet (the broadphase found the pair's bounding boxes overlapping, which with Bullet's
// continuous AABBs include the step's motion; the narrow phase found them farther apart than its threshold) between a
// movable sphere or capsule and a box or plane fixed partner, both responding: the body's rows need no point (the
// face under its spheres' centres, faceUnder), so a call that moves the body into the partner sees it. Returns the
// side of the body, −1 when the manifold is not one.
int nearFaceSide(const btPersistentManifold& manifold)
{
	if (manifold.getNumContacts() > 0) return -1;
	const btCollisionObject* object[2] = {manifold.getBody0(), manifold.getBody1()};
	if (!responds(*object[0]) || !responds(*object[1])) return -1;
	for (int s = 0; s < 2; ++s)
		if (movableOf(object[s]) && isRounded(*object[s]) && isFixedPartner(*object[1 - s]) && isBoxOrPlane(*object[1 - s]))
			return s;
	return -1;
}

// The velocity (world) of the point `at` of a fixed partner: a kinematic rigid body's velocity (Bullet sets it from
// its motion each step), a plain kinematic btCollisionObject's interpolation velocity (the app's), zero when static.
btVector3 partnerVelocity(const btCollisionObject& o, const btVector3& at)
{
	if (!o.isKinematicObject()) return btVector3(0, 0, 0);
	const btRigidBody* body = btRigidBody::upcast(&o);
	const btVector3 lin = body ? body->getLinearVelocity() : o.getInterpolationLinearVelocity();
	const btVector3 ang = body ? body->getAngularVelocity() : o.getInterpolationAngularVelocity();
	const btVector3 origin = body ? body->getCenterOfMassPosition() : o.getWorldTransform().getOrigin();
	return lin + ang.cross(at - origin);
}
}  // namespace

void scanContacts(btDispatcher& dispatcher, const Array<NearPair>& near, Array<SignatureEntry>& scan,
				  Array<std::pair<const btRigidBody*, long long>>& index)
{
	// the movable bodies of the joints, numbered by first appearance (the scan's order, not the pointers'), found by
	// binary search in `index` (sorted by pointer; kept by the caller, so its capacity stays)
	if (dispatcher.getNumManifolds() == 0 && near.empty()) return;  // a world without contacts (a hanging chain) pays nothing more
	const size_t joints = scan.size();
	index.clear();
	for (size_t i = 0; i < joints; ++i)
		for (int s = 0; s < 2; ++s)
			if (scan[i].flags & (s == 0 ? SignatureEntry::kMovableA : SignatureEntry::kMovableB))
				index.push_back({scan[i].body[s], (long long)(2 * i + size_t(s))});
	// by pointer, then by first appearance: the first entry of a pointer is its body's number
	std::sort(index.begin(), index.end());
	auto firstIndex = [&](const btRigidBody* body) {
		const auto at = std::lower_bound(index.begin(), index.end(), std::make_pair(body, -1LL));
		return at != index.end() && at->first == body ? at->second : -1LL;
	};
	const long long kPairs = 1LL << 50;  // a pair's key: its two bodies' numbers, after every fixed-partner slot
	// an island body's slot for all its fixed partners
	auto addFixedPartnerSlot = [&](const btRigidBody* body, long long number) {
		SignatureEntry e;
		e.joint = nullptr;
		e.point = nullptr;
		e.body[0] = const_cast<btRigidBody*>(body);
		e.body[1] = nullptr;
		e.flags = SignatureEntry::kMovableA | SignatureEntry::kContact;
		e.order = number;
		scan.push_back(e);
	};
	for (int m = 0; m < dispatcher.getNumManifolds(); ++m)
	{
		const btPersistentManifold* manifold = dispatcher.getManifoldByIndexInternal(m);
		if (nearFaceSide(*manifold) < 0 && !respondingPair(*manifold)) continue;
		const btCollisionObject* object[2] = {manifold->getBody0(), manifold->getBody1()};
		const btRigidBody* body[2] = {movableOf(object[0]), movableOf(object[1])};
		const long long number[2] = {body[0] ? firstIndex(body[0]) : -1LL, body[1] ? firstIndex(body[1]) : -1LL};
		if (number[0] >= 0 && number[1] >= 0)
		{
			// two island bodies: a pair slot, its body A the one that comes first
			const int first = number[0] < number[1] ? 0 : 1;
			SignatureEntry e;
			e.joint = nullptr;
			e.point = nullptr;
			e.body[0] = const_cast<btRigidBody*>(body[first]);
			e.body[1] = const_cast<btRigidBody*>(body[1 - first]);
			e.flags = SignatureEntry::kMovableA | SignatureEntry::kMovableB | SignatureEntry::kContact;
			e.order = kPairs + number[first] * (1LL << 24) + number[1 - first];
			scan.push_back(e);
			continue;
		}
		// an island body and a fixed partner
		const int s = number[0] >= 0 ? 0 : 1;
		if (number[s] < 0 || !isFixedPartner(*object[1 - s])) continue;  // neither, or a movable body outside
		addFixedPartnerSlot(body[s], number[s]);
	}
	for (const NearPair& pair : near)
	{
		const btRigidBody* body = movableOf(pair.body);
		const long long number = body ? firstIndex(body) : -1LL;
		if (number >= 0) addFixedPartnerSlot(body, number);
	}
	// in the order of the bodies' first appearance among the joints (the dispatcher's order of manifolds changes as
	// they come and go), each slot once (a body with several fixed partners, two manifolds of one pair)
	const auto first = scan.begin() + std::ptrdiff_t(joints);
	std::sort(first, scan.end(), [](const SignatureEntry& a, const SignatureEntry& b) { return a.order < b.order; });
	scan.erase(std::unique(first, scan.end(), [](const SignatureEntry& a, const SignatureEntry& b) { return a.order == b.order; }),
			   scan.end());
}

namespace
{
// A btStaticPlaneShape partner's plane: its outward normal and a point of it, world.
void planeFace(const btStaticPlaneShape& plane, const btTransform& t, btVector3& face, btVector3& onFace)
{
	face = t.getBasis() * plane.getPlaneNormal();
	onFace = t * (plane.getPlaneNormal() * plane.getPlaneConstant());
}

// A btBoxShape partner's face along its local `axis` on `side` (±1): its outward normal and its centre, world.
void boxFace(const btBoxShape& box, const btTransform& t, int axis, btScalar side, btVector3& face, btVector3& onFace)
{
	face = side * t.getBasis().getColumn(axis);
	btVector3 centre(0, 0, 0);
	centre[axis] = side * box.getHalfExtentsWithMargin()[axis];
	onFace = t * centre;
}

// Bullet's normal of a contact with a box or a plane is found by its convex algorithms (GJK, EPA) and, in float,
// is tilted from the face by up to ~1e-3 rad (measured: RagdollDemo's capsules on its box ground, 73% of the normals
// 1e-4 to 1e-3 rad): a row on it is off the face by the tilt times the point's distance from Bullet's point. When
// the partner is a btBoxShape or a btStaticPlaneShape and Bullet's normal is within kFaceNormal of one of its faces,
// the row takes that face's own normal and plane (`normal`, Bullet's, and `point`, on the partner, are replaced).
// `outward`: +1 when Bullet's normal points out of the partner (it is the manifold's body B), −1 when into it.
const btScalar kFaceNormal = btScalar(0.999);  // cos of the largest tilt taken for the face's (about 2.6°)
void takePartnerFace(const btCollisionObject& partner, btScalar outward, btVector3& normal, btVector3& point)
{
	const btCollisionShape* shape = partner.getCollisionShape();
	if (!shape) return;
	const btTransform& t = partner.getWorldTransform();
	btVector3 face(0, 0, 0), onFace(0, 0, 0);  // outward, world; a point of its plane
	if (shape->getShapeType() == STATIC_PLANE_PROXYTYPE)
	{
		planeFace(*static_cast<const btStaticPlaneShape*>(shape), t, face, onFace);
		if (outward * face.dot(normal) < kFaceNormal) return;
	}
	else if (shape->getShapeType() == BOX_SHAPE_PROXYTYPE)
	{
		int axis = -1;
		btScalar side = 0;
		for (int k = 0; k < 3; ++k)
		{
			const btScalar along = outward * t.getBasis().getColumn(k).dot(normal);
			if (btFabs(along) >= kFaceNormal)
			{
				axis = k;
				side = along > 0 ? btScalar(1) : btScalar(-1);
			}
		}
		if (axis < 0) return;
		boxFace(*static_cast<const btBoxShape*>(shape), t, axis, side, face, onFace);
	}
	else
		return;
	normal = outward * face;
	point -= face * face.dot(point - onFace);  // the point moved onto the face's plane (only n·point enters C)
}

// The face of a btBoxShape or btStaticPlaneShape partner that the point `at` (world) lies over: its outward normal
// and a point of its plane, world. A box's is the face whose plane is nearest above the point (the axis it is
// farthest outside along); false when the point is outside that face's rectangle (beside the box, where its plane is
// no surface) or the partner is neither shape.
bool faceUnder(const btCollisionObject& partner, const btVector3& at, btVector3& face, btVector3& onFace)
{
	const btCollisionShape* shape = partner.getCollisionShape();
	if (!shape) return false;
	const btTransform& t = partner.getWorldTransform();
	if (shape->getShapeType() == STATIC_PLANE_PROXYTYPE)
	{
		planeFace(*static_cast<const btStaticPlaneShape*>(shape), t, face, onFace);
		return true;
	}
	if (shape->getShapeType() != BOX_SHAPE_PROXYTYPE) return false;
	const btBoxShape& box = *static_cast<const btBoxShape*>(shape);
	const btVector3 half = box.getHalfExtentsWithMargin();
	const btVector3 local = t.invXform(at);
	int axis = 0;
	for (int k = 1; k < 3; ++k)
		if (btFabs(local[k]) - half[k] > btFabs(local[axis]) - half[axis]) axis = k;
	for (int k = 0; k < 3; ++k)
		if (k != axis && btFabs(local[k]) > half[k]) return false;
	boxFace(box, t, axis, local[axis] >= 0 ? btScalar(1) : btScalar(-1), face, onFace);
	return true;
}

// The centres of a rounded shape's spheres (a btSphereShape's, a btCapsuleShape's two) in its body's frame, and their
// radius: a sphere's point deepest towards a plane of normal n is its centre − r n whatever the body's turn, so a row
// on the centre, its plane point moved by r, is the depth of the shape's deepest point there. Returns how many (0: not
// such a shape).
int roundedCentres(const btCollisionObject& o, btVector3 centre[2], btScalar& radius)
{
	const btCollisionShape* shape = o.getCollisionShape();
	if (!shape) return 0;
	if (shape->getShapeType() == SPHERE_SHAPE_PROXYTYPE)
	{
		radius = static_cast<const btSphereShape*>(shape)->getRadius();
		centre[0].setZero();
		return 1;
	}
	if (shape->getShapeType() != CAPSULE_SHAPE_PROXYTYPE) return 0;
	const btCapsuleShape& capsule = *static_cast<const btCapsuleShape*>(shape);
	radius = capsule.getRadius();
	btVector3 axis(0, 0, 0);
	axis[capsule.getUpAxis()] = capsule.getHalfHeight();
	centre[0] = axis;
	centre[1] = -axis;
	return 2;
}

// Puts `row` (at Bullet's distance `distance`) into `set`, which keeps its `capacity` deepest rows; a row on a point
// the set already has with the same normal to rounding (a sphere's centre, from another point of the manifold) keeps
// the deeper of the two.
void keepDeepest(ContactSet& set, int capacity, const ContactRow& row, btScalar distance)
{
	int at = -1;
	for (int k = 0; k < set.count; ++k)
		if (set.rows[k].local == row.local && set.rows[k].sign == row.sign &&
			set.rows[k].normal.dot(row.normal) > 1 - 4 * SIMD_EPSILON)
		{
			if (distance >= set.distance[k]) return;
			at = k;
		}
	if (at < 0 && set.count < capacity) at = set.count++;
	if (at < 0)
	{
		btScalar shallowest = distance;
		for (int k = 0; k < set.count; ++k)
			if (set.distance[k] > shallowest)
			{
				shallowest = set.distance[k];
				at = k;
			}
	}
	if (at < 0) return;
	set.rows[at] = row;
	set.distance[at] = distance;
}

// Rows for a sphere or capsule `body` (the slot's body A; `sign` +1 when it is the manifold's body 0, or with no
// manifold) against a box or plane fixed `partner` with no manifold point: each of its spheres' centres over a face
// of the partner gets a row on that face's plane (inactive while the centre stays more than the radius above it).
void addFaceRows(ContactSet& set, int capacity, const btCollisionObject& body, const btCollisionObject& partner, btScalar sign)
{
	btVector3 centre[2];
	btScalar radius = 0;
	const int centres = roundedCentres(body, centre, radius);
	ContactRow row;
	row.sign = sign;
	for (int k = 0; k < centres; ++k)
	{
		const btVector3 at = body.getWorldTransform() * centre[k];
		btVector3 face, onFace;
		if (!faceUnder(partner, at, face, onFace)) continue;
		row.normal = sign * face;  // Bullet's convention: the normal on the manifold's body B, towards A
		row.other = onFace + radius * face;
		row.partnerVelocity = partnerVelocity(partner, row.other);
		row.local = centre[k];
		keepDeepest(set, capacity, row, face.dot(at - row.other));
	}
}
}  // namespace

void gatherContacts(btDispatcher& dispatcher, const Array<NearPair>& near, const Array<std::unique_ptr<Island>>& islands,
					const IslandBodyMap& bodyOf)
{
	for (const auto& island : islands)
		for (ContactSet& set : island->contacts) set.count = 0;
	for (int m = 0; m < dispatcher.getNumManifolds(); ++m)
	{
		const btPersistentManifold* manifold = dispatcher.getManifoldByIndexInternal(m);
		const bool nearFace = nearFaceSide(*manifold) >= 0;
		if (!nearFace && !respondingPair(*manifold)) continue;
		const btCollisionObject* object[2] = {manifold->getBody0(), manifold->getBody1()};
		const btRigidBody* body[2] = {movableOf(object[0]), movableOf(object[1])};
		const auto found0 = body[0] ? bodyOf.find(body[0]) : bodyOf.end(), found1 = body[1] ? bodyOf.find(body[1]) : bodyOf.end();
		const bool in[2] = {found0 != bodyOf.end(), found1 != bodyOf.end()};
		// the slot: a pair's (both island bodies), or the island body's slot for its fixed partners
		Island* island = nullptr;
		ContactSet* set = nullptr;
		int a = 0;  // the manifold's side that is the slot's body A
		if (in[0] && in[1])
		{
			island = found0->second.first;
			for (ContactSet& c : island->contacts)
				if ((c.body[0] == body[0] && c.body[1] == body[1]) || (c.body[0] == body[1] && c.body[1] == body[0]))
				{
					set = &c;
					a = c.body[0] == body[0] ? 0 : 1;
				}
		}
		else if (in[0] != in[1])
		{
			a = in[0] ? 0 : 1;
			if (!isFixedPartner(*object[1 - a])) continue;
			const auto& found = a == 0 ? found0 : found1;
			island = found->second.first;
			if (found->second.second->contactSet >= 0) set = &island->contacts[size_t(found->second.second->contactSet)];
		}
		if (!set) continue;
		const bool fixedB = set->body[1] == nullptr;
		const int capacity = (std::min)(island->blockRows, kMaxContactRows);
		// a sphere or capsule on a fixed partner: rows on its spheres' centres (roundedCentres), so that a turn of the
		// body that sinks another part of it than the manifold's point is seen
		btVector3 centre[2];
		btScalar radius = 0;
		const int centres = fixedB ? roundedCentres(*object[a], centre, radius) : 0;
		if (nearFace)
		{
			// no point yet: rows on the face under its spheres' centres
			addFaceRows(*set, capacity, *object[a], *object[1 - a], a == 0 ? btScalar(1) : btScalar(-1));
			continue;
		}
		for (int p = 0; p < manifold->getNumContacts(); ++p)
		{
			const btManifoldPoint& point = manifold->getContactPoint(p);
			ContactRow row;
			row.normal = point.m_normalWorldOnB;
			row.sign = a == 0 ? btScalar(1) : btScalar(-1);
			if (fixedB)
			{
				row.other = a == 0 ? point.getPositionWorldOnB() : point.getPositionWorldOnA();
				takePartnerFace(*object[1 - a], a == 0 ? btScalar(1) : btScalar(-1), row.normal, row.other);
			}
			else
				row.other = a == 0 ? point.m_localPointB : point.m_localPointA;
			row.partnerVelocity = fixedB ? partnerVelocity(*object[1 - a], row.other) : btVector3(0, 0, 0);
			if (centres == 0)
			{
				// the deepest `capacity` points: a new one takes the place of the shallowest kept one if it is deeper
				row.local = a == 0 ? point.m_localPointA : point.m_localPointB;
				keepDeepest(*set, capacity, row, point.getDistance());
				continue;
			}
			// C = s n·(c − (q + s r n)): the partner's point moved out by the radius, towards the body (s n)
			row.other += (row.sign * radius) * row.normal;
			for (int k = 0; k < centres; ++k)
			{
				row.local = centre[k];
				const btVector3 at = object[a]->getWorldTransform() * centre[k];
				keepDeepest(*set, capacity, row, row.sign * row.normal.dot(at - row.other));
			}
		}
	}
	for (const NearPair& pair : near)
	{
		const auto found = bodyOf.find(pair.body);
		if (found == bodyOf.end() || found->second.second->contactSet < 0) continue;
		Island& island = *found->second.first;
		addFaceRows(island.contacts[size_t(found->second.second->contactSet)], (std::min)(island.blockRows, kMaxContactRows),
					*pair.body, *pair.partner, btScalar(1));
	}
}

bool saveCallStart(const Array<std::unique_ptr<Island>>& islands, Array<CallStart>& saved)
{
	saved.clear();
	bool candidate = false;  // a body findSunkBodies looks at
	for (const auto& island : islands)
		for (const IslandBody& b : island->bodies)
			candidate = candidate || mayBeSunk(b);
	if (!candidate) return false;
	for (const auto& island : islands)
		for (const IslandBody& b : island->bodies)
			saved.push_back({b.rigid->getWorldTransform(), b.rigid->getInterpolationWorldTransform(),
							 b.rigid->getLinearVelocity(), b.rigid->getAngularVelocity()});
	return true;
}

void restoreCallStart(const Array<std::unique_ptr<Island>>& islands, const Array<CallStart>& saved)
{
	size_t k = 0;
	for (const auto& island : islands)
	{
		for (IslandBody& b : island->bodies)
		{
			const CallStart& c = saved[k++];
			b.rigid->setWorldTransform(c.transform);
			b.rigid->setInterpolationWorldTransform(c.interpolation);
			b.rigid->setLinearVelocity(c.linear);
			b.rigid->setAngularVelocity(c.angular);
			b.rigid->setInterpolationLinearVelocity(c.linear);
			b.rigid->setInterpolationAngularVelocity(c.angular);
			b.rigid->updateInertiaTensor();
		}
		island->inverseMassesStale = true;
	}
}

namespace
{
// The island body's overlapping broadphase proxies that are box or plane fixed partners it collides with.
struct FacePartners : btBroadphaseAabbCallback
{
	FacePartners(btCollisionWorld& w, const btCollisionObject& b) : world(w), body(b) {}
	bool process(const btBroadphaseProxy* proxy) override
	{
		const btCollisionObject* o = static_cast<const btCollisionObject*>(proxy->m_clientObject);
		if (!o || o == &body || !responds(*o) || !isFixedPartner(*o) || !isBoxOrPlane(*o)) return true;
		const btBroadphaseProxy* own = body.getBroadphaseHandle();
		if (!own) return true;
		const btOverlapFilterCallback* filter = world.getPairCache()->getOverlapFilterCallback();
		const bool collides =
			filter ? filter->needBroadphaseCollision(const_cast<btBroadphaseProxy*>(own), const_cast<btBroadphaseProxy*>(proxy))
				   : (own->m_collisionFilterGroup & proxy->m_collisionFilterMask) != 0 &&
						 (proxy->m_collisionFilterGroup & own->m_collisionFilterMask) != 0;
		if (collides && body.checkCollideWith(o) && o->checkCollideWith(&body)) partners.push_back(o);
		return true;
	}
	btCollisionWorld& world;
	const btCollisionObject& body;
	Array<const btCollisionObject*> partners;
};

// The depth (m; negative: clearance) of a rounded body's deepest point at `pose` towards the face of `partner` that
// its spheres' centres lie over at `over`'s pose (the face is chosen at the call's end and kept for both poses).
btScalar faceDepth(const btVector3* centre, int centres, btScalar radius, const btTransform& pose, const btTransform& over,
				   const btCollisionObject& partner, bool& found)
{
	btScalar deepest = -SIMD_INFINITY;
	found = false;
	for (int k = 0; k < centres; ++k)
	{
		btVector3 face, onFace;
		if (!faceUnder(partner, over * centre[k], face, onFace)) continue;
		found = true;
		deepest = btMax(deepest, radius - face.dot(pose * centre[k] - onFace));
	}
	return deepest;
}
}  // namespace

bool findSunkBodies(btCollisionWorld& world, const Array<std::unique_ptr<Island>>& islands, const Array<CallStart>& saved,
					btScalar tolerance, btScalar timeStep, Array<NearPair>& near)
{
	bool any = false;
	size_t k = 0;
	for (const auto& island : islands)
		for (const IslandBody& b : island->bodies)
		{
			const CallStart& start = saved[k++];
			if (!mayBeSunk(b)) continue;
			btVector3 centre[2];
			btScalar radius = 0;
			const int centres = roundedCentres(*b.rigid, centre, radius);  // 1 or 2: a sphere or a capsule
			// how far any point of it moved since Bullet's broadphase: the integration (the velocities it used, those
			// at the call's start) and the call
			const btScalar reach = radius + centre[0].length();
			const btTransform& now = b.rigid->getWorldTransform();
			const btScalar turned = (now.getRotation() * start.transform.getRotation().inverse()).getAngleShortestPath();
			const btScalar moved = (start.linear.length() + start.angular.length() * reach) * timeStep +
								   (now.getOrigin() - start.transform.getOrigin()).length() + turned * reach;
			if (moved < gContactBreakingThreshold) continue;
			btVector3 lo, hi;
			b.rigid->getCollisionShape()->getAabb(now, lo, hi);
			FacePartners query(world, *b.rigid);
			world.getBroadphase()->aabbTest(lo, hi, query);
			for (const btCollisionObject* partner : query.partners)
			{
				bool found = false;
				const btScalar after = faceDepth(centre, centres, radius, now, now, *partner, found);
				if (!found || after <= tolerance) continue;
				const btScalar before = faceDepth(centre, centres, radius, start.transform, now, *partner, found);
				if (after <= btMax(before, btScalar(0)) + tolerance) continue;
				near.push_back({b.rigid, partner});
				any = true;
			}
		}
	return any;
}

}  // namespace stabilizer
}  // namespace quathinge
