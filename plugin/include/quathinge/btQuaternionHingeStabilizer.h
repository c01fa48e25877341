/** \file
The post-stabilizer: btQuaternionHingeStabilizer, a btActionInterface that projects the bodies back onto their joints
after every internal step, with its settings, statistics and filter. How it works, what it holds and what it leaves
out: docs/STABILIZER.md; the equations: docs/MATH.md (Q13, Q14) and docs/ENERGY.md (Q15–Q19). Eigen is a private
dependency of this library: nothing here includes it.
*/
#ifndef BT_QUATERNION_HINGE_STABILIZER_H
#define BT_QUATERNION_HINGE_STABILIZER_H

#include "BulletDynamics/Dynamics/btActionInterface.h"
#include "LinearMath/btScalar.h"
#include "quathinge/quathinge_stabilizer_export.h"

class btCollisionWorld;
class btDynamicsWorld;
class btTypedConstraint;
class btIDebugDraw;

/// Which factorization solves an island's K.
enum btQuaternionHingeStabilizerSolver
{
	/// Block LDLᵀ: joints numbered along the tree of bodies (no fill) for islands without closed loops, in a
	/// fill-reducing order with the fill's blocks for islands with loops.
	BT_QHSTAB_SOLVER_AUTO = 0,
	/// Always the general sparse LDLᵀ (Eigen SimplicialLDLT, AMD ordering): the reference, and slower.
	BT_QHSTAB_SOLVER_SPARSE_LDLT = 1
};

