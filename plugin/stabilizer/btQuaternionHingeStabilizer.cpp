// btQuaternionHingeStabilizer: the btActionInterface around the island projection (public header for the design;
// StabilizerIsland.h for discovery and numbering; IslandProjection.cpp for Q13 and Q14).
#include "BulletAllocator.h"
#include "quathinge/btQuaternionHingeStabilizer.h"
#include "quathinge/btQuaternionHingeErrors.h"

#include "AttachedBodies.h"
#include "IslandContacts.h"
#include "IslandInvariants.h"
#include "IslandRestCache.h"
#include "StabilizerIsland.h"

#include "BulletCollision/BroadphaseCollision/btDispatcher.h"
#include "BulletCollision/NarrowPhaseCollision/btPersistentManifold.h"
#include "BulletDynamics/Dynamics/btDynamicsWorld.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <unordered_map>
#ifndef QUATHINGE_NO_EXCEPTIONS
#include <stdexcept>
#endif

using namespace quathinge::stabilizer;

struct btQuaternionHingeStabilizer::Impl
{
	BT_DECLARE_ALIGNED_ALLOCATOR();
	Array<SignatureEntry> signature;  // the scan the islands were built from
	Array<SignatureEntry> scan;       // this step's scan (kept to avoid allocating)
	UpcastCache upcasts;              // which of the world's constraints are quaternion hinges
	// every island body by its collision object, with its island (built with the islands)
	IslandBodyMap bodyOf;
	Array<AttachedBody> attached;                                  // this step's attached bodies (moveAttachedBodies, closeAttachedConstraints)
	Array<std::pair<const btRigidBody*, long long>> contactIndex;  // scanContacts' scratch (projectContacts)
	Array<std::unique_ptr<Island>> islands;
	Array<IslandHistory> history;          // the forgotten islands' energy histories (invalidateStructure), until the next build
	Array<NearPair> near;                  // this call's bodies sunk into a box or plane they had no slot with (findSunkBodies)
	Array<CallStart> callStart;            // the island bodies at the call's start (projectContacts), for the call done again
	Array<Island::Invariants> invariants;  // … and the islands' energy records
	bool built = false;
};

namespace
{
const char* const kClass = "btQuaternionHingeStabilizer";

// Refuses as the joint does (quathinge/btQuaternionHingeErrors.h): throws std::invalid_argument, or, built without
// exceptions, hands the message to the error callback and returns false.
bool fail(const char* fn, const char* field, const char* what, double value)
{
	std::ostringstream message;
	message << kClass << "::" << fn << ": " << field << " (" << value << ") " << what;
#ifdef QUATHINGE_NO_EXCEPTIONS
	btQuaternionHingeReportError(message.str().c_str());
	return false;
#else
	throw std::invalid_argument(message.str());
#endif
}

bool checkSettings(const char* fn, const btQuaternionHingeStabilizerSettings& s)
{
	if (!(s.positionTolerance > 0) || !std::isfinite(s.positionTolerance))
		return fail(fn, "settings.positionTolerance", "must be finite and > 0", s.positionTolerance);
	if (s.maxIterations < 1) return fail(fn, "settings.maxIterations", "must be >= 1", s.maxIterations);
	if (!(s.minimumProgress > 0 && s.minimumProgress <= 1))
		return fail(fn, "settings.minimumProgress", "must be in (0, 1]", s.minimumProgress);
	// 1e-2: beyond it the regularization visibly slows Newton on well-posed islands (a 1% relative perturbation).
	if (!(s.regularization >= 0 && s.regularization <= btScalar(1e-2)))
		return fail(fn, "settings.regularization", "must be in [0, 1e-2]", s.regularization);
	if (!(s.positionRotationWeight >= 1 && s.positionRotationWeight <= btScalar(1e6)))
		return fail(fn, "settings.positionRotationWeight", "must be in [1, 1e6]", s.positionRotationWeight);
	if (s.solver != BT_QHSTAB_SOLVER_AUTO && s.solver != BT_QHSTAB_SOLVER_SPARSE_LDLT)
		return fail(fn, "settings.solver", "is not a btQuaternionHingeStabilizerSolver", double(s.solver));
	return true;
}
}  // namespace

