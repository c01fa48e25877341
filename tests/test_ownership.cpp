// Ownership (issue 17): btReplaceHingeConstraints deletes nothing it did not allocate. The stock hinges of a file
// loaded with btBulletWorldImporter belong to the importer, which deletes them in deleteAllData(); deleting them in
// btReplaceHingeConstraints as well was a double free. Run under AddressSanitizer (build-asan) these tests fail on
// any double free, use after free or leak.
#ifdef QUATHINGE_HAVE_WORLD_IMPORTER

#include "quathinge/btQuaternionHingeConstraint.h"
#include "quathinge/btQuaternionHingeWorldImporter.h"  // btReplaceHingeConstraints with the importer

#include <btBulletDynamicsCommon.h>
#include <btBulletWorldImporter.h>
#include "support/World.h"
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <string>

namespace
{
// The spider's joints after 300 steps at 60 Hz under gravity and its motors: each pivot pair within 3 cm (m). The
// quaternion hinges measure at most 1.1 cm there (float build); a joint torn apart or a body gone NaN is far beyond.
const double kMaxSeparation = 0.03;
const int kSpiderHinges = 24;

std::string spiderFile()
{
	const char* dir = std::getenv("QUATHINGE_MODELS_DIR");
	return std::string(dir && *dir ? dir : QUATHINGE_TEST_MODELS_DIR) + "/spider.bullet";
}

int countStockHinges(const btDynamicsWorld& world)
{
	int n = 0;
	for (int i = 0; i < world.getNumConstraints(); ++i)
		n += world.getConstraint(i)->getConstraintType() == HINGE_CONSTRAINT_TYPE;
	return n;
}

// Steps the spider with its quaternion hinges and checks that each holds its pivot.
void stepAndCheck(qh_test::World& world, const btAlignedObjectArray<btQuaternionHingeConstraint*>& added)
{
	world.step(300);
	for (int i = 0; i < added.size(); ++i)
	{
		const btQuaternionHingeConstraint* q = added[i];
		const double gap = qh_test::separation(q->getRigidBodyA(), q->getAFrame(), q->getRigidBodyB(), q->getBFrame());
		EXPECT_TRUE(std::isfinite(gap)) << i;
		EXPECT_LT(gap, kMaxSeparation) << "joint " << i;
	}
}

void removeAndDelete(qh_test::World& world, btAlignedObjectArray<btQuaternionHingeConstraint*>& added)
{
	for (int i = 0; i < added.size(); ++i)
	{
		world.world().removeConstraint(added[i]);
		delete added[i];
	}
	added.clear();
}
}  // namespace

TEST(Ownership, ImportersHingesStayItsOwnWithoutARemovedArray)
{
	// No removedStock array: the importer's stock hinges are left to it (not deleted), and deleteAllData deletes them
	// once. They are still alive after the replacement: the importer still lists them and they still answer.
	qh_test::World world;
	btBulletWorldImporter importer(&world.world());
	ASSERT_TRUE(importer.loadFile(spiderFile().c_str())) << spiderFile();
	ASSERT_EQ(countStockHinges(world.world()), kSpiderHinges);
	btAlignedObjectArray<btQuaternionHingeConstraint*> added;
	EXPECT_EQ(btReplaceHingeConstraints(&world.world(), &added), kSpiderHinges);
	EXPECT_EQ(added.size(), kSpiderHinges);
	EXPECT_EQ(countStockHinges(world.world()), 0);
	int listed = 0;
	for (int i = 0; i < importer.getNumConstraints(); ++i)
	{
		btTypedConstraint* c = importer.getConstraintByIndex(i);
		if (c->getConstraintType() != HINGE_CONSTRAINT_TYPE) continue;
		++listed;
		btHingeConstraint* stock = static_cast<btHingeConstraint*>(c);
		EXPECT_TRUE(std::isfinite(stock->getLowerLimit()));  // a read: ASan reports it if the hinge was freed
	}
	EXPECT_EQ(listed, kSpiderHinges);
	stepAndCheck(world, added);
	removeAndDelete(world, added);
	importer.deleteAllData();  // deletes the stock hinges (once), the bodies and shapes
	EXPECT_EQ(world.world().getNumConstraints(), 0);
	EXPECT_EQ(world.world().getNumCollisionObjects(), 0);
}