/// The stabilizer's configuration: a plain struct with defaults. setSettings checks every field and keeps the previous
/// settings when one is refused.
/// \code
/// btQuaternionHingeStabilizer stabilizer;
/// btQuaternionHingeStabilizerSettings settings = stabilizer.getSettings();
/// settings.projectPointConstraints = true;  // a ragdoll's cone twists too
/// stabilizer.setSettings(settings);
/// \endcode
/// More: docs/STABILIZER.md, "Settings" (a table of every field).
struct btQuaternionHingeStabilizerSettings
{
	/// Newton stops once every row's |C| ≤ positionTolerance. Units: metres for the linear rows (pivot separation),
	/// radians for the quaternion rows (2 q_v·x̂, the misalignment angle for small errors) and the limit row. > 0.
	/// A row is also converged at its rounding floor, 4ε·max(1 m, |x|) for a linear row whose bodies are at
	/// coordinate x, 4ε rad for an angular row (ε = SIMD_EPSILON): float Bullet resolves a position 10 m from the
	/// origin only to ~1e-6 m, so a tighter tolerance there would just cost iterations.
	/// Default 1e-6 with float Bullet, 1e-10 with double Bullet (BT_USE_DOUBLE_PRECISION).
#ifdef BT_USE_DOUBLE_PRECISION
	btScalar positionTolerance = btScalar(1e-10);
#else
	btScalar positionTolerance = btScalar(1e-6);
#endif
	/// Most Newton iterations per island and step (≥ 1). After a velocity-projected step the error is small and one
	/// or two iterations suffice; a large error (a scene set up off its joints, a 1:1000 mass ratio, a long taut
	/// chain) takes a few more. An iteration that brings a stop or a contact into the system is not counted (at most
	/// maxIterations of those), so getLastStats().iterations can reach twice this.
	int maxIterations = 10;
	/// Within a few times the rounding floor of the precision, Newton stops when an iteration reduces ‖C‖∞ by less
	/// than this factor (more iterations cannot help there). (0, 1]; 1 turns the test off. Farther away it goes on
	/// while ‖C‖∞ decreases (a step that would increase it is halved, then undone).
	btScalar minimumProgress = btScalar(0.5);
	/// The two halves of the projection (Q13, Q14); each can be turned off.
	bool projectPositions = true;
	/// Project the velocities (Q14) after the positions.
	bool projectVelocities = true;
	/// Project violated limits (the limit row, as an inequality; a cone twist's too with projectConeTwistLimits; a
	/// locked 6-dof's limited axes with projectLockedConstraints).
	/// Off: only the bilateral rows.
	bool projectLimits = true;
	/// Also project the hinges an app already has, with no class swapped (docs/STABILIZED_JOINTS.md): stock
	/// btHingeConstraints and btHingeAccumulatedAngleConstraints — their frames (getAFrame, getBFrame; angular-only
	/// respected) get the quaternion hinge's rows (btQuaternionHingeConstraint::computeFramePositionRows), and a limit
	/// row with stock's meaning (its wrapped angle against the centre and half range it keeps: low > high free, a range
	/// of 2π or more never acts; softness, unused by stock, unused here). On by default: adding the stabilizer asks for it.
	bool projectStockHinges = true;
	/// Also project 6-dofs set up as hinges, as Bullet's URDF importer builds a revolute joint between rigid bodies:
	/// btGeneric6DofSpring2Constraint (any rotation order), btGeneric6DofConstraint and btGeneric6DofSpringConstraint
	/// with their three linear axes locked (low == high, at any value), exactly one angular axis free or limited (any
	/// of x, y, z) and the other two locked at 0 — the same rows on their frames turned so that ẑ is the free axis, and
	/// a limit row on the 6-dof's own angle of that axis with its limits (wrapped, the nearer stop; lo > hi free).
	/// With projectLimits, a free axis with a motor, servo or spring enabled is held by that row at the angle and rate
	/// Bullet's step left it (the projection does not turn a driven joint to close the joints beside it).
	/// Such a 6-dof is a hinge here, not a point or locked constraint (projectPoint/LockedConstraints). On by default.
	bool projectDofHinges = true;
	/// Also project the pivots of Bullet's point constraints, btPoint2PointConstraint, btConeTwistConstraint (its
	/// three point rows, unless angular-only; its swing and twist limits with projectConeTwistLimits) and
	/// a 6-dof (btGeneric6DofSpring2Constraint, btGeneric6DofConstraint, btGeneric6DofSpringConstraint) with its three
	/// linear axes locked (low == high; a ball built from a 6-dof, its pivot moved by the locked values; its angles are
	/// not projected: a 6-dof with some angle locked or limited as well, a universal joint, a hinge or a ball with its
	/// angles limited, is a locked 6-dof while projectLockedConstraints is on, a point only without it), in the same islands as the quaternion hinges: a ragdoll of
	/// hinges and cone twists then holds together at every joint. They go through the filter as well. On by default;
	/// off: not seen (getLastStats().skippedByOption counts them).
	bool projectPointConstraints = true;
	/// With projectPointConstraints and projectLimits, also project a btConeTwistConstraint's swing and twist limits
	/// as two limit rows, in the angles Bullet's cone twist limits (an elliptical cone, a symmetric twist range;
	/// docs/MATH.md, "Cone-twist limits"), acting past the spans themselves (a softness below 1 leaves the band from
	/// softness × span to Bullet), unless its motor is on or a swing span is under its fix threshold. RagdollDemo
	/// ragdolls then stay within their cone limits to the tolerance, where with this off the projection of the
	/// joints pushes them further past than Bullet alone leaves them (docs/STABILIZER.md, "Ragdolls"). On by default
	/// (off before 0.2.0's last change: its large corrections, where a ragdoll lands or starts, turned limbs into the
	/// ground where no contact row held them, which the rows for spheres and capsules near a box or plane now do).
	bool projectConeTwistLimits = true;
	/// Also project the 6-dofs whose three angles are locked at 0 — a slider (btGeneric6DofSpring2Constraint,
	/// btGeneric6DofConstraint or btGeneric6DofSpringConstraint with one or two linear axes free or limited: a URDF
	/// prismatic joint as pybullet builds it; a btSliderConstraint with its turn locked at 0, as Bullet makes it) or a weld (all six locked; btFixedConstraint) — as rows of the same islands: one per locked linear axis along frame A's axes and three for
	/// the relative rotation (docs/MATH.md, "Locked 6-dofs"). Also the 6-dofs with some of their Euler angles locked
	/// (at any value; Bullet's XYZ order, every btGeneric6DofConstraint's): a universal joint (btUniversalConstraint), a
	/// btHinge2Constraint, a cylindrical joint (a btSliderConstraint free to turn about its axis, or a 6-dof so set),
	/// one row per locked linear axis and per locked angle (MATH.md, "Some angles locked"). With projectLimits, each
	/// limited axis (low < high: a slider's stops, a universal joint's angles, a hinge-2's steering) is a limit row too,
	/// acting past its stops only (MATH.md, "Limited axes of a locked 6-dof"; angles in Bullet's XYZ order only). Springs
	/// and motors are Bullet's alone. A
	/// gripper's fingers on their slides then hold with the arm (Bullet's Panda in float: 7.8e-7 m off their slide
	/// lines, against 1.1e-2 m without the stabilizer and 5.3e-2 m with it and this off), and a slider inside a chain
	/// no longer keeps the error Bullet's solver left it while the hinges around it are closed. The host shares the
	/// correction and momentum is conserved (closeAttachedConstraints, by contrast, moves the attached body alone).
	/// They go through the filter as well. On by default (a weld's island works in 6-row blocks); off: not seen.
	bool projectLockedConstraints = true;
	/// Project contacts too: an island body touching static or kinematic objects (rigid bodies, plain btCollisionObjects
	/// such as RagdollDemo's ground; sleeping bodies) gets a contact slot of up to 5 or 6
	/// rows (its deepest points), two island bodies touching each other a pair slot. A row is one-sided: it enters once
	/// its point penetrates by more than the tolerance, then holds it at zero penetration for the rest of the step,
	/// positions and velocities (the normal velocity Bullet's solver gave it to push out goes with the penetration),
	/// and leaves if it would pull. The joints are then closed without handing the contacts the error: Bullet's
	/// RagdollDemo ragdolls, with projectPointConstraints, rest 1.8e-3 m deep against 4.3e-3 m without a stabilizer.
	/// A kinematic partner's velocity enters its rows' velocity stage. Contacts with dynamic bodies no projected joint
	/// holds, with ghost objects or CF_NO_CONTACT_RESPONSE are not rows. On by default; off saves its cost: a
	/// pair slot usually closes a loop (the general sparse LDLᵀ) and a body that starts or stops touching rebuilds its
	/// island (allocating): 2.9 × stock on a crowd of 100 ragdolls, against 1.6 × without it (docs/PERFORMANCE.md, "Mixed ragdolls").
	bool projectContacts = true;
	/// Carry attached bodies: a body whose every enabled constraint goes to one projected body (its host) and that
	/// is dynamic, awake and held by no projected joint — a gripper's finger on its slider, a lamp on a point-to-point
	/// — moves rigidly with its host, keeping its pose and velocity relative to it, so the projection does not leave
	/// it behind and its constraints keep the error Bullet's solver left (Bullet's Panda: the fingers 5.3e-2 m off
	/// their slide line with the stabilizer, 1.7e-2 m with this; a lamp on a 4-link chain, its cord 7.7e-2 m apart
	/// with the stabilizer, 2.3e-2 m with this, 6.6e-2 m without a stabilizer). Off (the default): such
	/// bodies are not moved, as the filter promises for the joints it leaves out.
	bool moveAttachedBodies = false;
	/// Close attached constraints: an attached body (as above) held by exactly one constraint of a form the stabilizer
	/// knows is then put on it, its host held fixed — a point (btPoint2PointConstraint; btConeTwistConstraint's pivot;
	/// a btGeneric6DofSpring2Constraint or btFixedConstraint with its linear axes locked): moved so the pivots meet,
	/// and the impulse that stops their relative motion applied to it alone; a slider or weld (the 6-dof with its
	/// angles locked at 0): turned to the host's frame, its locked linear axes set to their values, its spin the
	/// host's and its velocity along the locked axes the host's. The constraint then holds like the projected joints
	/// (Bullet's Panda: its fingers 7.7e-8 m off their slide line, against 1.1e-2 m without the stabilizer). The host takes
	/// none of the correction: meant for bodies light beside their host (fingers, tools, lamps). Independent of
	/// moveAttachedBodies (both on: carried, then closed). Off by default.
	bool closeAttachedConstraints = false;
	/// The position correction (Q13) is the smallest move in a metric with every body's inertia multiplied by this
	/// weight (its mass unchanged): above 1 it prefers moving a body along over turning it. A move enters a point row
	/// linearly, a turn through R(Δθ)·r, whose second-order term is what makes Newton's step fall short on a long
	/// taut chain (measured at 30: a 100-link chain 2.2 → 1.2 Newton iterations per step, a 1000-link one 3.5 → 1.2;
	/// docs/PERFORMANCE.md). The quaternion rows still turn the bodies (no move changes them), and any weight converges to
	/// the same manifold; only the point on it differs, by the order of the error removed. 1 is the mass metric M
	/// (Cline & Pai). The velocity projection (Q14) always uses M. [1, 1e6].
	btScalar positionRotationWeight = btScalar(30);
	/// Relative diagonal regularization ε of K: K + ε·(trace K / rows)·I. Keeps redundant and closed-loop islands
	/// finite. [0, 1e-2]; 0 only when no island is ever redundant.
	btScalar regularization = btScalar(1e-9);
	/// How K is factorized: automatic (block LDLᵀ, tree-ordered or, with loops, fill-reducing) or always sparse.
	btQuaternionHingeStabilizerSolver solver = BT_QHSTAB_SOLVER_AUTO;
	/// The projection does no work (on by default; docs/ENERGY.md, Q15–Q19). Ideal joints exert no power, so their
	/// correction may neither add nor remove energy. Per island and step, after the projection its kinetic energy is
	/// set so that its energy (kinetic + the work of each body's total force and torque for the step, its gravity's and
	/// what the app applied with applyForce/applyTorque, with the term ½h Σ F·v that makes it the invariant of Bullet's
	/// semi-implicit Euler step) is what Bullet's step left, corrected for what Bullet's
	/// solver left undone (the sag it let happen and the speed it gave). What the joints' curvature costs (the velocity
	/// projection's share (m d²/I)(ωh)² per step, the position correction's pull back onto the manifold) is given back. What Bullet's step did (gravity, damping, motors,
	/// friction, contacts, limits, a push) is kept. A free island (no static, kinematic or touching partner) also
	/// keeps its linear momentum and its angular momentum (its rigid spin scaled, unless a constraint not projected ties
	/// it to other bodies), and only its motion relative to its rigid motion is scaled. Not restored in a step where a limit or contact row was
	/// projected (their work), on an island touching something outside it (a ragdoll settles on the ground with the projection's damping),
	/// on an island hung on a moving kinematic body; held back, in part and for as long as it lasts, on an island whose
	/// calls left, averaged, more energy than their goal (a guard on the stabilizer's own ledger, blind to the app's
	/// work: getLastStats().energyGuardedIslands). A
	/// push, an app spring, a gravity change, a motor burst and damping keep their energy (docs/ENERGY.md, "Under an
	/// app's forces"). At most 10% of the speeds
	/// per step; one more solve per island and step, no factorization (chain100: +5.8% instructions per step).
	/// Measured (float, 60 Hz, 10 iterations): a 1 m bar pendulum released at 90° keeps its swing energy within 0.15%
	/// over 60 s and its period within 1.3e-4 (without it: 89% lost, 9% short); every conservative scene of the
	/// report drifts less than with stock hinges, and within 5% of its energy scale over 10 s. Off: the projection's own damping.
	bool keepEnergyAndMomentum = true;
	/// Deprecated: keepEnergyAndMomentum (the default) holds conservative scenes' energy without a stored reference
	/// (docs/ENERGY.md, "conserveEnergy"). Off by default, for islands the user knows to be conservative: gravity only —
	/// no damping, motors, springs, friction, limits being hit, contacts or other constraints doing work. After the
	/// velocity projection the island's velocities are scaled by one factor so that its energy (kinetic + the
	/// gravity potential of each body's own gravity) returns to the value it had when the island was first projected
	/// (J v = 0 is kept exactly: it is linear in v). At most 10% per step; skipped for an island hung on a moving
	/// kinematic body. The reference is taken again when the islands are rebuilt (structureRebuilt) — after applying
	/// an impulse by hand, call invalidateStructure() to make the new energy the reference.
	bool conserveEnergy = false;
};

