// projectContacts: contacts with static bodies as one-sided rows of the projection (plugin/stabilizer/IslandContacts.h).
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/StabilizerScene.h"

#include <gtest/gtest.h>

#include "BulletCollision/CollisionDispatch/btGhostObject.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <utility>

using namespace qh_test;

namespace
{
// What the chain lies on: a static rigid box, the same box kinematic, a plain static btCollisionObject (as Bullet's
// RagdollDemo makes its ground), or objects Bullet's solver does not respond to — a btCollisionObject with
// CF_NO_CONTACT_RESPONSE, a btGhostObject.
enum class Ground
{
	StaticBody,
	KinematicBody,
	CollisionObject,
	NoResponse,
	Ghost
};

// A 4-link chain of 0.5 m boxes (10 × 5 × 5 cm) hinged end to end about z, the first to the world at x = 0, lying on a
// ground box whose top is at y = 0; the first link's pivot 2.6 cm up (its box 1 mm above the ground), the links left
// to sag onto the ground from there.
struct ChainOnTheGround
{
	StabilizerScene scene;
	std::vector<btRigidBody*> links;
	btCollisionObject* ground = nullptr;
	btRigidBody* groundBody = nullptr;  // the ground when it is a rigid body
	btBoxShape groundShape{btVector3(20, 1, 20)};
	std::unique_ptr<btCollisionObject> groundObject;  // the ground when it is not
	explicit ChainOnTheGround(Ground kind = Ground::StaticBody, int n = 4)
	{
		if (kind == Ground::StaticBody || kind == Ground::KinematicBody)
		{
			ground = groundBody = scene.box(btVector3(20, 1, 20), 0, btVector3(0, -1, 0));
			if (kind == Ground::KinematicBody)
			{
				ground->setCollisionFlags(ground->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
				ground->setActivationState(DISABLE_DEACTIVATION);
			}
		}
		else
		{
			groundObject.reset(kind == Ground::Ghost ? new btGhostObject() : new btCollisionObject());
			groundObject->setCollisionShape(&groundShape);
			groundObject->setWorldTransform(btTransform(btQuaternion::getIdentity(), btVector3(0, -1, 0)));
			if (kind == Ground::NoResponse)
				groundObject->setCollisionFlags(groundObject->getCollisionFlags() | btCollisionObject::CF_NO_CONTACT_RESPONSE);
			ground = groundObject.get();
			scene.world().addCollisionObject(ground);
		}
		const btScalar y = btScalar(0.026);
		for (int i = 0; i < n; ++i)
		{
			links.push_back(scene.box(btVector3(btScalar(0.25), btScalar(0.025), btScalar(0.025)), 1,
									  btVector3(btScalar(0.25 + 0.5 * i), y, 0)));
			if (i == 0) scene.hingeToWorld(*links[0], btVector3(btScalar(-0.25), 0, 0), btVector3(0, 0, 1));
			else
				scene.hinge(*links[size_t(i - 1)], *links[size_t(i)], btVector3(btScalar(0.25), 0, 0),
							btVector3(btScalar(-0.25), 0, 0), btVector3(0, 0, 1), btVector3(0, 0, 1));
		}
	}
	~ChainOnTheGround()
	{
		if (groundObject) scene.world().removeCollisionObject(groundObject.get());
	}
	// Calls f(link, point in the link's frame, point in world at the link's current pose) for every contact point of
	// the links with the ground.
	template <class F>
	void forEachGroundPoint(F f)
	{
		btDispatcher& d = *scene.world().getDispatcher();
		for (int m = 0; m < d.getNumManifolds(); ++m)
		{
			btPersistentManifold* manifold = d.getManifoldByIndexInternal(m);
			const bool groundIsB = manifold->getBody1() == ground;
			if (!groundIsB && manifold->getBody0() != ground) continue;
			const btCollisionObject* link = groundIsB ? manifold->getBody0() : manifold->getBody1();
			for (int p = 0; p < manifold->getNumContacts(); ++p)
			{
				const btManifoldPoint& point = manifold->getContactPoint(p);
				const btVector3 local = groundIsB ? point.m_localPointA : point.m_localPointB;
				f(link, local, link->getWorldTransform() * local);
			}
		}
	}
	// The links' contact points with the ground deeper than `depth` (m): the link and the point in its frame.
	std::vector<std::pair<const btCollisionObject*, btVector3>> pointsDeeperThan(double depth)
	{
		std::vector<std::pair<const btCollisionObject*, btVector3>> points;
		forEachGroundPoint([&](const btCollisionObject* link, const btVector3& local, const btVector3& onLink) {
			if (-double(onLink.y()) > depth) points.push_back({link, local});
		});
		return points;
	}
	// The deepest penetration (m, ≥ 0) of the links' contact points with the ground, at the links' current poses.
	double penetration()
	{
		double deepest = 0;
		forEachGroundPoint([&](const btCollisionObject*, const btVector3&, const btVector3& onLink) {
			deepest = std::max(deepest, -double(onLink.y()));  // the ground's top is y = 0
		});
		return deepest;
	}
};

btQuaternionHingeStabilizerSettings withContacts()
{
	btQuaternionHingeStabilizerSettings s;
	s.projectContacts = true;
	return s;
}
}  // namespace

TEST(StabilizerContacts, AChainLyingOnTheGroundIsLiftedOutAndClosed)
{
	ChainOnTheGround w;
	btQuaternionHingeStabilizer stabilizer(withContacts());
	for (int i = 0; i < 30; ++i) w.scene.world().stepSimulation(kTimeStep, 0, kTimeStep);
	const double before = w.penetration();
	const btQuaternionHingeStabilizerStats& stats = stabilizer.stabilize(&w.scene.world(), kTimeStep);
	double separation = 0, misalignment = 0;
	w.scene.jointErrors(separation, misalignment);
	std::printf("[ measured ] penetration %.3g -> %.3g m, separation %.3g m, contact rows %d, iterations %d\n", before,
				w.penetration(), separation, stats.contactRows, stats.iterations);
	EXPECT_GT(stats.contactRows, 0);
	EXPECT_LE(w.penetration(), kSeparationTolerance);
	EXPECT_LE(separation, kSeparationTolerance);
}

TEST(StabilizerContacts, AStaticCollisionObjectGroundIsAPartnerLikeAStaticBody)
{
	// Bullet's RagdollDemo makes its ground a plain static btCollisionObject: its contacts are rows as a static body's are
	for (Ground kind : {Ground::CollisionObject, Ground::KinematicBody})
	{
		ChainOnTheGround w(kind);
		btQuaternionHingeStabilizer stabilizer(withContacts());
		for (int i = 0; i < 30; ++i) w.scene.world().stepSimulation(kTimeStep, 0, kTimeStep);
		const double before = w.penetration();
		ASSERT_GT(before, kSeparationTolerance) << "the test needs links in the ground";
		const btQuaternionHingeStabilizerStats& stats = stabilizer.stabilize(&w.scene.world(), kTimeStep);
		double separation = 0, misalignment = 0;
		w.scene.jointErrors(separation, misalignment);
		std::printf("[ measured ] %s ground: penetration %.3g -> %.3g m, separation %.3g m, contact rows %d\n",
					kind == Ground::CollisionObject ? "btCollisionObject" : "kinematic", before, w.penetration(),
					separation, stats.contactRows);
		EXPECT_GT(stats.contactRows, 0);
		EXPECT_LE(w.penetration(), kSeparationTolerance);
		EXPECT_LE(separation, kSeparationTolerance);
	}
}

TEST(StabilizerContacts, ContactsBulletDoesNotRespondToAreNotRows)
{
	// off (projectContacts = false), a ground with CF_NO_CONTACT_RESPONSE, a ghost object: no contact rows
	for (Ground kind : {Ground::StaticBody, Ground::NoResponse, Ground::Ghost})
	{
		ChainOnTheGround w(kind);
		btQuaternionHingeStabilizerSettings settings = withContacts();
		if (kind == Ground::StaticBody) settings.projectContacts = false;
		btQuaternionHingeStabilizer stabilizer(settings);
		for (int i = 0; i < 30; ++i) w.scene.world().stepSimulation(kTimeStep, 0, kTimeStep);
		if (kind == Ground::StaticBody) ASSERT_GT(w.penetration(), 0) << "the test needs links in the ground";
		else ASSERT_GT(w.scene.world().getDispatcher()->getNumManifolds(), 0) << "the test needs manifolds with the ground";
		EXPECT_EQ(stabilizer.stabilize(&w.scene.world(), kTimeStep).contactRows, 0) << int(kind);
	}
}

TEST(StabilizerContacts, AKinematicGroundRisingIsNotApproachedAfterTheProjection)
{
	// A kinematic ground moving up at 0.5 m/s: a contact row's velocity is relative to it, so after the projection the
	// deepest link point (a row of its link's slot) does not approach it (a partner taken at rest would leave it
	// sinking at 0.5 m/s). Shallower points may have left the rows in the position stage (their multiplier pulled):
	// those are Bullet's solver's.
	const double kRise = 0.5;                // m/s
	const double kApproachTolerance = 1e-4;  // m/s: the velocity rows' threshold (positionTolerance / step) and rounding
	ChainOnTheGround w(Ground::KinematicBody);
	btQuaternionHingeStabilizer stabilizer(withContacts());
	for (int i = 0; i < 30; ++i) w.scene.world().stepSimulation(kTimeStep, 0, kTimeStep);
	const auto deep = w.pointsDeeperThan(kSeparationTolerance);  // deeper than the rows' threshold
	ASSERT_FALSE(deep.empty()) << "the test needs links in the ground";
	size_t deepest = 0;
	for (size_t i = 0; i < deep.size(); ++i)
		if ((deep[i].first->getWorldTransform() * deep[i].second).y() < (deep[deepest].first->getWorldTransform() * deep[deepest].second).y())
			deepest = i;
	w.groundBody->setLinearVelocity(btVector3(0, btScalar(kRise), 0));
	const btQuaternionHingeStabilizerStats& stats = stabilizer.stabilize(&w.scene.world(), kTimeStep);
	EXPECT_GT(stats.contactRows, 0);
	const btRigidBody* link = btRigidBody::upcast(deep[deepest].first);
	const btVector3 at = link->getWorldTransform() * deep[deepest].second;
	const double separating = link->getVelocityInLocalPoint(at - link->getCenterOfMassPosition()).y() - kRise;
	std::printf("[ measured ] the deepest point's separation from the rising ground %.3g m/s\n", separating);
	EXPECT_GE(separating, -kApproachTolerance);
}
namespace
{
// A heavy ball (the torso, 10 kg, 0.15 m) and a capsule leg (1 kg, radius 5 cm, 0.5 m tip to tip) hinged about z at
// the ball's centre, 0.4 m above a ground box (a static btCollisionObject, RagdollDemo's kind), with the hinge's limits
// ±0.1 rad about the leg hanging down; the leg starts horizontal, 1.47 rad past its limit, 0.35 m above the ground:
// Bullet has no contact for it (its AABB is clear of the ground's). Closing the limit swings it down, and with the
// torso where it is its tip would go 0.1 m into the ground: the leg must swing and the torso rise.
struct LegOverTheGround
{
	btDefaultCollisionConfiguration configuration;
	btCollisionDispatcher dispatcher{&configuration};
	btDbvtBroadphase broadphase;
	btSequentialImpulseConstraintSolver solver;
	btDiscreteDynamicsWorld world{&dispatcher, &broadphase, &solver, &configuration};
	btBoxShape groundShape{btVector3(5, btScalar(0.5), 5)};
	btCollisionObject ground;
	btSphereShape torsoShape{btScalar(0.15)};
	btCapsuleShape legShape{btScalar(0.05), btScalar(0.4)};
	std::unique_ptr<btRigidBody> torso, leg;
	std::unique_ptr<btHingeConstraint> hinge;
	static constexpr double kLegHalf = 0.25;  // m: from the leg's centre to its tip
	LegOverTheGround()
	{
		ground.setCollisionShape(&groundShape);
		ground.setWorldTransform(btTransform(btQuaternion::getIdentity(), btVector3(0, btScalar(-0.5), 0)));
		world.addCollisionObject(&ground);
		btVector3 inertia;
		torsoShape.calculateLocalInertia(10, inertia);
		torso.reset(new btRigidBody(10, nullptr, &torsoShape, inertia));
		torso->setWorldTransform(btTransform(btQuaternion::getIdentity(), btVector3(0, btScalar(0.4), 0)));
		legShape.calculateLocalInertia(1, inertia);
		leg.reset(new btRigidBody(1, nullptr, &legShape, inertia));
		// the leg's axis (its local y) along world −x, its top tip at the torso's centre
		leg->setWorldTransform(btTransform(btQuaternion(btVector3(0, 0, 1), btScalar(SIMD_HALF_PI)),
										   btVector3(btScalar(kLegHalf), btScalar(0.4), 0)));
		for (btRigidBody* b : {torso.get(), leg.get()})
		{
			b->setActivationState(DISABLE_DEACTIVATION);
			world.addRigidBody(b);
		}
		// angle 0: the leg hanging down (its frame aligned with the torso's)
		hinge.reset(new btHingeConstraint(*torso, *leg, btTransform::getIdentity(),
										  btTransform(btQuaternion::getIdentity(), btVector3(0, btScalar(kLegHalf), 0))));
		hinge->setLimit(btScalar(-0.1), btScalar(0.1));
		world.addConstraint(hinge.get(), true);
	}
	~LegOverTheGround()
	{
		world.removeConstraint(hinge.get());
		world.removeRigidBody(leg.get());
		world.removeRigidBody(torso.get());
		world.removeCollisionObject(&ground);
	}
	// m: how deep the leg's lowest point is below the ground's top (negative: its clearance)
	double legDepth() const
	{
		const btTransform& t = leg->getWorldTransform();
		const btVector3 tip(0, legShape.getHalfHeight(), 0);
		return double(legShape.getRadius()) - std::min(double((t * tip).y()), double((t * -tip).y()));
	}
};
}  // namespace

TEST(StabilizerContacts, APartSwungIntoAGroundItHadNoContactWithIsHeld)
{
	// One step with the stabilizer: its projection closes the leg's limit; a first pass that swings the leg into the
	// ground (no contact row: Bullet had no manifold for it) is found after the projection and the call is done again
	// with rows for the leg on the ground's face (getLastStats().nearFacePairs). Without projectContacts the leg goes
	// in, which shows the scene asks the question.
	for (bool contacts : {false, true})
	{
		LegOverTheGround w;
		ASSERT_LT(w.legDepth(), -0.3) << "the leg starts clear of the ground";
		btQuaternionHingeStabilizerSettings settings;
		settings.projectContacts = contacts;
		btQuaternionHingeStabilizer stabilizer(settings);
		w.world.addAction(&stabilizer);
		w.world.stepSimulation(kTimeStep, 0, kTimeStep);
		w.world.removeAction(&stabilizer);
		const btQuaternionHingeStabilizerStats& stats = stabilizer.getLastStats();
		const double angle = double(w.hinge->getHingeAngle());
		const double separation = double((w.torso->getWorldTransform() * btVector3(0, 0, 0) -
										  w.leg->getWorldTransform() * btVector3(0, btScalar(LegOverTheGround::kLegHalf), 0))
											 .length());
		std::printf(
			"[ measured ] projectContacts %d: leg depth %.3e m, hinge angle %.4f rad, pivot %.2e m, torso at y %.4f m, "
			"near-face pairs %d\n",
			int(contacts), w.legDepth(), angle, separation, double(w.torso->getWorldTransform().getOrigin().y()),
			stats.nearFacePairs);
		EXPECT_LE(separation, kSeparationTolerance);
		EXPECT_LE(std::fabs(angle), 0.1 + 1e-3);  // rad: the limit, to the 1e-3 rad
		if (!contacts)
		{
			EXPECT_GT(w.legDepth(), 0.02);  // m: the leg went in (measured 3.8e-2 m: the limit leaves it 0.1 rad from vertical)
			continue;
		}
		EXPECT_EQ(stats.nearFacePairs, 1);
		EXPECT_LE(w.legDepth(), kSeparationTolerance);  // m: at the ground's face, not in it
	}
}
#endif
