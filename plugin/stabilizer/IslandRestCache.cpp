// An island at rest gets the last step's projection back: IslandRestCache.h.
#include "IslandRestCache.h"

#include "ConeTwistRows.h"
#include "PointRows.h"

#include "quathinge/btQuaternionHingeConstraint.h"

#include "BulletDynamics/Dynamics/btRigidBody.h"

#include <cstring>

namespace quathinge
{
namespace stabilizer
{
namespace
{
// The inputs are gathered as scalars into an array sized once (no allocation after the island's first step) and
// compared as bytes (bit for bit: −0 and +0 differ, as they may in atan2).
struct Gather
{
	btScalar* at;
	void add(btScalar x) { *at++ = x; }
	void add(const btVector3& v)
	{
		at[0] = v.x();
		at[1] = v.y();
		at[2] = v.z();
		at += 3;
	}
	void add(const btTransform& t)
	{
		for (int r = 0; r < 3; ++r) add(t.getBasis()[r]);
		add(t.getOrigin());
	}
};

// Scalars gathered per island body, per fixed partner, per joint (and its multi-turn angle), and for the step.
const size_t kPerBody = 12 + 3 + 3 + 1 + 3 + 3 + 3 + 1 + 3 + 3 + 3;
const size_t kPerFixedSide = 12 + 3 + 3;
const size_t kPerJoint = 12 + 12 + 1 + 2;
// a contact slot (projectContacts): its points' count, then per point its local and partner points, normal, sign and
// the partner's velocity there
const size_t kPerContactSlot = 1 + (3 + 3 + 3 + 1 + 3) * size_t(kMaxContactRows);

size_t inputSize(const Island& island)
{
	size_t n = 1 + kPerBody * island.bodies.size();
	for (const JointSlot& js : island.joints)
		n += js.contact >= 0 ? kPerContactSlot
							 : kPerJoint + (js.limitSlot ? 1 : 0) + (js.locked ? 3 : 0) + (js.locked && js.limitSlot ? 1 : 0) + (js.point ? 6 : 0) +
								   kPerFixedSide * size_t((js.body[0] < 0) + (js.body[1] < 0));
	return n;
}

void gatherInputs(const Island& island, btScalar timeStep, Array<btScalar>& out)
{
	const size_t n = inputSize(island);
	if (out.size() != n) out.resize(n);  // sized once: the island's structure is fixed
	Gather g{out.data()};
	g.add(timeStep);
	for (const IslandBody& b : island.bodies)
	{
		const btRigidBody& body = *b.rigid;
		g.add(body.getCenterOfMassTransform());
		g.add(body.getLinearVelocity());
		g.add(body.getAngularVelocity());
		g.add(body.getInvMass());
		g.add(body.getInvInertiaDiagLocal());
		g.add(body.getLinearFactor());
		g.add(body.getAngularFactor());
		g.add(btScalar(b.contactScale));  // whether it touches something outside the island (IslandBodies.cpp)
		g.add(body.getGravity());         // the energy restoration's potential (IslandInvariants.h)
		g.add(body.getTotalForce());      // … and the step's forces (its gravity's and the app's: Q15)
		g.add(body.getTotalTorque());
	}
	for (const JointSlot& js : island.joints)
	{
		if (js.contact >= 0)  // its points and fixed partners' velocities (the points say where the partners are)
		{
			const ContactSet& set = island.contacts[size_t(js.contact)];
			g.add(btScalar(set.count));
			for (int r = 0; r < kMaxContactRows; ++r)
			{
				const bool used = r < set.count;
				g.add(used ? set.rows[r].local : btVector3(0, 0, 0));
				g.add(used ? set.rows[r].other : btVector3(0, 0, 0));
				g.add(used ? set.rows[r].normal : btVector3(0, 0, 0));
				g.add(used ? set.rows[r].sign : btScalar(0));
				g.add(used ? set.rows[r].partnerVelocity : btVector3(0, 0, 0));
			}
			continue;
		}
		for (int s = 0; s < 2; ++s)
			if (js.body[s] < 0)  // a fixed partner (static, kinematic, asleep): its pose and velocity enter the rows
			{
				g.add(js.rigid[s]->getCenterOfMassTransform());
				g.add(js.rigid[s]->getLinearVelocity());
				g.add(js.rigid[s]->getAngularVelocity());
			}
		if (js.locked)  // a locked 6-dof: its frames and locked values (which axes are locked is in the signature)
		{
			const DofLocks k = dofLocks(*js.locked);
			g.add(k.frameA);
			g.add(k.frameB);
			g.add(k.offset);
			g.add(k.angles);  // (3 more than the joint's share)
			static_assert(kPerJoint == 12 + 12 + 3, "a locked 6-dof fills the joint's share");
			if (js.limitSlot)  // its limited axis's stops (1 more than a limit slot's share)
			{
				g.add(js.lowerStop);
				g.add(js.upperStop);
			}
			continue;
		}
		if (js.frameHinge)  // a stock or 6-dof hinge: its frames and limit as read this step (readAngleReferences)
		{
			const FrameHinge& h = js.hinge;
			g.add(h.frameA);
			g.add(h.frameB);
			g.add(btScalar((h.angularOnly ? 1 : 0) + (h.sign > 0 ? 2 : 0) + (h.limit ? 4 : 0)));
			g.add(h.center + h.low);
			g.add(h.center + h.high);
			if (js.limitSlot) g.add(js.angleReference);
			continue;
		}
		if (js.point)  // a point constraint: its pivots (a cone twist with a limit row: its frames and spans too), the
					   // rest of its share (6 more than a joint's) zero
		{
			size_t used = 6;
			btVector3 inA, inB;
			pointPivots(*js.point, inA, inB);
			g.add(inA);
			g.add(inB);
			if (js.limitSlot)
			{
				const btConeTwistConstraint& cone = *static_cast<const btConeTwistConstraint*>(js.point);
				const ConeLimits k = coneLimits(cone);
				g.add(cone.getAFrame());
				g.add(cone.getBFrame());
				g.add(btVector3(k.span1, k.span2, k.twistSpan));
				used += 12 + 12 + 3;
				static_assert(kPerJoint + 6 == 6 + 12 + 12 + 3, "a cone twist's limits fill its share (6 more than a joint's)");
			}
			for (size_t k = used; k < kPerJoint + 6; ++k) g.add(btScalar(0));
			if (js.limitSlot) g.add(js.angleReference);
			continue;
		}
		const btQuaternionHingeSettings& settings = js.joint->getSettings();
		g.add(settings.frameInA);
		g.add(settings.frameInB);
		g.add(btScalar((settings.useReferenceFrameA ? 1 : 0) + (settings.angularOnly ? 2 : 0) + (settings.hasLimit ? 4 : 0)));
		g.add(settings.lowerLimit);
		g.add(settings.upperLimit);
		// the projection's limit row starts from the joint's multi-turn angle (readAngleReferences; only where the
		// projection reads it)
		if (js.limitSlot) g.add(js.angleReference);
	}
	btAssert(g.at == out.data() + n);
}

const size_t kOutputsPerBody = 12 + 3 + 3;  // transform, linear and angular velocity

void gatherOutputs(const Island& island, Array<btScalar>& out)
{
	const size_t n = kOutputsPerBody * island.bodies.size();
	if (out.size() != n) out.resize(n);
	Gather g{out.data()};
	for (const IslandBody& b : island.bodies)
	{
		g.add(b.rigid->getCenterOfMassTransform());
		g.add(b.rigid->getLinearVelocity());
		g.add(b.rigid->getAngularVelocity());
	}
}

btVector3 vectorAt(const btScalar* p) { return btVector3(p[0], p[1], p[2]); }
}  // namespace

bool replayIfAtRest(Island& island, btScalar timeStep, ProjectionResult& result)
{
	RestCache& cache = island.restCache;
	gatherInputs(island, timeStep, cache.current);
	const size_t n = cache.current.size();
	if (cache.state[0].inputs.size() != n)
	{
		// the island's first step: every array gets its size now, so that no later swap or gather leaves one to grow
		const size_t outputs = kOutputsPerBody * island.bodies.size();
		for (RestState& s : cache.state)
		{
			s.inputs.resize(n);
			s.outputs.resize(outputs);
			s.valid = false;
		}
	}
	// the last step's state first (a fixed point), then older ones (a cycle of two, three … steps); a moving island
	// differs from each in its first body's pose, so the comparisons stop at their first bytes
	const RestState* match = nullptr;
	for (int age = 1; age <= kRestStates && !match; ++age)
	{
		const RestState& kept = cache.state[(cache.pending + kRestStates - age) % kRestStates];
		if (kept.valid && std::memcmp(cache.current.data(), kept.inputs.data(), n * sizeof(btScalar)) == 0) match = &kept;
	}
	if (!match)
	{
		RestState& into = cache.state[cache.pending];
		into.inputs.swap(cache.current);
		into.valid = false;
		return false;
	}
	// The projection's effects, as it made them: every body's pose (and interpolation pose) and Bullet's world inverse
	// inertia after a position iteration (movePositions, finishPositions), every body's velocities (and interpolation
	// velocities) after a velocity solve (changeVelocities) or the energy and momentum restoration (IslandInvariants.h).
	const ProjectionResult& kept = match->result;
	const bool posesSet = kept.iterations > 0;
	const bool velocitiesSet = kept.solves > kept.iterations || kept.velocitiesRestored;
	const btScalar* out = match->outputs.data();
	for (IslandBody& b : island.bodies)
	{
		btRigidBody& body = *b.rigid;
		if (posesSet)
		{
			const btTransform t(btMatrix3x3(out[0], out[1], out[2], out[3], out[4], out[5], out[6], out[7], out[8]),
								vectorAt(out + 9));
			body.setWorldTransform(t);
			body.setInterpolationWorldTransform(t);
			body.updateInertiaTensor();
		}
		if (velocitiesSet)
		{
			const btVector3 v = vectorAt(out + 12), w = vectorAt(out + 15);
			body.setLinearVelocity(v);
			body.setAngularVelocity(w);
			body.setInterpolationLinearVelocity(v);
			body.setInterpolationAngularVelocity(w);
		}
		out += kOutputsPerBody;
	}
	result = kept;
	result.iterations = result.factorizations = result.solves = result.backtracks = result.metricSwitches =
		result.limitReleases = 0;
	result.reused = true;
	return true;
}

void rememberProjection(Island& island, const ProjectionResult& result)
{
	RestCache& cache = island.restCache;
	RestState& into = cache.state[cache.pending];
	gatherOutputs(island, into.outputs);
	into.result = result;
	into.valid = true;
	cache.pending = (cache.pending + 1) % kRestStates;  // the next one is now the oldest
}

void forgetProjection(Island& island)
{
	for (RestState& s : island.restCache.state) s.valid = false;
}

}  // namespace stabilizer
}  // namespace quathinge