/// What the last call did (one internal step: updateAction or stabilize). Residuals are ‖C‖∞ over every projected
/// row of every island, in the units of positionTolerance.
struct btQuaternionHingeStabilizerStats
{
	int islands = 0;  ///< islands projected (replayed ones included)
	/// Islands at rest, left out: every input of their projection (the bodies' poses, velocities and mass properties,
	/// the fixed partners' poses and velocities, the joints' frames, flags, limits and multi-turn angles, the step)
	/// was, bit for bit, what it was at the last step's start or the one before, so that step's result was applied
	/// again without computing anything (exact: the projection is a deterministic function of them). A hanging chain
	/// kept awake reaches such a fixed point under Bullet's solver, a chain folded against its stops a cycle of two
	/// states; their counters below are zero, their residuals the kept ones.
	int restingIslands = 0;
	int positionsWithinTolerance = 0;     ///< islands projected whose joint error was already within tolerance: no Newton step
	int velocitiesWithinTolerance = 0;    ///< islands projected whose J v was already within tolerance: no velocity solve
	int sparseIslands = 0;                ///< of which solved by the general sparse LDLᵀ (solver = BT_QHSTAB_SOLVER_SPARSE_LDLT; otherwise none expected)
	int loopIslands = 0;                  ///< of which with closed loops, solved by the block LDLᵀ in a fill-reducing order
	int joints = 0;                       ///< joints projected (point constraints and locked 6-dofs included: projectPoint/LockedConstraints)
	int quaternionHinges = 0;             ///< of which btQuaternionHingeConstraints
	int stockHinges = 0;                  ///< … btHingeConstraints and btHingeAccumulatedAngleConstraints (projectStockHinges)
	int dofHinges = 0;                    ///< … 6-dofs set up as hinges (projectDofHinges)
	int pointConstraints = 0;             ///< … point constraints (projectPointConstraints)
	int lockedConstraints = 0;            ///< … locked 6-dofs (projectLockedConstraints)
	int filteredJoints = 0;               ///< joints the filter left out (setFilter): not projected, not counted above
	int skippedByOption = 0;              ///< joints of a kind the stabilizer projects whose option is off (project*)
	int skippedUnexpressible = 0;         ///< Bullet joints in a form it cannot express (a 6-dof with no axis locked; a btGeneric6DofSpring2Constraint in a rotation order other than XYZ with an angle locked and a linear axis free)
	int skippedFaulted = 0;               ///< faulted quaternion hinges (getFault), re-enabled without clearFault
	int otherConstraints = 0;             ///< constraints of other types (gears, custom btTypedConstraints): never projected
	int bodies = 0;                       ///< movable bodies in those islands
	int attachedBodiesMoved = 0;          ///< attached bodies carried with their host (moveAttachedBodies)
	int attachedConstraintsClosed = 0;    ///< attached bodies put on their constraint (closeAttachedConstraints)
	int rows = 0;                         ///< rows of K (bilateral rows plus one slot per joint with a limit)
	int iterations = 0;                   ///< Newton iterations, the most any island used
	int totalIterations = 0;              ///< Newton iterations summed over islands
	int factorizations = 0;               ///< numeric factorizations of K (usually 2 per island: see "How it solves")
	int solves = 0;                       ///< solves with a factorized K (Newton iterations plus velocity solves)
	int backtracks = 0;                   ///< Newton steps halved because the full step made ‖C‖ worse
	int metricSwitches = 0;               ///< islands whose position correction switched to the stiff metric (see above)
	int activeLimitRows = 0;              ///< limit rows projected (violated at some iteration)
	int limitReleases = 0;                ///< … of which taken out again because they pulled (a stop only pushes)
	int contactRows = 0;                  ///< contact rows projected (projectContacts: penetrating at some iteration)
	int nearFacePairs = 0;                ///< spheres and capsules the projection sank into a box or plane fixed partner they had no contact with: the call was done again from its start with rows for them (projectContacts)
	btScalar residualBefore = 0;          ///< ‖C‖∞ before the position projection
	btScalar residualAfter = 0;           ///< ‖C‖∞ after it (at the final positions)
	btScalar velocityResidualBefore = 0;  ///< ‖J v‖∞ (m/s, rad/s) before the velocity projection
	btScalar velocityResidualAfter = 0;   ///< ‖J v‖∞ after it, at the final positions (each row's |J v| is then below
										  ///< its position threshold over the time step, or the rounding floor)
	bool structureRebuilt = false;        ///< the islands were (re)built this step: joints, bodies or their state changed
	int islandsBuilt = 0;                 ///< … of which built anew (an island whose own joints and contacts are unchanged is kept)
	int numericalIssues = 0;              ///< pivots that were not positive and were treated as inactive rows (none expected)
	btScalar energyCorrection = 0;        ///< the largest relative velocity scaling |s − 1| applied (keepEnergyAndMomentum,
										  ///< conserveEnergy)
	int energyRestoredIslands = 0;        ///< islands whose kinetic energy keepEnergyAndMomentum set this step
	int momentumRestoredIslands = 0;      ///< free islands whose momentum keepEnergyAndMomentum put back this step
	int energyGuardedIslands = 0;         ///< islands whose energy restoration the guard holds back, in part or in full
										  ///< (their calls left, averaged, more energy than their goal; it lets go as
										  ///< that average falls again)
	double timeMicroseconds = 0;          ///< wall time of the call
};