btQuaternionHingeStabilizer::btQuaternionHingeStabilizer(const btQuaternionHingeStabilizerSettings& settings)
	: m_impl(nullptr)
{
	// refused without exceptions: the default settings stay; with exceptions the throw comes before anything is
	// allocated (m_impl is a plain pointer: a throw after it would leak it)
	if (checkSettings("btQuaternionHingeStabilizer", settings)) m_settings = settings;
	m_impl = new Impl;
}

btQuaternionHingeStabilizer::~btQuaternionHingeStabilizer() { delete m_impl; }

void btQuaternionHingeStabilizer::setSettings(const btQuaternionHingeStabilizerSettings& settings)
{
	if (!checkSettings("setSettings", settings)) return;
	// projectLimits and solver change the islands' structure.
	if (settings.projectLimits != m_settings.projectLimits || settings.solver != m_settings.solver ||
		settings.projectPointConstraints != m_settings.projectPointConstraints ||
		settings.projectConeTwistLimits != m_settings.projectConeTwistLimits ||
		settings.projectLockedConstraints != m_settings.projectLockedConstraints ||
		settings.projectContacts != m_settings.projectContacts ||
		settings.projectStockHinges != m_settings.projectStockHinges ||
		settings.projectDofHinges != m_settings.projectDofHinges)
		invalidateStructure();
	// a kept projection was made with the old settings
	for (const auto& island : m_impl->islands) forgetProjection(*island);
	m_settings = settings;
}

void btQuaternionHingeStabilizer::invalidateStructure()
{
	// the islands go; their energy histories stay with their entries, for the islands built from them again
	for (auto& island : m_impl->islands)
	{
		m_impl->history.emplace_back();
		m_impl->history.back().entries.swap(island->entries);
		m_impl->history.back().invariants = island->invariants;
	}
	m_impl->islands.clear();
	m_impl->signature.clear();
	m_impl->upcasts = UpcastCache();
	m_impl->bodyOf.clear();
	m_impl->built = false;
}

void btQuaternionHingeStabilizer::updateAction(btCollisionWorld* collisionWorld, btScalar deltaTimeStep)
{
	btDynamicsWorld* world = dynamic_cast<btDynamicsWorld*>(collisionWorld);
	if (world && deltaTimeStep > 0) stabilize(world, deltaTimeStep);
}

void btQuaternionHingeStabilizer::debugDraw(btIDebugDraw* /*debugDrawer*/) {}

