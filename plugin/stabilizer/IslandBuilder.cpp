// Discovery, islands and the tree numbering of the stabilizer (see StabilizerIsland.h).
#include "BulletAllocator.h"
#include "IslandRestCache.h"
#include "StabilizerIsland.h"

#include "quathinge/btQuaternionHingeConstraint.h"
#include "quathinge/btQuaternionHingeStabilizer.h"

#include "ConeTwistRows.h"
#include "LockedRows.h"
#include "PointRows.h"

#include "BulletDynamics/ConstraintSolver/btHingeConstraint.h"
#include "BulletDynamics/Dynamics/btDynamicsWorld.h"
#include "BulletDynamics/Dynamics/btRigidBody.h"

#include <algorithm>
#include <unordered_map>
#include <utility>

namespace quathinge
{
namespace stabilizer
{
bool isMovable(const btRigidBody& body)
{
	return !body.isStaticOrKinematicObject() && body.isActive() &&
		   (body.getInvMass() > 0 || !body.getInvInertiaDiagLocal().isZero());
}

namespace
{
// Bullet's joint types (the kinds the stabilizer knows, expressible or not); gears, contacts and custom types are not.
bool isBulletJointType(int type)
{
	switch (type)
	{
		case POINT2POINT_CONSTRAINT_TYPE:
		case HINGE_CONSTRAINT_TYPE:
		case CONETWIST_CONSTRAINT_TYPE:
		case D6_CONSTRAINT_TYPE:
		case SLIDER_CONSTRAINT_TYPE:
		case D6_SPRING_CONSTRAINT_TYPE:
		case D6_SPRING_2_CONSTRAINT_TYPE:
		case FIXED_CONSTRAINT_TYPE:
		case QUATERNION_HINGE_CONSTRAINT_TYPE:
			return true;
		default:
			return false;
	}
}

bool hasMovableBody(const btTypedConstraint& c) { return isMovable(c.getRigidBodyA()) || isMovable(c.getRigidBodyB()); }

// Why a constraint with a movable body that no option took is left out: its kind's option is off, or its form is one
// the stabilizer cannot express (or it is no joint of Bullet's).
void countSkip(const btTypedConstraint& c, ScanSkips& skipped)
{
	if (!isBulletJointType(c.getConstraintType()))
	{
		++skipped.otherConstraints;
		return;
	}
	const DofLocks locks = dofLocks(c);
	const bool expressible = readFrameHinge(c, true, true, nullptr, nullptr, nullptr) != FrameHingeKind::None ||
							 hasPointRows(c, locks) || hasLockedRows(locks);
	if (expressible) ++skipped.byOption;
	else ++skipped.unexpressible;
}
}  // namespace

void scanWorld(btDynamicsWorld& world, const ScanKinds& kinds, const btQuaternionHingeStabilizerFilter* filter,
			   UpcastCache& upcasts, Array<SignatureEntry>& out, ScanSkips& skipped)
{
	const bool projectLimits = kinds.limits, projectPoints = kinds.points, projectLocked = kinds.locked;
	out.clear();
	skipped = ScanSkips();
	const int n = world.getNumConstraints();
	upcasts.constraints.resize(size_t(n), nullptr);
	upcasts.hinges.resize(size_t(n), nullptr);
	for (int i = 0; i < n; ++i)
	{
		btTypedConstraint* c = world.getConstraint(i);
		// upcast's dynamic_cast once per constraint in the world, not once per step (in a world of sleeping ragdolls
		// it was most of the stabilizer's time): its answer is kept while the same address is at index i and its type
		// number still agrees with it (a constraint deleted and another made at its address and index is cast again
		// unless it has the same type number as the old one: a quaternion hinge for a quaternion hinge, or another
		// plugin's constraint claiming QUATERNION_HINGE_CONSTRAINT_TYPE for a quaternion hinge, which upcast's own
		// comment rules out).
		btQuaternionHingeConstraint* hinge;
		const bool isHingeType = c->getConstraintType() == QUATERNION_HINGE_CONSTRAINT_TYPE;
		if (upcasts.constraints[size_t(i)] == c && (upcasts.hinges[size_t(i)] != nullptr) == isHingeType)
			hinge = upcasts.hinges[size_t(i)];
		else
		{
			hinge = btQuaternionHingeConstraint::upcast(c);
			upcasts.constraints[size_t(i)] = c;
			upcasts.hinges[size_t(i)] = hinge;
		}
		if (!c->isEnabled()) continue;
		// a stock or 6-dof hinge first (a 6-dof hinge is a hinge, not a point constraint); its limit's ability to act
		bool frameLimit = false;
		unsigned frameShape = 0;
		const FrameHingeKind frameKind =
			hinge ? FrameHingeKind::None
				  : readFrameHinge(*c, kinds.stockHinges, kinds.dofHinges, nullptr, &frameLimit, &frameShape);
		const bool frame = frameKind != FrameHingeKind::None;
		// a 6-dof's locks, read once for both options (and not at all with both off)
		const DofLocks locks = !hinge && !frame && (projectPoints || projectLocked) ? dofLocks(*c) : DofLocks();
		// a 6-dof with some angle locked as well as its linear axes (a universal joint) is held whole by its locked
		// rows where that option is on, else by its point rows
		const bool locked = !hinge && !frame && projectLocked && hasLockedRows(locks);
		const bool point = !hinge && !frame && !locked && projectPoints && hasPointRows(*c, locks);
		if (!hinge && !frame && !point && !locked)
		{
			if (hasMovableBody(*c)) countSkip(*c, skipped);
			continue;
		}
		SignatureEntry e;
		e.joint = hinge;
		e.point = point ? c : nullptr;
		e.locked = locked ? c : nullptr;
		e.frameHinge = frame ? c : nullptr;
		e.body[0] = &c->getRigidBodyA();
		e.body[1] = &c->getRigidBodyB();
		e.flags = 0;
		if (isMovable(*e.body[0])) e.flags |= SignatureEntry::kMovableA;
		if (isMovable(*e.body[1])) e.flags |= SignatureEntry::kMovableB;
		if (!(e.flags & (SignatureEntry::kMovableA | SignatureEntry::kMovableB))) continue;
		// a faulted joint (refused frame edit, bad body state) re-enabled with setEnabled(true) instead of
		// clearFault(): the solver gets no rows from it, and the stabilizer must not project onto its refused frame
		if (hinge && hinge->getFault() != BT_QHINGE_FAULT_NONE)
		{
			++skipped.faulted;
			continue;
		}
		if (filter && !filter->needsStabilization(*c))
		{
			++skipped.filtered;
			continue;
		}
		if (frame)
		{
			if (frameKind == FrameHingeKind::Dof) e.flags |= SignatureEntry::kDofHinge | frameShape * SignatureEntry::kDofShape0;
			else if (static_cast<btHingeConstraint*>(c)->getAngularOnly()) e.flags |= SignatureEntry::kAngularOnly;
			if (projectLimits && frameLimit) e.flags |= SignatureEntry::kLimitSlot;
			out.push_back(e);
			continue;
		}
		if (point || locked)
		{
			if (locked)
				e.flags |= lockedLinearAxes(locks) * SignatureEntry::kLockedAxis0 |
						   lockedAngularAxes(locks) * SignatureEntry::kLockedAngle0;
			// a cone twist's limits (ConeTwistRows.h): the swing's row in its pivot's slot, the twist's in one of its own;
			// a locked 6-dof's limited axes (LockedRows.h): the first's row in its slot, each further one's in its own
			ConeLimits cone;
			if (point && projectLimits && kinds.coneLimits && c->getConstraintType() == CONETWIST_CONSTRAINT_TYPE)
				cone = coneLimits(*static_cast<btConeTwistConstraint*>(c));
			int axes[6];
			const int limited = locked && projectLimits ? limitedAxes(locks, axes) : 0;
			if (cone.swing) e.flags |= SignatureEntry::kLimitSlot;
			if (limited > 0) e.flags |= SignatureEntry::kLimitSlot | unsigned(axes[0]) * SignatureEntry::kLimitAxis0;
			out.push_back(e);
			const unsigned movable = e.flags & (SignatureEntry::kMovableA | SignatureEntry::kMovableB);
			if (cone.twist)
			{
				e.flags = movable | SignatureEntry::kLimitSlot | SignatureEntry::kLimitOnly;
				out.push_back(e);
			}
			for (int i = 1; i < limited; ++i)
			{
				e.flags = movable | SignatureEntry::kLimitSlot | SignatureEntry::kLimitOnly |
						  unsigned(axes[i]) * SignatureEntry::kLimitAxis0;
				out.push_back(e);
			}
			continue;
		}
		if (hinge->getAngularOnly()) e.flags |= SignatureEntry::kAngularOnly;
		if (projectLimits && hinge->getSettings().hasLimit) e.flags |= SignatureEntry::kLimitSlot;
		out.push_back(e);
	}
}

namespace
{
// A locked 6-dof's rows from its signature flags: one per locked linear axis and per angular row (LockedRows.h).
int lockedRows(unsigned flags)
{
	int rows = 0;
	for (int i = 0; i < 3; ++i)
		rows += ((flags & (SignatureEntry::kLockedAxis0 << i)) ? 1 : 0) + ((flags & (SignatureEntry::kLockedAngle0 << i)) ? 1 : 0);
	return rows;
}

int findRoot(Array<int>& parent, int x)
{
	while (parent[x] != x)
	{
		parent[x] = parent[parent[x]];
		x = parent[x];
	}
	return x;
}

// Joint numbering along a depth-first tree of the bodies, leaves first (StabilizerIsland.h). joints: island joints
// with island body indices (−1 fixed). Returns the joints' order.
Array<int> treeOrder(int numBodies, const Array<JointSlot>& joints)
{
	Array<Array<int>> incident(numBodies);
	for (int j = 0; j < int(joints.size()); ++j)
		for (int s = 0; s < 2; ++s)
			if (joints[j].body[s] >= 0) incident[joints[j].body[s]].push_back(j);

	auto other = [&](int j, int b) { return joints[j].body[0] == b ? joints[j].body[1] : joints[j].body[0]; };
	Array<int> order;
	order.reserve(joints.size());
	Array<char> emitted(joints.size(), 0);
	Array<char> visited(numBodies, 0);
	Array<int> parentBody(numBodies, -1);
	struct Frame
	{
		int body;
		size_t next;
	};
	Array<Frame> stack;
	for (int root = 0; root < numBodies; ++root)
	{
		if (visited[root]) continue;
		visited[root] = 1;
		stack.push_back(Frame{root, 0});
		while (!stack.empty())
		{
			Frame& f = stack.back();
			const int b = f.body;
			if (f.next < incident[b].size())
			{
				const int o = other(incident[b][f.next++], b);
				if (o >= 0 && !visited[o])
				{
					visited[o] = 1;
					parentBody[o] = b;
					stack.push_back(Frame{o, 0});
				}
				continue;
			}
			// Finished b: its joints to fixed bodies first, then to other non-parent bodies, then to its parent.
			for (int pass = 0; pass < 3; ++pass)
				for (int j : incident[b])
				{
					if (emitted[j]) continue;
					const int o = other(j, b);
					const int kind = o < 0 ? 0 : (o != parentBody[b] ? 1 : 2);
					if (kind != pass) continue;
					emitted[j] = 1;
					order.push_back(j);
				}
			stack.pop_back();
		}
	}
	return order;
}

// The island's block pattern in its joints' order: a lower block for each pair of joints on a common movable body and,
// with `fill`, for each pair the elimination in that order joins (the symbolic factorization: a column's blocks
// below its first are added to that first block row's column), so that no numbering fills.
void buildPattern(Island& island, bool fill)
{
	const int n = int(island.joints.size());
	BlockPattern& p = island.pattern;
	p.size.resize(n);
	p.offset.resize(n);
	p.rows = 0;
	for (int j = 0; j < n; ++j)
	{
		p.size[j] = island.joints[j].rows;
		p.offset[j] = p.rows;
		p.rows += p.size[j];
	}
	// Pairs of joints on a common movable body: (i > j, body side of i, of j).
	Array<Array<std::pair<int, int>>> incident(island.bodies.size());  // (joint, side)
	for (int j = 0; j < n; ++j)
		for (int s = 0; s < 2; ++s)
			if (island.joints[j].body[s] >= 0) incident[island.joints[j].body[s]].push_back({j, s});
	Array<Coupling> couplings;
	for (const auto& list : incident)
		for (size_t a = 0; a < list.size(); ++a)
			for (size_t b = 0; b < list.size(); ++b)
				if (list[a].first > list[b].first)
					couplings.push_back(Coupling{-1, list[a].first, list[a].second, list[b].first, list[b].second});
	// Lower blocks per column, rows ascending, each once.
	Array<Array<int>> columns(n);
	for (const Coupling& c : couplings) columns[c.j].push_back(c.i);
	p.colStart.assign(n + 1, 0);
	p.rowOf.clear();
	for (int k = 0; k < n; ++k)
	{
		Array<int>& rows = columns[k];
		std::sort(rows.begin(), rows.end());
		rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
		if (fill && rows.size() > 1)  // column k's later blocks, below its first, join that block row's column
		{
			Array<int>& parent = columns[rows[0]];
			parent.insert(parent.end(), rows.begin() + 1, rows.end());
		}
		p.colStart[k] = int(p.rowOf.size());
		p.rowOf.insert(p.rowOf.end(), rows.begin(), rows.end());
	}
	p.colStart[n] = int(p.rowOf.size());
	for (Coupling& c : couplings) c.block = p.find(c.i, c.j);
	// Assemble in memory order of the target blocks.
	std::sort(couplings.begin(), couplings.end(),
			  [](const Coupling& x, const Coupling& y) { return x.block < y.block; });
	island.couplings.swap(couplings);
}

// The block-sized data of an island whose joints and pattern are final (zeroed); returns BlockLDLT's analysis
// (false: the numbering would fill).
template <int R>
bool prepareBlocks(BlockIsland<R>& island)
{
	JointBlock<R> zero;
	zero.jacobian.setZero();
	zero.c.setZero();
	zero.jv.setZero();
	zero.h[0].setZero();
	zero.h[1].setZero();
	island.blocks.assign(island.joints.size(), zero);
	// J's linear part never changes (JointSlot::linearSign: the point rows' ±I, zero elsewhere): written once here;
	// evaluatePositions copies only the angular part
	for (size_t j = 0; j < island.joints.size(); ++j)
		for (int side = 0; side < 2; ++side)
			for (int r = 0; r < 3; ++r) island.blocks[j].jacobian(r, 6 * side + r) = island.joints[j].linearSign[side];
	island.k.resize(island.pattern);
	island.lambda.assign(island.joints.size(), BlockVector<R>::Zero());
	return island.block.analyze(island.pattern);
}
}  // namespace

namespace
{
// One island built from nothing: `entries` are its joints (and contact slots), connected through their movable
// bodies, in scan order (buildIslands groups the scan).
std::unique_ptr<Island> buildOne(const Array<SignatureEntry>& entries, bool forceSparse)
{
	// 6-row blocks if some joint of the island has a limit slot or six rows (a weld: every axis locked), else 5.
	const bool hasLimitSlot = std::any_of(entries.begin(), entries.end(), [&](const SignatureEntry& e) {
		return (e.flags & SignatureEntry::kLimitSlot) != 0 || (e.locked && lockedRows(e.flags) == 6);
	});
	std::unique_ptr<Island> islandPtr(hasLimitSlot ? static_cast<Island*>(new BlockIsland<6>)
												   : static_cast<Island*>(new BlockIsland<5>));
	Island& island = *islandPtr;
	// Movable bodies, numbered in scan order.
	std::unordered_map<const btRigidBody*, int> bodyIndex;
	const unsigned movableFlag[2] = {SignatureEntry::kMovableA, SignatureEntry::kMovableB};
	for (const SignatureEntry& e : entries)
		for (int s = 0; s < 2; ++s)
			if ((e.flags & movableFlag[s]) && bodyIndex.emplace(e.body[s], int(island.bodies.size())).second)
			{
				IslandBody body;
				body.rigid = e.body[s];
				body.invMass.setZero();
				body.invInertia.setZero();
				body.delta.setZero();
				body.saved.setIdentity();
				island.bodies.push_back(body);
			}
	auto indexOf = [&](const SignatureEntry& e, int s) {
		return (e.flags & movableFlag[s]) ? bodyIndex[e.body[s]] : -1;
	};

	for (const SignatureEntry& e : entries)
	{
		const int a = indexOf(e, 0), b = indexOf(e, 1);
		JointSlot slot;
		slot.joint = e.joint;
		slot.point = e.point;
		slot.locked = e.locked;
		slot.frameHinge = e.frameHinge;
		slot.dofHinge = (e.flags & SignatureEntry::kDofHinge) != 0;
		// a 6-dof's shape, kept while the island stands (its frames and limits: refreshFrameHinge, every step)
		if (slot.dofHinge) setDofHingeShape((e.flags / SignatureEntry::kDofShape0) & 31, slot.hinge);
		slot.contact = -1;
		slot.rigid[0] = e.body[0];
		slot.rigid[1] = e.body[1];
		slot.body[0] = a;
		slot.body[1] = b;
		slot.bilateralRows = e.point ? 3 : (e.flags & SignatureEntry::kAngularOnly) ? 2
																					: 5;
		slot.linearRows = (e.flags & SignatureEntry::kAngularOnly) ? 0 : 3;
		slot.limitOnly = (e.flags & SignatureEntry::kLimitOnly) != 0;
		if (slot.limitOnly) slot.bilateralRows = slot.linearRows = 0;  // a limit row alone
		if (e.locked)
		{
			slot.linearRows = 0;
			for (int i = 0; i < 3; ++i)
				if (e.flags & (SignatureEntry::kLockedAxis0 << i)) ++slot.linearRows;
			slot.bilateralRows = lockedRows(e.flags);
			island.generalLinear = true;
		}
		slot.limitSlot = (e.flags & SignatureEntry::kLimitSlot) != 0;
		slot.rows = slot.bilateralRows + (slot.limitSlot ? 1 : 0);
		slot.limitAxis = e.locked && slot.limitSlot ? int((e.flags / SignatureEntry::kLimitAxis0) & 7) : -1;
		slot.contactTouched = slot.contactReleased = slot.contactReleasedTwice = slot.contactActiveInFactor = slot.contactSaved = 0;
		slot.contactFloorSet = false;
		if (e.flags & SignatureEntry::kContact)
		{
			// a contact slot (IslandContacts.h): R optional rows, all linear, whose linear part is written per step
			slot.contact = int(island.contacts.size());
			ContactSet set;
			set.body[0] = e.body[0];
			set.body[1] = e.body[1];
			island.contacts.push_back(set);
			if (slot.body[1] < 0) island.bodies[size_t(slot.body[0])].contactSet = slot.contact;
			slot.bilateralRows = 0;
			slot.rows = slot.linearRows = island.blockRows;
			island.generalLinear = true;
		}
		slot.angleReference = slot.angle = slot.lowerStop = slot.upperStop = 0;
		const JointKindIndex kind = e.joint        ? kQuaternionHinges
									: e.point      ? kPointConstraints
									: e.locked     ? kLockedConstraints
									: e.frameHinge ? (slot.dofHinge ? kDofHinges : kStockHinges)
												   : kJointKinds;  // a contact slot
		if (slot.limitOnly) ++island.limitOnlySlots;               // its joint's
		else if (kind != kJointKinds) ++island.jointsOfKind[kind];
		slot.limitActive = slot.limitActiveInFactor = false;
		slot.limitTouched = 0;
		slot.limitReleased = false;
		slot.held = false;
		slot.heldRate = 0;
		slot.linearThreshold = slot.angularThreshold = 0;
		slot.limitGradient.setZero();
		for (int side = 0; side < 2; ++side)
			slot.linearSign[side] =
				((e.flags & SignatureEntry::kAngularOnly) || slot.limitOnly || slot.generalLinear()) ? 0 : (side == 0 ? -1 : 1);
		island.joints.push_back(slot);
	}

	{
		const Array<int> order = treeOrder(int(island.bodies.size()), island.joints);
		Array<JointSlot> ordered;
		ordered.reserve(order.size());
		for (int j : order) ordered.push_back(island.joints[j]);
		island.joints.swap(ordered);
		buildPattern(island, false);
		auto prepare = [&island]() {
			return island.blockRows == 5 ? prepareBlocks(static_cast<BlockIsland<5>&>(island))
										 : prepareBlocks(static_cast<BlockIsland<6>&>(island));
		};
		island.treeOrdered = prepare();
		if (!island.treeOrdered && !forceSparse)
		{
			// Closed loops: the joints in a fill-reducing order, the fill in the pattern, and the same block LDLᵀ.
			const Array<int> fillOrder = fillReducingOrder(island.pattern);
			ordered.clear();
			for (int j : fillOrder) ordered.push_back(island.joints[j]);
			island.joints.swap(ordered);
			buildPattern(island, true);
			island.fillOrdered = prepare();
		}
		island.useSparse = forceSparse || !(island.treeOrdered || island.fillOrdered);
		if (island.useSparse)
		{
			island.sparse.reset(new SparseLDLT);
			island.sparse->analyze(island.pattern);
		}
	}
	return islandPtr;
}
}  // namespace

int buildIslands(const Array<SignatureEntry>& scan, bool forceSparse, Array<std::unique_ptr<Island>>& islands,
				 Array<IslandHistory>& history)
{
	int built = 0;
	// The scan's entries by island (union-find over their movable bodies), in the order of each island's first entry,
	// with each island's entries in scan order.
	std::unordered_map<const btRigidBody*, int> bodyIndex;
	Array<int> parent;
	const unsigned movableFlag[2] = {SignatureEntry::kMovableA, SignatureEntry::kMovableB};
	Array<int> firstBody(scan.size(), -1);
	for (size_t i = 0; i < scan.size(); ++i)
		for (int s = 0; s < 2; ++s)
			if (scan[i].flags & movableFlag[s])
			{
				const auto found = bodyIndex.emplace(scan[i].body[s], int(parent.size()));
				if (found.second) parent.push_back(int(parent.size()));
				const int b = found.first->second;
				if (firstBody[i] < 0) firstBody[i] = b;
				else parent[size_t(findRoot(parent, b))] = findRoot(parent, firstBody[i]);
			}
	std::unordered_map<int, int> groupOf;  // root → group
	Array<Array<SignatureEntry>> groups;
	for (size_t i = 0; i < scan.size(); ++i)
	{
		const auto found = groupOf.emplace(findRoot(parent, firstBody[i]), int(groups.size()));
		if (found.second) groups.emplace_back();
		groups[size_t(found.first->second)].push_back(scan[i]);
	}
	// An island whose entries are unchanged is kept (no allocation, no analysis), its kept projection and conserveEnergy's
	// reference forgotten (every island steps as if all were rebuilt); the others are built. The energy restoration's
	// history (its guard: Island::Invariants) stays with an island's entries, kept or built again: a rebuild elsewhere,
	// or the app's invalidateStructure() every step, changes no island's energy. A contact that comes or goes
	// (projectContacts) rebuilds its own island, not the world's.
	auto same = [](const Array<SignatureEntry>& a, const Array<SignatureEntry>& b) {
		return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin());
	};
	Array<std::unique_ptr<Island>> old;
	old.swap(islands);
	for (Array<SignatureEntry>& entries : groups)
	{
		std::unique_ptr<Island> island;
		for (std::unique_ptr<Island>& o : old)
			if (o && same(o->entries, entries))
			{
				island = std::move(o);
				forgetProjection(*island);
				island->energyReferenceSet = false;
				break;
			}
		if (!island)
		{
			island = buildOne(entries, forceSparse);
			for (const IslandHistory& h : history)
				if (same(h.entries, entries))
				{
					island->invariants = h.invariants;
					break;
				}
			island->entries.swap(entries);
			++built;
		}
		islands.push_back(std::move(island));
	}
	history.clear();
	return built;
}

}  // namespace stabilizer
}  // namespace quathinge
