// An island of the joints the stabilizer holds (hinges of every kind, and the point, locked and contact rows its
// options add), as it keeps it between steps (docs/MATH.md Q13, Q14).
//
// Discovery: every enabled btQuaternionHingeConstraint of the world with at least one movable body (dynamic and
// active; static, kinematic and sleeping bodies are fixed: infinite mass, never moved), with projectPointConstraints
// also every btPoint2PointConstraint and (not angular-only) btConeTwistConstraint (PointRows.h), with
// projectLockedConstraints every 6-dof with a mix of locked axes but a ball's (LockedRows.h), less what the
// user's filter leaves out (btQuaternionHingeStabilizer::setFilter). The scan is summarized as a
// signature (joint, bodies, which are movable, row counts); while it equals the cached one the islands are reused
// as they are, with their block pattern, joint numbering and symbolic analysis. When it changes, an island whose own
// entries are unchanged is still kept (reset to a fresh island's state) and only the others are built.
// Islands: joints connected through shared movable bodies (union–find); fixed bodies do not connect.
// Numbering: along a depth-first tree of the island's bodies, leaves first — a body's joints to fixed bodies and to
// non-parent bodies, then its joints to its parent, after all of its subtree. For an island without closed loops
// this is a perfect elimination order of K (the later neighbours of each joint all share one body), so BlockLDLT
// factorizes it without fill; with loops BlockLDLT::analyze refuses and the island uses SparseLDLT.
// Rows of joint j: its bilateral rows (5, 2 when angular-only, 3 for a point constraint, one per locked linear axis
// and per angular row for a locked 6-dof) at [0, bilateral), the point
// rows first; then, for a joint with a limit
// (and projectLimits), one limit slot that is a structural zero row while the limit is not violated.
// Block size: an island in which some joint has a limit slot or 6 rows (a weld) works in 6-row blocks, any other in
// 5-row blocks
// (BlockMatrix.h; the assembly and factorization of K cost about (5/6)² as much); chosen when the island is built.
#ifndef QUATHINGE_STABILIZER_ISLAND_H
#define QUATHINGE_STABILIZER_ISLAND_H

#include "BulletAllocator.h"
#include "BlockLDLT.h"
#include "BlockMatrix.h"
#include "SparseLDLT.h"
#include "StockHingeRows.h"

#include "LinearMath/btScalar.h"
#include "LinearMath/btTransform.h"

#include <Eigen/Core>

#include <memory>
#include <unordered_map>
#include <utility>

class btCollisionObject;
class btDynamicsWorld;
class btRigidBody;
class btTypedConstraint;
class btQuaternionHingeConstraint;
struct btQuaternionHingeStabilizerFilter;