/// Chooses the joints a stabilizer projects (btQuaternionHingeStabilizer::setFilter), as btOverlapFilterCallback chooses
/// broadphase pairs: to pay for the stabilizer only where a scene needs it (the hero's ragdoll, a crane's chain) and
/// leave the rest of the world to the solver alone. A joint left out is not projected and costs one call of
/// needsStabilization per step; to the joints projected it is like a constraint of another type (not seen as rows).
/// Its bodies, if no projected joint holds them, are never moved (unless moveAttachedBodies carries one with the
/// projected body it hangs from, or closeAttachedConstraints puts one on its constraint to it), so a world whose
/// joints are all left out steps exactly as without the stabilizer.
/// \code
/// struct HeroOnly : btQuaternionHingeStabilizerFilter  // the joints the app marked with user id 1
/// {
///   bool needsStabilization(const btTypedConstraint& joint) const override { return joint.getUserConstraintId() == 1; }
/// };
/// \endcode
/// More: docs/STABILIZER.md, "Only where the scene needs it".
struct QUATHINGE_STABILIZER_API btQuaternionHingeStabilizerFilter
{
	virtual ~btQuaternionHingeStabilizerFilter() {}  ///< A filter is deleted through its own type or this one.
	/// Called once per step for every enabled joint of a kind the settings project (quaternion, stock and 6-dof
	/// hinges; point constraints and locked 6-dofs with their options) with a movable body: true projects it. The answer may change from step to step (the islands are then rebuilt).
	/// btQuaternionHingeConstraint::upcast tells a quaternion hinge.
	virtual bool needsStabilization(const btTypedConstraint& constraint) const = 0;
};