const btQuaternionHingeStabilizerStats& btQuaternionHingeStabilizer::stabilize(btDynamicsWorld* world,
																			   btScalar timeStep)
{
	const auto start = std::chrono::steady_clock::now();
	if (!world && !fail("stabilize", "world", "must not be null", 0)) return m_stats;
	if ((!(timeStep > 0) || !std::isfinite(timeStep)) && !fail("stabilize", "timeStep", "must be finite and > 0", timeStep))
		return m_stats;
	Impl& impl = *m_impl;
	impl.near.clear();
	// Once more at most: when the projection sank a sphere or capsule into a box or plane it had no contact slot with
	// (Bullet had no manifold for them: findSunkBodies), the call is done again from the same start with a slot for
	// the pair (measured: RagdollDemo's pile of 20, a first call closing the cone twists' limits swung a shin 0.29 m
	// down, 0.12 m into the ground).
	for (int pass = 0;; ++pass)
	{
		m_stats = btQuaternionHingeStabilizerStats();
		const ScanKinds kinds{m_settings.projectLimits, m_settings.projectPointConstraints,
							  m_settings.projectLockedConstraints, m_settings.projectStockHinges, m_settings.projectDofHinges,
							  m_settings.projectConeTwistLimits};
		ScanSkips skipped;
		scanWorld(*world, kinds, m_filter, impl.upcasts, impl.scan, skipped);
		m_stats.filteredJoints = skipped.filtered;
		m_stats.skippedByOption = skipped.byOption;
		m_stats.skippedUnexpressible = skipped.unexpressible;
		m_stats.skippedFaulted = skipped.faulted;
		m_stats.otherConstraints = skipped.otherConstraints;
		if (m_settings.projectContacts) scanContacts(*world->getDispatcher(), impl.near, impl.scan, impl.contactIndex);
		if (!impl.built || impl.scan.size() != impl.signature.size() ||
			!std::equal(impl.scan.begin(), impl.scan.end(), impl.signature.begin()))
		{
			impl.signature = impl.scan;  // a copy, not a swap: both keep their capacity (no allocation the next step)
			m_stats.islandsBuilt = buildIslands(impl.signature, m_settings.solver == BT_QHSTAB_SOLVER_SPARSE_LDLT, impl.islands,
												impl.history);
			impl.bodyOf.clear();
			for (const auto& island : impl.islands)
				for (IslandBody& b : island->bodies) impl.bodyOf[b.rigid] = std::make_pair(island.get(), &b);
			impl.built = true;
			m_stats.structureRebuilt = true;
		}

		ProjectionSettings settings;
		settings.tolerance = m_settings.positionTolerance;
		settings.timeStep = timeStep;
		settings.maxIterations = m_settings.maxIterations;
		settings.minimumProgress = m_settings.minimumProgress;
		settings.positions = m_settings.projectPositions;
		settings.velocities = m_settings.projectVelocities;
		settings.regularization = m_settings.regularization;
		settings.rotationWeight = m_settings.positionRotationWeight;
		settings.measureLeftover = m_settings.keepEnergyAndMomentum;
		// Bodies touching something outside their island (the ground, another object: a contact at or below zero
		// distance) take a tenth of their share of the position correction in its weighted metric, so that a ragdoll on
		// the ground is closed by moving its free parts rather than pushing the grounded ones into the ground, which the
		// projection does not see (measured on Bullet's RagdollDemo ragdolls, tests/test_stabilizer_mixed.cpp: the deepest
		// ground contact 7.96e-2 m with the stabilizer, 6.18e-2 m without it, 6.14e-2 m with this weight; 1e-2 and 1e-3
		// gain no more and let the cone twists part more).
		const double kContactWeight = 0.1;
		if (!impl.islands.empty())
		{
			for (const auto& island : impl.islands)
				for (IslandBody& b : island->bodies) b.contactScale = 1;
			btDispatcher& dispatcher = *world->getDispatcher();
			for (int m = 0; m < dispatcher.getNumManifolds(); ++m)
			{
				const btPersistentManifold* manifold = dispatcher.getManifoldByIndexInternal(m);
				bool touching = false;
				for (int p = 0; p < manifold->getNumContacts() && !touching; ++p)
					touching = manifold->getContactPoint(p).getDistance() <= 0;
				if (!touching) continue;
				const auto a = impl.bodyOf.find(manifold->getBody0());
				const auto b = impl.bodyOf.find(manifold->getBody1());
				const Island* islandA = a != impl.bodyOf.end() ? a->second.first : nullptr;
				const Island* islandB = b != impl.bodyOf.end() ? b->second.first : nullptr;
				if (islandA && islandA != islandB) a->second.second->contactScale = kContactWeight;
				if (islandB && islandB != islandA) b->second.second->contactScale = kContactWeight;
			}
		}
		if (m_settings.projectContacts) gatherContacts(*world->getDispatcher(), impl.near, impl.islands, impl.bodyOf);
		if (m_settings.keepEnergyAndMomentum) markTiedIslands(*world, impl.bodyOf, impl.islands);
		impl.attached.clear();  // keeps its capacity: no allocation the next step
		if (m_settings.moveAttachedBodies || m_settings.closeAttachedConstraints)
			for (const auto& island : impl.islands)
				for (IslandBody& b : island->bodies) findAttachedBodies(*b.rigid, impl.bodyOf, impl.attached);
		// (with attached bodies carried or closed the call is not done again: those bodies are not saved)
		const bool recheck = pass == 0 && m_settings.projectContacts && settings.positions && !m_settings.moveAttachedBodies &&
							 !m_settings.closeAttachedConstraints && saveCallStart(impl.islands, impl.callStart);
		if (recheck)
		{
			impl.invariants.clear();
			for (const auto& island : impl.islands) impl.invariants.push_back(island->invariants);
		}
		for (const auto& islandPtr : impl.islands)
		{
			Island& island = *islandPtr;
			ProjectionResult r;
			readAngleReferences(island);
			if (!replayIfAtRest(island, timeStep, r))
			{
				// the energy and momentum restoration (IslandInvariants.h) is part of the projection the rest cache keeps:
				// a function of the same inputs
				if (m_settings.keepEnergyAndMomentum) recordInvariants(island);
				r = projectIsland(island, settings);
				if (m_settings.keepEnergyAndMomentum)
				{
					const InvariantResult k = restoreInvariants(island, r, double(timeStep), settings.velocities);
					if (k.momentumRestored) ++m_stats.momentumRestoredIslands;
					if (k.energyRestored) ++m_stats.energyRestoredIslands;
					m_stats.energyCorrection = std::max(m_stats.energyCorrection, btScalar(std::fabs(k.scale - 1)));
				}
				rememberProjection(island, r);
			}
			if (m_settings.keepEnergyAndMomentum && island.invariants.hold < 1) ++m_stats.energyGuardedIslands;
			if (m_settings.conserveEnergy)
				m_stats.energyCorrection = (std::max)(m_stats.energyCorrection, btScalar(restoreEnergy(island)));
			++m_stats.islands;
			if (r.reused) ++m_stats.restingIslands;
			else
			{
				if (r.iterations == 0) ++m_stats.positionsWithinTolerance;
				if (r.solves == r.iterations) ++m_stats.velocitiesWithinTolerance;
			}
			if (island.useSparse) ++m_stats.sparseIslands;
			if (island.fillOrdered) ++m_stats.loopIslands;
			m_stats.joints += int(island.joints.size()) - island.limitOnlySlots;
			m_stats.quaternionHinges += island.jointsOfKind[kQuaternionHinges];
			m_stats.stockHinges += island.jointsOfKind[kStockHinges];
			m_stats.dofHinges += island.jointsOfKind[kDofHinges];
			m_stats.pointConstraints += island.jointsOfKind[kPointConstraints];
			m_stats.lockedConstraints += island.jointsOfKind[kLockedConstraints];
			m_stats.bodies += int(island.bodies.size());
			m_stats.rows += island.pattern.rows;
			m_stats.iterations = (std::max)(m_stats.iterations, r.iterations);
			m_stats.totalIterations += r.iterations;
			m_stats.factorizations += r.factorizations;
			m_stats.solves += r.solves;
			m_stats.backtracks += r.backtracks;
			m_stats.metricSwitches += r.metricSwitches;
			m_stats.activeLimitRows += r.activeLimitRows;
			m_stats.limitReleases += r.limitReleases;
			m_stats.contactRows += r.contactRows;
			m_stats.numericalIssues += r.numericalIssues;
			m_stats.residualBefore = (std::max)(m_stats.residualBefore, r.residualBefore);
			m_stats.residualAfter = (std::max)(m_stats.residualAfter, r.residualAfter);
			m_stats.velocityResidualBefore = (std::max)(m_stats.velocityResidualBefore, r.velocityResidualBefore);
			m_stats.velocityResidualAfter = (std::max)(m_stats.velocityResidualAfter, r.velocityResidualAfter);
		}
		if (recheck && findSunkBodies(*world, impl.islands, impl.callStart, settings.tolerance, timeStep, impl.near))
		{
			restoreCallStart(impl.islands, impl.callStart);
			for (size_t i = 0; i < impl.islands.size(); ++i)
			{
				impl.islands[i]->invariants = impl.invariants[i];
				forgetProjection(*impl.islands[i]);  // (remade from the same start)
			}
			continue;
		}
		break;
	}
	m_stats.nearFacePairs = int(impl.near.size());
	if (m_settings.moveAttachedBodies) m_stats.attachedBodiesMoved = carryAttachedBodies(impl.attached);
	if (m_settings.closeAttachedConstraints) m_stats.attachedConstraintsClosed = closeAttachedConstraints(impl.attached);
	m_stats.timeMicroseconds =
		std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
	return m_stats;
}
