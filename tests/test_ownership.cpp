// Ownership (issue 17): btReplaceHingeConstraints deletes nothing it did not allocate. The stock hinges of a file
// loaded with btBulletWorldImporter belong to the importer, which deletes them in deleteAllData(); deleting them in
// btReplaceHingeConstraints as well was a double free. Run under AddressSanitizer (build-asan) these tests fail on
// any double free, use after free or leak.
#ifdef QUATHINGE_HAVE_WORLD_IMPORTER

#include "quathinge/btQuaternionHingeConstraint.h"

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

TEST(Ownership, RemovedArrayHandsBackTheImportersOwnHinges)
{
	// With a removedStock array the caller gets exactly the hinges the importer loaded (to inspect, not to delete:
	// they are the importer's), and deleteAllData still deletes each once.
	qh_test::World world;
	btBulletWorldImporter importer(&world.world());
	ASSERT_TRUE(importer.loadFile(spiderFile().c_str())) << spiderFile();
	btAlignedObjectArray<btQuaternionHingeConstraint*> added;
	btAlignedObjectArray<btHingeConstraint*> removed;
	EXPECT_EQ(btReplaceHingeConstraints(&world.world(), &added, &removed), kSpiderHinges);
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