/// The post-stabilizer: a btActionInterface that, after every internal step of the world it is added to, projects the
/// bodies back onto their joints, positions by Newton (MATH.md Q13) and velocities in the mass metric (Q14), doing no
/// work by default (keepEnergyAndMomentum, ENERGY.md Q15–Q19). It holds btQuaternionHingeConstraints and, as its
/// settings ask: stock btHingeConstraints and btHingeAccumulatedAngleConstraints (projectStockHinges), 6-dofs set up
/// as hinges (projectDofHinges), the pivots of point-to-point, cone twist and linear-locked 6-dof constraints
/// (projectPointConstraints), sliders and welds (projectLockedConstraints) and contacts as one-sided rows
/// (projectContacts), grouped into islands of joints that share movable bodies; a filter (setFilter) narrows them.
/// \code
/// btQuaternionHingeStabilizer stabilizer;   // settings: btQuaternionHingeStabilizerSettings
/// world->addAction(&stabilizer);            // it must outlive its place in the world
/// world->stepSimulation(btScalar(1) / 60);  // getLastStats() says what the last internal step did
/// world->removeAction(&stabilizer);
/// \endcode
/// More: docs/STABILIZER.md (how it works, settings, ragdolls, robots), docs/STABILIZED_JOINTS.md (stock joints held).
ATTRIBUTE_ALIGNED16(class)
QUATHINGE_STABILIZER_API btQuaternionHingeStabilizer : public btActionInterface
{
public:
	BT_DECLARE_ALIGNED_ALLOCATOR();

	/// Refuses a setting out of range, naming the field (btQuaternionHingeErrors.h: throws std::invalid_argument, or,
	/// without exceptions, reports and keeps the default settings).
	explicit btQuaternionHingeStabilizer(const btQuaternionHingeStabilizerSettings& settings =
											 btQuaternionHingeStabilizerSettings());
	/// Frees the islands. Remove the stabilizer from its world first (removeAction).
	virtual ~btQuaternionHingeStabilizer();
	btQuaternionHingeStabilizer(const btQuaternionHingeStabilizer&) = delete;             ///< Not copyable: it owns its islands.
	btQuaternionHingeStabilizer& operator=(const btQuaternionHingeStabilizer&) = delete;  ///< Not copyable: it owns its islands.

	/// btActionInterface: called by the world after each internal step's integration. Does nothing unless
	/// collisionWorld is a btDynamicsWorld (only those hold constraints).
	virtual void updateAction(btCollisionWorld * collisionWorld, btScalar deltaTimeStep);
	/// btActionInterface: nothing to draw.
	virtual void debugDraw(btIDebugDraw * debugDrawer);

	/// Projects `world` now, as updateAction does; e.g. once after placing bodies by hand, before the first step.
	/// timeStep (s, > 0): the step the velocities will next be integrated over; the velocity projection aims at
	/// |J v| ≤ (a row's position threshold) / timeStep per row. Refuses a null world or a bad timeStep (thrown, or
	/// reported without exceptions, and nothing projected).
	const btQuaternionHingeStabilizerStats& stabilize(btDynamicsWorld * world, btScalar timeStep = btScalar(1) / 60);

	/// Refuses a setting out of range, naming the field (thrown, or reported without exceptions); nothing is changed
	/// then.
	void setSettings(const btQuaternionHingeStabilizerSettings& settings);
	/// The settings in use: change a copy and hand it to setSettings.
	const btQuaternionHingeStabilizerSettings& getSettings() const { return m_settings; }

	/// The joints to project: those `filter` says need it (not owned; it must outlive its use here). Null, the
	/// default: every joint of the kinds the settings project.
	void setFilter(const btQuaternionHingeStabilizerFilter* filter) { m_filter = filter; }
	/// The filter set by setFilter, or null.
	const btQuaternionHingeStabilizerFilter* getFilter() const { return m_filter; }

	/// Statistics of the last updateAction or stabilize call.
	const btQuaternionHingeStabilizerStats& getLastStats() const { return m_stats; }

	/// Forgets the cached islands: they are rebuilt at the next call. Never needed for correctness (the structure
	/// is compared with the world's every step); frees the memory of a world the stabilizer no longer serves (all
	/// but each island's energy history, a few hundred bytes, which an island built again from the same joints
	/// carries on: calling it every step changes no run).
	void invalidateStructure();

private:
	struct Impl;
	btQuaternionHingeStabilizerSettings m_settings;
	btQuaternionHingeStabilizerStats m_stats;
	const btQuaternionHingeStabilizerFilter* m_filter = nullptr;
	Impl* m_impl;  // the islands and their scan (owned; the class is not copyable)
};

#endif  // BT_QUATERNION_HINGE_STABILIZER_H