namespace quathinge
{
namespace stabilizer
{
/// One scanned joint: what decides the islands' structure.
struct SignatureEntry
{
	enum Flags
	{
		kMovableA = 1,
		kMovableB = 2,
		kAngularOnly = 4,
		kLimitSlot = 8,
		kContact = 16,          // a contact slot (projectContacts: IslandContacts.h): body[1] null for the fixed partners
		kLockedAxis0 = 32,      // a locked 6-dof (projectLockedConstraints: LockedRows.h): its locked linear axes, bits 5–7
		kDofHinge = 256,        // frameHinge is a 6-dof set up as a hinge (else a stock hinge: StockHingeRows.h)
		kDofShape0 = 512,       // … its shape (readFrameHinge: free axis, rotation order), bits 9–13
		kLockedAngle0 = 16384,  // a locked 6-dof's angular rows (LockedRows.h, lockedAngularAxes), bits 14–16
		kLimitOnly = 131072,    // a limit row alone, in a slot of its own after its joint's: a cone twist's twist
								// (ConeTwistRows.h), a locked 6-dof's second and further limited axes (LockedRows.h)
		kLimitAxis0 = 262144    // a locked 6-dof's limit row: its axis (DofLocks::limited's index), bits 18–20
	};
	btQuaternionHingeConstraint* joint;       // a quaternion hinge, or null for a point constraint
	btTypedConstraint* point;                 // a point constraint (projectPointConstraints: PointRows.h), or null
	btTypedConstraint* locked = nullptr;      // a locked 6-dof (projectLockedConstraints: LockedRows.h), or null
	btTypedConstraint* frameHinge = nullptr;  // a stock or 6-dof hinge (projectStock/DofHinges: StockHingeRows.h)
	btRigidBody* body[2];
	unsigned flags;
	long long order = 0;  // a contact entry's place (scanContacts sorts by it); not part of the signature
	bool operator==(const SignatureEntry& o) const
	{
		return joint == o.joint && point == o.point && locked == o.locked && frameHinge == o.frameHinge &&
			   body[0] == o.body[0] &&
			   body[1] == o.body[1] && flags == o.flags;
	}
};

/// Dynamic, active, with some inverse mass or inertia: the stabilizer may move it.
bool isMovable(const btRigidBody& body);

/// The world's constraints as last scanned, and which of them are quaternion hinges (null: another type).
struct UpcastCache
{
	Array<btTypedConstraint*> constraints;
	Array<btQuaternionHingeConstraint*> hinges;
};

/// Which constraints a scan takes besides quaternion hinges (btQuaternionHingeStabilizerSettings).
struct ScanKinds
{
	bool limits, points, locked, stockHinges, dofHinges;
	bool coneLimits = false;  // a cone twist's swing and twist limits (with limits and points: ConeTwistRows.h)
};

/// Appends the world's enabled quaternion hinges (and, with kinds.points, its point constraints: PointRows.h; with
/// kinds.locked, its locked 6-dofs: LockedRows.h; with kinds.stockHinges/dofHinges, its stock and 6-dof hinges:
/// StockHingeRows.h) with a movable body that `filter` (if any) keeps, in constraint order, to out (cleared first);
/// of the enabled constraints with a movable body it leaves out, it counts (in `skipped`) those the filter left out, those
/// of a kind whose option is off, those of Bullet's joint types in a form it cannot express (a 6-dof with no axis locked,
/// or a btGeneric6DofSpring2Constraint in a rotation order other than XYZ with some angle locked and a linear axis
/// free; an angular-only cone twist), faulted quaternion hinges,
/// and constraints of other types (gears, custom constraints): none is skipped uncounted.
/// fills `skipped` with the joints it did not take and why (btQuaternionHingeStabilizerStats::filteredJoints, skipped*).
struct ScanSkips
{
	int filtered = 0, byOption = 0, unexpressible = 0, faulted = 0, otherConstraints = 0;
};
void scanWorld(btDynamicsWorld& world, const ScanKinds& kinds, const btQuaternionHingeStabilizerFilter* filter,
			   UpcastCache& upcasts, Array<SignatureEntry>& out, ScanSkips& skipped);

struct IslandBody
{
	btRigidBody* rigid;
	Eigen::Vector3d invMass;            // inverse mass times the linear factor, per world axis
	Eigen::Matrix3d invInertia;         // S I⁻¹_world S, S = diag(angular factor)
	Eigen::Matrix<double, 6, 1> delta;  // accumulated M⁻¹ Jᵀ λ: linear, then angular (world)
	btTransform saved;                  // the transform before the last Newton step (for backtracking)
	// This step: 1, or kContactWeight when the body touches something outside its island (IslandBodies.cpp)
	double contactScale = 1;
	int contactSet = -1;                                       // its contact slot's points in Island::contacts (projectContacts), else −1
	btVector3 startPosition = btVector3(0, 0, 0);              // its centre of mass before this step's projection (IslandInvariants.h)
	btQuaternion startRotation = btQuaternion::getIdentity();  // … and its orientation
};

/// J of one joint in R-row blocks (the block's storage rows, BlockShape, are zero).
template <int R>
using JointJacobian = Eigen::Matrix<double, BlockShape<R>::kStorageRows, 12>;

/// One contact point of a contact slot, held for the step (IslandContacts.h): C = sign·n·(p₀ − p₁), p₀ = T₀·local
/// on the slot's body A, p₁ = T₁·other on its body B, or `other` itself (world) when B is a fixed partner.
struct ContactRow
{
	btVector3 local;            // the point on the slot's body A, in its centre-of-mass frame
	btVector3 other;            // the point on its body B: in B's centre-of-mass frame, or world for a fixed partner
	btVector3 normal;           // world, Bullet's normal on body B of the manifold
	btScalar sign;              // +1 when the slot's body A is the manifold's body 0, else −1: C < 0 is penetration
	btVector3 partnerVelocity;  // a fixed partner's velocity at `other` (world; non-zero only for a kinematic one)
};

/// The contact points of one contact slot this step (at most kMaxContactRows, the deepest): an island body with its
/// fixed partners, or two island bodies.
const int kMaxContactRows = 6;
struct ContactSet
{
	const btCollisionObject* body[2] = {nullptr, nullptr};  // the slot's bodies (B null: fixed partners)
	int count = 0;
	ContactRow rows[kMaxContactRows];
	btScalar distance[kMaxContactRows];  // Bullet's distance of each row's point when gathered (picks the deepest)
};

struct JointSlot
{
	btQuaternionHingeConstraint* joint;  // null for a point constraint, a locked 6-dof, a frame hinge or a contact slot
	btTypedConstraint* point;            // a point constraint (PointRows.h), else null
	bool limitOnly;                      // … a limit row alone (a cone twist's twist, a locked 6-dof's further limited
										 // axis; the joint's own rows: the slot before)
	int limitAxis;                       // a locked 6-dof's limit row: its axis (DofLocks::limited's index), else −1
	// the limit row is a length (m; a locked 6-dof's linear axis), else an angle
	bool limitLinear() const { return limitAxis >= 0 && limitAxis < 3; }
	btTypedConstraint* locked;      // a locked 6-dof (LockedRows.h), else null
	btTypedConstraint* frameHinge;  // a stock or 6-dof hinge (StockHingeRows.h), else null
	bool dofHinge;                  // … a 6-dof one
	FrameHinge hinge;               // its frames and limit, read at the step's start (readAngleReferences)
	int contact;                    // a contact slot: its index in Island::contacts, else −1
	// J's linear part is general (a contact slot's n per row, a locked 6-dof's frame-A axes), not linearSign·I:
	// written with the rows at every evaluation, and taken by the general products (IslandSystem.h)
	bool generalLinear() const { return contact >= 0 || locked != nullptr; }
	btRigidBody* rigid[2];  // A, B
	int body[2];            // island body index of A, B; −1 for a fixed body
	int bilateralRows;      // 5, 2 when angular-only, 3 for a point constraint, 1–6 for a locked 6-dof
	int linearRows;         // of which the point rows (first): 3, 0 when angular-only, the locked axes' for a 6-dof
	bool limitSlot;         // row bilateralRows is the limit row
	int rows;               // bilateralRows + limitSlot

