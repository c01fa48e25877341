// btQuaternionHingeStabilizer::setFilter: the stabilizer projects only the joints a filter keeps, so an app pays for it
// only where a scene needs it; the joints left out step exactly as in a world without the stabilizer.
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/StabilizerScene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

using namespace qh_test;

namespace
{
// Keeps the joints whose user constraint id is `id` (how an app marks its hero's joints).
struct KeepId : btQuaternionHingeStabilizerFilter
{
	int id = 1;
	bool needsStabilization(const btTypedConstraint& joint) const override
	{
		return joint.getUserConstraintId() == id;
	}
};

// Two 5-link chains (MATH.md's 3-D chain, released horizontally) far apart: "hero" at 10 m, "crowd" at 20 m. The
// hero's joints carry user id 1, the crowd's 2.
struct TwoChains
{
	StabilizerScene scene;
	std::vector<btRigidBody*> hero, crowd;
	TwoChains()
	{
		hero = scene.chain(5, 1, 10);
		for (btQuaternionHingeConstraint* h : scene.hinges()) h->setUserConstraintId(1);
		crowd = scene.chain(5, 1, 20);
		for (btQuaternionHingeConstraint* h : scene.hinges())
			if (h->getUserConstraintId() != 1) h->setUserConstraintId(2);
	}
	// Largest pivot separation (m) over the joints with user id `id`.
	double separation(int id) const
	{
		double worst = 0;
		for (const btQuaternionHingeConstraint* h : scene.hinges())
		{
			if (h->getUserConstraintId() != id) continue;
			const btTransform a = h->getRigidBodyA().getCenterOfMassTransform() * h->getAFrame();
			const btTransform b = h->getRigidBodyB().getCenterOfMassTransform() * h->getBFrame();
			worst = std::max(worst, double((b.getOrigin() - a.getOrigin()).length()));
		}
		return worst;
	}
};
}  // namespace

TEST(StabilizerFilter, ProjectsOnlyTheJointsKeptAndLeavesTheOthersAsWithoutIt)
{
	TwoChains filtered, bare;
	KeepId keep;
	btQuaternionHingeStabilizer stabilizer;
	stabilizer.setFilter(&keep);
	EXPECT_EQ(stabilizer.getFilter(), &keep);
	filtered.scene.addAction(&stabilizer);
	double heroWorst = 0, bareHeroWorst = 0;
	for (int i = 0; i < 120; ++i)
	{
		filtered.scene.world().stepSimulation(kTimeStep, 0);
		bare.scene.world().stepSimulation(kTimeStep, 0);
		const btQuaternionHingeStabilizerStats& stats = stabilizer.getLastStats();
		ASSERT_EQ(stats.joints, 5) << "step " << i;
		ASSERT_EQ(stats.filteredJoints, 5) << "step " << i;
		ASSERT_EQ(stats.islands, 1) << "step " << i;
		heroWorst = std::max(heroWorst, filtered.separation(1));
		bareHeroWorst = std::max(bareHeroWorst, bare.separation(1));
	}
	// The hero is held to the stabilizer's tolerance; without the stabilizer the same chain drifts far more.
	EXPECT_LE(heroWorst, kSeparationTolerance);
	EXPECT_GT(bareHeroWorst, 100 * kSeparationTolerance);
	// The crowd was never touched: bit for bit the trajectory of the world without a stabilizer.
	for (size_t k = 0; k < filtered.crowd.size(); ++k)
	{
		EXPECT_TRUE(sameTransform(filtered.crowd[k]->getCenterOfMassTransform(), bare.crowd[k]->getCenterOfMassTransform()))
			<< "crowd link " << k;
		EXPECT_EQ(filtered.crowd[k]->getLinearVelocity(), bare.crowd[k]->getLinearVelocity()) << "crowd link " << k;
		EXPECT_EQ(filtered.crowd[k]->getAngularVelocity(), bare.crowd[k]->getAngularVelocity()) << "crowd link " << k;
	}
	EXPECT_EQ(filtered.separation(2), bare.separation(2));
}

TEST(StabilizerFilter, AChangedAnswerRebuildsTheIslandsAndNullProjectsEveryJoint)
{
	TwoChains w;
	KeepId keep;
	btQuaternionHingeStabilizer stabilizer;
	stabilizer.setFilter(&keep);
	w.scene.addAction(&stabilizer);
	w.scene.world().stepSimulation(kTimeStep, 0);
	EXPECT_TRUE(stabilizer.getLastStats().structureRebuilt);
	w.scene.world().stepSimulation(kTimeStep, 0);
	EXPECT_FALSE(stabilizer.getLastStats().structureRebuilt);
	EXPECT_EQ(stabilizer.getLastStats().joints, 5);
	// the filter now keeps the crowd instead: rebuilt, the crowd projected, the hero left
	keep.id = 2;
	w.scene.world().stepSimulation(kTimeStep, 0);
	EXPECT_TRUE(stabilizer.getLastStats().structureRebuilt);
	EXPECT_EQ(stabilizer.getLastStats().joints, 5);
	EXPECT_LE(w.separation(2), kSeparationTolerance);
	// no filter: every joint
	stabilizer.setFilter(nullptr);
	w.scene.world().stepSimulation(kTimeStep, 0);
	EXPECT_TRUE(stabilizer.getLastStats().structureRebuilt);
	EXPECT_EQ(stabilizer.getLastStats().joints, 10);
	EXPECT_EQ(stabilizer.getLastStats().filteredJoints, 0);
	EXPECT_EQ(stabilizer.getLastStats().islands, 2);
	for (int i = 0; i < 30; ++i) w.scene.world().stepSimulation(kTimeStep, 0);
	EXPECT_LE(w.separation(1), kSeparationTolerance);
	EXPECT_LE(w.separation(2), kSeparationTolerance);
}
#endif  // QUATHINGE_HAVE_STABILIZER