TEST(Ownership, WithTheImporterRemovedHoldsOnlyTheAppsOwnHinges)
{
	// A world the importer loaded, plus one stock hinge the app allocated: given the importer, the removed array holds
	// exactly the app's hinge, which the app deletes; deleteAllData deletes the importer's 24 once. Under ASan
	// (build-asan, and the docs_snippets test's sanitized app) a hinge deleted twice or never fails the run.
	qh_test::World world;
	btBulletWorldImporter importer(&world.world());
	ASSERT_TRUE(importer.loadFile(spiderFile().c_str())) << spiderFile();
	btRigidBody* box = world.addBox(1, btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)),
									btTransform(btQuaternion::getIdentity(), btVector3(0, 5, 0)));
	btHingeConstraint* apps = new btHingeConstraint(*box, btVector3(0, 1, 0), btVector3(0, 0, 1));
	world.world().addConstraint(apps);
	btAlignedObjectArray<btQuaternionHingeConstraint*> added;
	btAlignedObjectArray<btHingeConstraint*> removed;
	EXPECT_EQ(btReplaceHingeConstraints(&world.world(), &added, &removed, importer), kSpiderHinges + 1);
	EXPECT_EQ(countStockHinges(world.world()), 0);
	ASSERT_EQ(removed.size(), 1);
	EXPECT_EQ(removed[0], apps);
	for (int i = 0; i < removed.size(); ++i) delete removed[i];  // README's snippet 3: the removed array is yours
	// the app's hinge's replacement (the last one): stepped with the spider, not checked against the spider's bound
	added.pop_back();
	btQuaternionHingeConstraint* appsReplacement = btQuaternionHingeConstraint::upcast(
		world.world().getConstraint(world.world().getNumConstraints() - 1));
	ASSERT_NE(appsReplacement, nullptr);
	stepAndCheck(world, added);
	world.world().removeConstraint(appsReplacement);
	delete appsReplacement;
	removeAndDelete(world, added);
	importer.deleteAllData();  // the importer's stock hinges, bodies and shapes: each deleted once
	EXPECT_EQ(world.world().getNumConstraints(), 0);
}

TEST(Ownership, DeprecatedRemovedArrayHandsBackEveryHingeAsBefore)
{
	// The deprecated three-argument form keeps its meaning: every stock hinge taken out, the importer's too (to
	// inspect, not to delete), and deleteAllData still deletes each once.
	qh_test::World world;
	btBulletWorldImporter importer(&world.world());
	ASSERT_TRUE(importer.loadFile(spiderFile().c_str())) << spiderFile();
	btAlignedObjectArray<btQuaternionHingeConstraint*> added;
	btAlignedObjectArray<btHingeConstraint*> removed;
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
#elif defined(_MSC_VER)
#pragma warning(push)
#pragma warning(disable : 4996)
#endif
	EXPECT_EQ(btReplaceHingeConstraints(&world.world(), &added, &removed), kSpiderHinges);
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#elif defined(_MSC_VER)
#pragma warning(pop)
#endif
	ASSERT_EQ(removed.size(), kSpiderHinges);
	for (int i = 0; i < removed.size(); ++i)
	{
		bool importers = false;
		for (int k = 0; k < importer.getNumConstraints(); ++k) importers = importers || importer.getConstraintByIndex(k) == removed[i];
		EXPECT_TRUE(importers) << i;
	}
	stepAndCheck(world, added);
	removeAndDelete(world, added);
	importer.deleteAllData();
	EXPECT_EQ(world.world().getNumCollisionObjects(), 0);
}

#endif  // QUATHINGE_HAVE_WORLD_IMPORTER