	// Per step.
	// The limit row's variable: a quaternion hinge's multi-turn angle (getHingeAngle's sign), a frame hinge's v
	// (StockHingeRows.h); its stops read at the step's start with it (readAngleReferences)
	btScalar angleReference;  // at the step's start
	btScalar angle;           // at the last evaluation
	btScalar lowerStop, upperStop;
	bool limitActive;                // the limit row is in the system (else a padding row)
	bool limitActiveInFactor;        // … as it was when K was last factorized
	int limitTouched;                // +1 the lower stop, −1 the upper stop was violated this step, 0 neither
	bool limitReleased;              // … and it pulled and was taken out once this step (IslandProjection.cpp)
	bool held;                       // the slot holds a driven axis (a 6-dof's drive: StockHingeRows.h) where the step left it
	btScalar heldRate;               // … at the rate it had (rad/s; 0 while a stop is pushed into)
	unsigned contactTouched;         // a contact slot: bit r set once row r penetrated this step (then in the system)
	unsigned contactReleased;        // … and bit r once row r pulled (λ < 0) and was taken out (IslandContacts.h)
	unsigned contactReleasedTwice;   // … and bit r once it was taken out a second time (then it stays in when back)
	unsigned contactActiveInFactor;  // … as it was when K was last factorized
	unsigned contactSaved;           // … as it was when the bodies' transforms were saved (a Newton step's start)
	// … per row: min(0, C at the step's start), the depth a row taken out may sink back to before it comes back
	// (−∞: never; IslandContacts.h), set at the step's first evaluation (contactFloorSet)
	btScalar contactFloor[kMaxContactRows];
	bool contactFloorSet;
	btScalar linearThreshold;                    // converged |C| of the linear rows (m): max(tolerance, their rounding floor)
	btScalar angularThreshold;                   // … of the angular and limit rows (rad)
	Eigen::Matrix<double, 1, 12> limitGradient;  // ∂α/∂(v_A, ω_A, v_B, ω_B) at the last evaluation
	// M_b⁻¹ J_bᵀ for side s (A, B; unused for a fixed side), in the structure every row has (MATH.md, "Bullet's
	// conventions", Q7): the linear part of J_b is linearSign[s]·[I₃; 0] (the point rows, C = p_B − p_A, so −I for A
	// and +I for B; 0 for an angular-only joint), hence M_b⁻¹ J_bᵀ = [linearSign·m_b⁻¹ on the first 3 rows; h]
	// (h in JointBlock).
	double linearSign[2];
};

/// The per-step rows of one joint in an island of R-row blocks (BlockIsland<R>::blocks, parallel to Island::joints).
template <int R>
struct JointBlock
{
	JointJacobian<R> jacobian;         // rows beyond the joint's own and an inactive limit row are zero
	BlockVector<R> c;                  // C at the last position evaluation; zero on padding rows
	BlockVector<R> jv;                 // J v at the last velocity evaluation; zero on padding rows
	BlockVector<R> leftover;           // the solver's leftover's share of C at the step's start, h r (Q16)
	Eigen::Matrix<double, 3, R> h[2];  // I_b⁻¹ A_bᵀ, A_b the angular part of J_b (R×3): see JointSlot::linearSign
};

/// Joints i > j sharing movable body b: K_ij += J_i,b M_b⁻¹ J_j,bᵀ.
struct Coupling
{
	int block;  // lower block (i, j)
	int i, sideI;
	int j, sideJ;
};

/// What one island's projection did (summed into btQuaternionHingeStabilizerStats).
struct ProjectionResult
{
	bool reused = false;  // the last step's result, replayed (IslandRestCache.h)
	int iterations = 0;
	int factorizations = 0;
	int solves = 0;
	int backtracks = 0;
	int metricSwitches = 0;
	int activeLimitRows = 0;
	int limitReleases = 0;  // limit rows taken out in the position stage because they pulled
	int contactRows = 0;    // contact rows in the system at the end of the step (projectContacts)
	int numericalIssues = 0;
	btScalar residualBefore = 0;
	btScalar residualAfter = 0;
	btScalar velocityResidualBefore = 0;
	btScalar velocityResidualAfter = 0;
	double leftoverLift = 0;          // J: the potential energy of undoing the solver's leftover h r (in M; Q16)
	double leftoverKinetic = 0;       // J: the kinetic energy of the leftover velocity r, ½ rᵀ K⁻¹ r (in M; Q16)
	bool velocitiesRestored = false;  // the energy and momentum restoration changed the velocities (IslandInvariants.h)
};

/// The last projection of an island, kept to replay while the island is at rest (IslandRestCache.h).
struct RestState
{
	Array<btScalar> inputs;   // what the projection read at that step's start
	Array<btScalar> outputs;  // per body: its transform and velocities after the projection
	ProjectionResult result;  // that projection's (its counters also say which of the bodies' state it set)
	bool valid = false;
};
/// The last kRestStates projections: an island at rest under Bullet's solver reaches a fixed point, or, with a stop
/// or a slider's stop held, a cycle of a few states (IslandRestCache.h); any of them is replayed.
const int kRestStates = 8;
struct RestCache
{
	RestState state[kRestStates];
	Array<btScalar> current;  // this step's inputs, gathered to compare (kept to avoid allocating)
	int pending = 0;          // the state a projection that runs now goes into (the oldest one)
};

/// The joints of an island by kind (btQuaternionHingeStabilizerStats): quaternion, stock and 6-dof hinges, point
/// constraints, locked 6-dofs.
enum JointKindIndex
{
	kQuaternionHinges,
	kStockHinges,
	kDofHinges,
	kPointConstraints,
	kLockedConstraints,
	kJointKinds
};

/// What every island holds; the block-sized data is in BlockIsland<blockRows>.
struct Island
{
	BT_DECLARE_ALIGNED_ALLOCATOR();  // allocated through Bullet's allocator (BulletAllocator.h)
	explicit Island(int rows) : blockRows(rows) {}
	virtual ~Island() = default;
	const int blockRows;  // R: 6 if some joint has a limit slot, else 5
	Array<IslandBody> bodies;
	Array<SignatureEntry> entries;                    // the scan's entries it was built from, in scan order (kept while they stay)
	Array<JointSlot> joints;                          // in elimination order
	int jointsOfKind[kJointKinds] = {0, 0, 0, 0, 0};  // by JointKindIndex
	int limitOnlySlots = 0;                           // slots of a limit row alone (JointSlot::limitOnly): not joints of their own
	Array<ContactSet> contacts;                       // the contact slots' points this step (projectContacts), by JointSlot::contact
	bool generalLinear = false;                       // some slot's J has a general linear part (JointSlot::generalLinear())
	BlockPattern pattern;
	Array<Coupling> couplings;
	bool treeOrdered = false;  // BlockLDLT accepted the numbering (no fill)
	bool fillOrdered = false;  // … or, with closed loops, the fill-reducing numbering with its fill (fillReducingOrder)
	bool useSparse = false;    // solved by SparseLDLT
	std::unique_ptr<SparseLDLT> sparse;
	// The position correction's metric for the rest of a step: M, or M + M_ref (IslandProjection.cpp, "stiff").
	bool stiffMetric = false;
	// The position correction's inertia factor (1: M's inertia; the velocities always use 1).
	double rotationWeight = 1;
	// The bodies moved since their M⁻¹ was loaded (IslandBodies.cpp): computeDirections loads it again first.
	bool inverseMassesStale = false;
	double referenceMass = 0;     // kg: the heaviest body's mass
	double referenceInertia = 0;  // kg·m²: the largest principal inertia of any body
	// conserveEnergy (EnergyProjection.cpp): the energy the island had when first projected (J).
	double energyReference = 0;
	bool energyReferenceSet = false;
	// keepEnergyAndMomentum (IslandInvariants.h): this step's record before the projection, and the guard's history.
	struct Invariants
	{
		double kinetic = 0;                                  // J
		double forcePower = 0;                               // W: Σ F_b·v_b + τ_b·ω_b (the shadow energy's term, Q16)
		Eigen::Vector3d momentum = Eigen::Vector3d::Zero();  // kg·m/s
		Eigen::Vector3d angular = Eigen::Vector3d::Zero();   // kg·m²/s, about the centre of mass (a free island)
		double mass = 0;                                     // kg
		bool free = false;                                   // no fixed partner, nothing outside touching, every axis free: P and L are invariants
		bool source = false;                                 // a drive, an outside contact or a moving partner can feed energy in
		bool touching = false;                               // a body touches something outside the island (a contact Bullet's solver works on)
		bool tied = false;                                   // a constraint the stabilizer does not project joins a body of it to one outside (this step)
		// the guard: the energy's running average (J), its lowest value, the restoration's summed work (J) then and now
		double scale = 0;  // J: the island's energy scale (set at its first record)
		double average = 0, lowest = 0, workAtLowest = 0, work = 0, elapsed = 0;
		double ledger = 0;  // J: the energy the calls left beyond their goal T* (IslandInvariants.cpp), the guard's input
		double hold = 1;    // the guard's share of the restoration's change of the speeds, 0…1 (IslandInvariants.cpp)
	} invariants;
	RestCache restCache;
};

/// Every island body by its collision object, with its island.
using IslandBodyMap = std::unordered_map<const btCollisionObject*, std::pair<Island*, IslandBody*>>;

template <int R>
struct BlockIsland : Island
{
	BlockIsland() : Island(R) {}
	Array<JointBlock<R>> blocks;  // per joint, as joints
	BlockMatrix<R> k;
	BlockLDLT<R> block;
	Array<BlockVector<R>> lambda;  // right-hand side, then λ, per joint
};

/// What an island's energy restoration remembers across steps (its guard), kept by its entries when the islands are
/// forgotten (btQuaternionHingeStabilizer::invalidateStructure): an island built again from the same entries carries on.
struct IslandHistory
{
	Array<SignatureEntry> entries;
	Island::Invariants invariants;
};

/// Builds the islands of a scan, keeping each island of `islands` whose entries are unchanged; returns how many it
/// built. An island built from the entries of one of `history` takes its invariants; `history` is emptied.
/// forceSparse: every island uses SparseLDLT.
int buildIslands(const Array<SignatureEntry>& scan, bool forceSparse, Array<std::unique_ptr<Island>>& islands,
				 Array<IslandHistory>& history);

/// Step settings and counters shared by the projection (a subset of btQuaternionHingeStabilizerSettings/Stats).
struct ProjectionSettings
{
	btScalar tolerance;
	btScalar timeStep;  // the step the velocities are integrated over (s): velocity tolerance = tolerance / timeStep
	int maxIterations;
	btScalar minimumProgress;
	bool positions;
	bool velocities;
	double regularization;
	double rotationWeight;         // the position metric's inertia factor (btQuaternionHingeStabilizerSettings)
	bool measureLeftover = false;  // measure ProjectionResult::leftoverLift, leftoverKinetic (keepEnergyAndMomentum)
};


/// Each limited joint's multi-turn angle at the step's start into JointSlot::angleReference: what the rest check
/// compares and the projection's limit row continues from, read once per step before both.
void readAngleReferences(Island& island);

/// Q13 then Q14 on one island (its angle references read this step: readAngleReferences).
ProjectionResult projectIsland(Island& island, const ProjectionSettings& settings);

/// conserveEnergy: scales the island's velocities back toward its reference energy (EnergyProjection.cpp); returns
/// the relative change |s − 1| applied (0 when skipped or when the reference was just taken).
double restoreEnergy(Island& island);

}  // namespace stabilizer
}  // namespace quathinge

#endif
