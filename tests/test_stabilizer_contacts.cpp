// projectContacts: contacts with static bodies as one-sided rows of the projection (plugin/stabilizer/IslandContacts.h).
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/StabilizerScene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

using namespace qh_test;

namespace
{
// A 4-link chain of 0.5 m boxes (10 × 5 × 5 cm) hinged end to end about z, the first to the world at x = 0, lying on a
// static ground box whose top is at y = 0; the first link's pivot 2.6 cm up (its box 1 mm above the ground), the
// links left to sag onto the ground from there.
struct ChainOnTheGround
{
	StabilizerScene scene;
	std::vector<btRigidBody*> links;
	btRigidBody* ground;
	explicit ChainOnTheGround(bool kinematicGround = false, int n = 4)
	{
		ground = scene.box(btVector3(20, 1, 20), 0, btVector3(0, -1, 0));
		if (kinematicGround)
		{
			ground->setCollisionFlags(ground->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
			ground->setActivationState(DISABLE_DEACTIVATION);
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
	// The deepest penetration (m, ≥ 0) of the links' contact points with the ground, at the links' current poses.
	double penetration()
	{
		double deepest = 0;
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
				const btVector3 onLink =
					link->getWorldTransform() * (groundIsB ? point.m_localPointA : point.m_localPointB);
				deepest = std::max(deepest, -double(onLink.y()));  // the ground's top is y = 0
			}
		}
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

TEST(StabilizerContacts, OffOrOnAKinematicBodyThereAreNoContactRows)
{
	// the default leaves contacts out; a kinematic partner moves within the step, so its contacts are not rows either
	for (bool kinematic : {false, true})
	{
		ChainOnTheGround w(kinematic);
		btQuaternionHingeStabilizer stabilizer(kinematic ? withContacts() : btQuaternionHingeStabilizerSettings());
		for (int i = 0; i < 30; ++i) w.scene.world().stepSimulation(kTimeStep, 0, kTimeStep);
		ASSERT_GT(w.penetration(), 0) << "the test needs links in the ground";
		EXPECT_EQ(stabilizer.stabilize(&w.scene.world(), kTimeStep).contactRows, 0);
	}
}
#endif
