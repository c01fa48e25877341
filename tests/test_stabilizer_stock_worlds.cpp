// Worlds of the hinges an app already has, held with no class swapped (projectStockHinges, projectDofHinges: on by
// default; the rows: tests/test_stabilizer_stock.cpp). Chains of every kind are held to the targets and their limits
// within 1e-3 rad, where the solver alone parts them by centimetres; a world whose joints the filter leaves out steps
// bit for bit as without the stabilizer; the filter and the stats see every kind; spider.bullet's 24 stock hinges are
// held as loaded, and URDF robots as Bullet's importer builds them (6-dof hinges).
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/StabilizerScene.h"
#include "support/StockHinges.h"
#include "support/World.h"

#ifdef QUATHINGE_HAVE_SCENES
#include "JointKinds.h"
#include "SceneSpec.h"
#include "Simulation.h"
#endif

#include <btBulletDynamicsCommon.h>
#ifdef QUATHINGE_HAVE_WORLD_IMPORTER
#include <btBulletWorldImporter.h>
#endif
#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

using namespace qh_test;

namespace
{
// A 3-D chain of n links (0.5 m along x, released horizontally at 10 m), joint i's axis z or y alternately, every
// other joint limited to [−0.6, 0.6] rad on the joint's own angle, built with `kind`; the first to the world.
struct KindChain
{
	StabilizerScene scene;
	std::vector<btTypedConstraint*> joints;
	std::vector<int> axes;
	KindChain(const Kind& kind, int n)
	{
		btRigidBody* previous = scene.box(btVector3(btScalar(0.05), btScalar(0.05), btScalar(0.05)), 0, btVector3(0, 10, 0));
		for (int i = 0; i < n; ++i)
		{
			btRigidBody* link = scene.box(btVector3(btScalar(0.25), btScalar(0.05), btScalar(0.05)), 1,
										  btVector3(btScalar(0.5 * i + 0.25), 10, 0));
			const btVector3 w = i % 2 ? btVector3(0, 1, 0) : btVector3(0, 0, 1);
			const btMatrix3x3 basis = basisWithAxis(kind.axis, w);
			const btVector3 pivot(btScalar(0.5 * i), 10, 0);
			const btTransform frame(basis, pivot);
			const btTransform fa = previous->getCenterOfMassTransform().inverse() * frame;
			const btTransform fb = link->getCenterOfMassTransform().inverse() * frame;
			const bool limited = i % 2 == 1;
			btTypedConstraint* c = kind.make(*previous, *link, fa, fb, limited ? btScalar(-0.6) : 1,
											 limited ? btScalar(0.6) : -1);
			scene.addConstraint(c);
			joints.push_back(c);
			axes.push_back(kind.axis);
			previous = link;
		}
	}
	// The largest separation (m), misalignment (rad) and overshoot past a stop (rad, the joint's own angle) over
	// `steps` steps, measured from the frames here (not through StockHingeRows.h).
	void run(int steps, double& separation, double& misalignment, double& overshoot)
	{
		separation = misalignment = overshoot = 0;
		for (int s = 0; s < steps; ++s)
		{
			scene.world().stepSimulation(kTimeStep, 0);
			for (size_t j = 0; j < joints.size(); ++j)
			{
				btTypedConstraint& c = *joints[j];
				btTransform fa, fb;
				btScalar lo = 1, hi = -1, angle = 0;
				const btTransform tA = c.getRigidBodyA().getCenterOfMassTransform();
				const btTransform tB = c.getRigidBodyB().getCenterOfMassTransform();
				if (c.getConstraintType() == HINGE_CONSTRAINT_TYPE)
				{
					auto& h = static_cast<btHingeConstraint&>(c);
					fa = h.getAFrame();
					fb = h.getBFrame();
					if (h.hasLimit()) lo = h.getLowerLimit(), hi = h.getUpperLimit();
					angle = h.getHingeAngle(tA, tB);
				}
				else
				{
					btVector3 low, high;
					if (c.getConstraintType() == D6_SPRING_2_CONSTRAINT_TYPE)
					{
						auto& d = static_cast<btGeneric6DofSpring2Constraint&>(c);
						fa = d.getFrameOffsetA();
						fb = d.getFrameOffsetB();
						d.getAngularLowerLimit(low);
						d.getAngularUpperLimit(high);
						d.calculateTransforms(tA, tB);
						angle = d.getAngle(axes[j]);
					}
					else
					{
						auto& d = static_cast<btGeneric6DofConstraint&>(c);
						fa = d.getFrameOffsetA();
						fb = d.getFrameOffsetB();
						d.getAngularLowerLimit(low);
						d.getAngularUpperLimit(high);
						d.calculateTransforms(tA, tB);
						angle = d.getAngle(axes[j]);
					}
					lo = low[axes[j]];
					hi = high[axes[j]];
				}
				const btTransform a = tA * fa, b = tB * fb;
				separation = std::max(separation, double((b.getOrigin() - a.getOrigin()).length()));
				const btVector3 za = a.getBasis().getColumn(axes[j]), zb = b.getBasis().getColumn(axes[j]);
				misalignment = std::max(misalignment, double(btAtan2(za.cross(zb).length(), za.dot(zb))));
				if (lo <= hi) overshoot = std::max(overshoot, std::max(double(lo - angle), double(angle - hi)));
			}
		}
	}
};
}  // namespace

TEST(StabilizerStock, ChainsOfEveryKindAreHeldAndTheirLimitsKept)
{
	// A 10-link chain of each kind (stock; 6dof2 about x, y, z in two rotation orders; the old 6-dof), 2 s: with the
	// stabilizer's defaults every joint within the targets, without it parted by more than a millimetre.
	std::vector<Kind> all = kinds();
	std::vector<Kind> picked;
	for (const Kind& k : all)
		if (k.name == "stock" || k.name.rfind("6dof2 order 0", 0) == 0 || k.name.rfind("6dof2 order 5", 0) == 0 ||
			k.name == "6dof axis 2")
			picked.push_back(k);
	for (const Kind& kind : picked)
	{
		double separation, misalignment, overshoot;
		{
			KindChain bare(kind, 10);
			bare.run(120, separation, misalignment, overshoot);
			EXPECT_GT(separation, kUnheldSeparation) << kind.name;
		}
		KindChain chain(kind, 10);
		btQuaternionHingeStabilizer stabilizer;
		chain.scene.addAction(&stabilizer);
		chain.run(120, separation, misalignment, overshoot);
		EXPECT_LE(separation, kDouble ? kSeparationTolerance : kHeldSeparation) << kind.name;
		EXPECT_LE(misalignment, kHeldMisalignment) << kind.name;
		EXPECT_LE(overshoot, kHeldOvershoot) << kind.name;
		const btQuaternionHingeStabilizerStats& stats = stabilizer.getLastStats();
		EXPECT_EQ(stats.joints, 10);
		EXPECT_EQ(kind.name == "stock" ? stats.stockHinges : stats.dofHinges, 10) << kind.name;
		chain.scene.world().removeAction(&stabilizer);
	}
}

namespace
{
// Sets a hinge's limit on its own angle to [lo, hi] through its public API (the free axis's, for a 6-dof).
void setHingeLimit(btTypedConstraint& c, int axis, btScalar lo, btScalar hi)
{
	btVector3 low(0, 0, 0), high(0, 0, 0);
	low[axis] = lo;
	high[axis] = hi;
	if (c.getConstraintType() == HINGE_CONSTRAINT_TYPE) static_cast<btHingeConstraint&>(c).setLimit(lo, hi);
	else if (c.getConstraintType() == D6_SPRING_2_CONSTRAINT_TYPE)
	{
		static_cast<btGeneric6DofSpring2Constraint&>(c).setAngularLowerLimit(low);
		static_cast<btGeneric6DofSpring2Constraint&>(c).setAngularUpperLimit(high);
	}
	else
	{
		static_cast<btGeneric6DofConstraint&>(c).setAngularLowerLimit(low);
		static_cast<btGeneric6DofConstraint&>(c).setAngularUpperLimit(high);
	}
}

// Moves a 6-dof's frame in B by `offset` (in B's frame) through setFrames.
template <typename Dof>
void shiftDofFrameB(Dof& d, const btVector3& offset)
{
	btTransform fb = d.getFrameOffsetB();
	fb.setOrigin(fb.getOrigin() + offset);
	d.setFrames(d.getFrameOffsetA(), fb);
}

// Moves a hinge's frame in B by `offset` (in B's frame) through its public API (setFrames).
void shiftFrameB(btTypedConstraint& c, const btVector3& offset)
{
	if (c.getConstraintType() == HINGE_CONSTRAINT_TYPE)
	{
		auto& h = static_cast<btHingeConstraint&>(c);
		btTransform fb = h.getBFrame();
		fb.setOrigin(fb.getOrigin() + offset);
		h.setFrames(h.getAFrame(), fb);
	}
	else if (c.getConstraintType() == D6_SPRING_2_CONSTRAINT_TYPE)
		shiftDofFrameB(static_cast<btGeneric6DofSpring2Constraint&>(c), offset);
	else
		shiftDofFrameB(static_cast<btGeneric6DofConstraint&>(c), offset);
}
}  // namespace

TEST(StabilizerStock, LimitsAndFramesChangedBetweenStepsAreHeldFromTheNextStep)
{
	// The stabilizer keeps a hinge's shape while its island stands and reads its limits and frames every step: a
	// chain of each kind swings for 0.5 s, then every limited joint's limit becomes [0.3, 0.5] rad (the joints are
	// below it then) and the last joint's frame in B moves by 1 cm, through the joints' own API. From the next step
	// on every joint is within the targets of its new limit and frames, with the islands kept (read, not rebuilt);
	// without the stabilizer the solver leaves the joints past their new stops by more than 10 × the target.
	for (const Kind& kind : kinds())
	{
		if (!(kind.name == "stock" || kind.name == "6dof2 order 0 axis 0" || kind.name == "6dof2 order 5 axis 1" ||
			  kind.name == "6dof axis 2"))
			continue;
		double separation, misalignment, overshoot;
		auto change = [&](KindChain& chain) {
			for (size_t j = 1; j < chain.joints.size(); j += 2)
				setHingeLimit(*chain.joints[j], kind.axis, btScalar(0.3), btScalar(0.5));
			shiftFrameB(*chain.joints.back(), btVector3(btScalar(0.01), 0, 0));
		};
		{
			KindChain bare(kind, 6);
			bare.run(30, separation, misalignment, overshoot);
			change(bare);
			bare.run(1, separation, misalignment, overshoot);
			EXPECT_GT(overshoot, 10 * kHeldOvershoot) << kind.name;
		}
		KindChain chain(kind, 6);
		btQuaternionHingeStabilizer stabilizer;
		chain.scene.addAction(&stabilizer);
		chain.run(30, separation, misalignment, overshoot);
		change(chain);
		for (int s = 0; s < 30; ++s)
		{
			chain.run(1, separation, misalignment, overshoot);
			EXPECT_FALSE(stabilizer.getLastStats().structureRebuilt) << kind.name;
			EXPECT_LE(separation, kDouble ? kSeparationTolerance : kHeldSeparation) << kind.name << " step " << s;
			EXPECT_LE(misalignment, kHeldMisalignment) << kind.name << " step " << s;
			EXPECT_LE(overshoot, kHeldOvershoot) << kind.name << " step " << s;
		}
		// a 6dof2's rotation order (its angle's meaning: its sign) is part of its shape: the island is built again
		if (kind.name.rfind("6dof2", 0) == 0)
		{
			for (btTypedConstraint* c : chain.joints)
				static_cast<btGeneric6DofSpring2Constraint*>(c)->setRotationOrder(kind.name == "6dof2 order 0 axis 0" ? RO_ZYX
																													  : RO_XYZ);
			chain.run(1, separation, misalignment, overshoot);
			EXPECT_TRUE(stabilizer.getLastStats().structureRebuilt) << kind.name;
			for (int s = 0; s < 10; ++s)
			{
				chain.run(1, separation, misalignment, overshoot);
				EXPECT_LE(overshoot, kHeldOvershoot) << kind.name << " new order, step " << s;
			}
		}
		chain.scene.world().removeAction(&stabilizer);
	}
}

namespace
{
// A mixed world: a stock hinge with a limit and its motor, a 6dof2 hinge about x with a motor, an old 6-dof hinge,
// a quaternion hinge and a point-to-point, in one chain from the world.
struct MixedChain
{
	StabilizerScene scene;
	btHingeConstraint* stock;
	btGeneric6DofSpring2Constraint* dof2;
	btGeneric6DofConstraint* dof;
	MixedChain()
	{
		std::vector<btRigidBody*> links;
		for (int i = 0; i < 5; ++i)
			links.push_back(scene.box(btVector3(btScalar(0.25), btScalar(0.05), btScalar(0.05)), 1,
									  btVector3(btScalar(0.5 * i + 0.25), 10, 0)));
		btRigidBody* ground = scene.box(btVector3(btScalar(0.05), btScalar(0.05), btScalar(0.05)), 0, btVector3(0, 10, 0));
		auto frames = [&](btRigidBody& a, btRigidBody& b, int axis, const btVector3& w, btTransform& fa, btTransform& fb) {
			const btVector3 pivot = b.getCenterOfMassPosition() - btVector3(btScalar(0.25), 0, 0);
			const btTransform frame(basisWithAxis(axis, w), pivot);
			fa = a.getCenterOfMassTransform().inverse() * frame;
			fb = b.getCenterOfMassTransform().inverse() * frame;
		};
		btTransform fa, fb;
		frames(*ground, *links[0], 2, btVector3(0, 0, 1), fa, fb);
		stock = new btHingeConstraint(*ground, *links[0], fa, fb, false);
		stock->setLimit(btScalar(-0.8), btScalar(0.8));
		stock->enableAngularMotor(true, 1, btScalar(0.05));
		scene.addConstraint(stock);
		frames(*links[0], *links[1], 0, btVector3(0, 1, 0), fa, fb);
		dof2 = dofHinge(*links[0], *links[1], fa, fb, 0, RO_ZYX, 1, -1);
		dof2->enableMotor(0, true);
		dof2->setTargetVelocity(0, btScalar(0.5));
		dof2->setMaxMotorForce(0, 2);
		scene.addConstraint(dof2);
		frames(*links[1], *links[2], 1, btVector3(0, 0, 1), fa, fb);
		dof = oldDofHinge(*links[1], *links[2], fa, fb, 1, btScalar(-1), btScalar(1));
		scene.addConstraint(dof);
		scene.hinge(*links[2], *links[3], btVector3(btScalar(0.25), 0, 0), btVector3(btScalar(-0.25), 0, 0),
					btVector3(0, 1, 0), btVector3(0, 1, 0));
		scene.addConstraint(new btPoint2PointConstraint(*links[3], *links[4], btVector3(btScalar(0.25), 0, 0),
														btVector3(btScalar(-0.25), 0, 0)));
	}
	std::vector<btScalar> state()
	{
		std::vector<btScalar> s;
		const btCollisionObjectArray& objects = scene.world().getCollisionObjectArray();
		for (int i = 0; i < objects.size(); ++i)
		{
			const btRigidBody* b = btRigidBody::upcast(objects[i]);
			const btTransform& t = b->getCenterOfMassTransform();
			for (int r = 0; r < 3; ++r)
				for (int k = 0; k < 3; ++k) s.push_back(t.getBasis()[r][k]);
			for (int k = 0; k < 3; ++k)
			{
				s.push_back(t.getOrigin()[k]);
				s.push_back(b->getLinearVelocity()[k]);
				s.push_back(b->getAngularVelocity()[k]);
			}
		}
		return s;
	}
};

struct RejectAll : btQuaternionHingeStabilizerFilter
{
	bool needsStabilization(const btTypedConstraint&) const override { return false; }
};
struct RejectStock : btQuaternionHingeStabilizerFilter
{
	bool needsStabilization(const btTypedConstraint& c) const override
	{
		return c.getConstraintType() != HINGE_CONSTRAINT_TYPE;
	}
};
}  // namespace

TEST(StabilizerStock, WorldWhoseJointsAreFilteredOutStepsBitForBitAsWithoutTheStabilizer)
{
	// The solver's rows of these joints are untouched: only the action moves bodies. The same world stepped 2 s bare,
	// with the stabilizer filtering every joint out, and with every kind turned off in its settings: the same bits.
	MixedChain bare, filtered, off;
	btQuaternionHingeStabilizer rejecting;
	RejectAll none;
	rejecting.setFilter(&none);
	filtered.scene.addAction(&rejecting);
	btQuaternionHingeStabilizerSettings settings = hingesOnly();
	settings.projectStockHinges = settings.projectDofHinges = false;
	btQuaternionHingeStabilizer kindsOff(settings);
	off.scene.addAction(&kindsOff);
	// and the quaternion hinge of `off` filtered out (the point constraint is not seen without its option)
	struct OnlyStock : btQuaternionHingeStabilizerFilter
	{
		bool needsStabilization(const btTypedConstraint& c) const override
		{
			return c.getConstraintType() == HINGE_CONSTRAINT_TYPE;
		}
	} onlyStock;
	kindsOff.setFilter(&onlyStock);
	for (int s = 0; s < 120; ++s)
	{
		bare.scene.world().stepSimulation(kTimeStep, 0);
		filtered.scene.world().stepSimulation(kTimeStep, 0);
		off.scene.world().stepSimulation(kTimeStep, 0);
	}
	const std::vector<btScalar> a = bare.state(), b = filtered.state(), c = off.state();
	ASSERT_EQ(a.size(), b.size());
	EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(btScalar)), 0);
	EXPECT_EQ(std::memcmp(a.data(), c.data(), a.size() * sizeof(btScalar)), 0);
	EXPECT_EQ(rejecting.getLastStats().joints, 0);
	EXPECT_EQ(rejecting.getLastStats().filteredJoints, 5);  // stock, 6dof2, 6-dof and quaternion hinges, the point
	EXPECT_EQ(kindsOff.getLastStats().joints, 0);
	EXPECT_EQ(kindsOff.getLastStats().filteredJoints, 1);   // the quaternion hinge; the kinds turned off are not seen,
	EXPECT_EQ(kindsOff.getLastStats().skippedByOption, 4);  // but counted: stock, 6dof2 and 6-dof hinges, the point
	filtered.scene.world().removeAction(&rejecting);
	off.scene.world().removeAction(&kindsOff);
}

TEST(StabilizerStock, FilterAndStatsSeeEveryKind)
{
	MixedChain chain;
	btQuaternionHingeStabilizerSettings settings;
	settings.projectPointConstraints = true;
	btQuaternionHingeStabilizer stabilizer(settings);
	chain.scene.addAction(&stabilizer);
	chain.scene.world().stepSimulation(kTimeStep, 0);
	const btQuaternionHingeStabilizerStats& all = stabilizer.getLastStats();
	EXPECT_EQ(all.joints, 5);
	EXPECT_EQ(all.quaternionHinges, 1);
	EXPECT_EQ(all.stockHinges, 1);
	EXPECT_EQ(all.dofHinges, 2);
	EXPECT_EQ(all.pointConstraints, 1);
	EXPECT_EQ(all.lockedConstraints, 0);
	EXPECT_EQ(all.islands, 1);
	RejectStock rejectStock;
	stabilizer.setFilter(&rejectStock);
	chain.scene.world().stepSimulation(kTimeStep, 0);
	EXPECT_EQ(stabilizer.getLastStats().stockHinges, 0);
	EXPECT_EQ(stabilizer.getLastStats().filteredJoints, 1);
	EXPECT_EQ(stabilizer.getLastStats().joints, 4);
	stabilizer.setFilter(nullptr);
	settings.projectDofHinges = false;  // the 6-dofs set up as hinges: no longer hinges here
	stabilizer.setSettings(settings);
	chain.scene.world().stepSimulation(kTimeStep, 0);
	EXPECT_EQ(stabilizer.getLastStats().dofHinges, 0);
	// the two 6-dof hinges are then held as 6-dofs: the btGeneric6DofConstraint whole by its locked rows (its linear
	// axes and its two locked Euler angles), the btGeneric6DofSpring2Constraint, in rotation order ZYX, by its pivot as
	// a point constraint (locked angles are rows only in Bullet's XYZ order), as the ball
	EXPECT_EQ(stabilizer.getLastStats().lockedConstraints, 1);
	EXPECT_EQ(stabilizer.getLastStats().pointConstraints, 2);
	EXPECT_EQ(stabilizer.getLastStats().skippedUnexpressible, 0);
	EXPECT_EQ(stabilizer.getLastStats().stockHinges, 1);
	chain.scene.world().removeAction(&stabilizer);
}

TEST(StabilizerStock, ManualSnippet)
{
	// docs/STABILIZED_JOINTS.md's snippet, as written there, on a world of a stock hinge and a 6-dof hinge.
	MixedChain chain;
	btDiscreteDynamicsWorld* world = &chain.scene.world();
	// --- the snippet
	btQuaternionHingeStabilizer stabilizer;  // defaults: every hinge kind projected
	world->addAction(&stabilizer);           // the world's hinges, whatever their class, are held from the next step on
	world->stepSimulation(btScalar(1) / 60);
	const btQuaternionHingeStabilizerStats& stats = stabilizer.getLastStats();
	// stats.stockHinges, stats.dofHinges, stats.quaternionHinges: what it held; stats.residualAfter: how well (m, rad)
	EXPECT_EQ(stats.stockHinges, 1);
	EXPECT_EQ(stats.dofHinges, 2);
	EXPECT_LE(stats.residualAfter, kResidualTolerance);

	btQuaternionHingeStabilizerSettings settings;
	settings.projectDofHinges = false;         // only the btHingeConstraints (and quaternion hinges)
	settings.projectLockedConstraints = true;  // and welds: a URDF fixed joint is a 6-dof with every axis locked
	stabilizer.setSettings(settings);
	world->stepSimulation(btScalar(1) / 60);
	EXPECT_EQ(stabilizer.getLastStats().dofHinges, 0);
	EXPECT_EQ(stabilizer.getLastStats().stockHinges, 1);
	world->removeAction(&stabilizer);  // before the stabilizer goes
}

#ifdef QUATHINGE_HAVE_WORLD_IMPORTER
TEST(StabilizerStock, SpiderBulletIsHeldAsLoaded)
{
	// spider.bullet as a Bullet app loads it (24 btHingeConstraints with limits and motors), the stabilizer added and
	// nothing swapped, 5 s at 60 Hz, 10 iterations: every hinge within the targets; without it, parted.
	const char* dir = std::getenv("QUATHINGE_MODELS_DIR");
	const std::string file = std::string(dir && *dir ? dir : QUATHINGE_TEST_MODELS_DIR) + "/spider.bullet";
	double worst[2][3];  // without, with: separation (m), misalignment (rad), overshoot (rad)
	for (int withStabilizer = 0; withStabilizer < 2; ++withStabilizer)
	{
		World world;
		btBulletWorldImporter importer(&world.world());
		ASSERT_TRUE(importer.loadFile(file.c_str())) << file;
		btQuaternionHingeStabilizer stabilizer;
		if (withStabilizer) world.world().addAction(&stabilizer);
		std::vector<btHingeConstraint*> hinges;
		for (int i = 0; i < world.world().getNumConstraints(); ++i)
			if (world.world().getConstraint(i)->getConstraintType() == HINGE_CONSTRAINT_TYPE)
				hinges.push_back(static_cast<btHingeConstraint*>(world.world().getConstraint(i)));
		ASSERT_EQ(hinges.size(), 24u);
		for (int i = 0; i < world.world().getNumCollisionObjects(); ++i)
			world.world().getCollisionObjectArray()[i]->setActivationState(DISABLE_DEACTIVATION);
		double* w = worst[withStabilizer];
		w[0] = w[1] = w[2] = 0;
		for (int s = 0; s < 300; ++s)
		{
			world.step();
			for (btHingeConstraint* h : hinges)
			{
				const btTransform tA = h->getRigidBodyA().getCenterOfMassTransform();
				const btTransform tB = h->getRigidBodyB().getCenterOfMassTransform();
				const btTransform a = tA * h->getAFrame(), b = tB * h->getBFrame();
				w[0] = std::max(w[0], double((b.getOrigin() - a.getOrigin()).length()));
				const btVector3 za = a.getBasis().getColumn(2), zb = b.getBasis().getColumn(2);
				w[1] = std::max(w[1], double(btAtan2(za.cross(zb).length(), za.dot(zb))));
				if (h->hasLimit() && h->getLowerLimit() < h->getUpperLimit())
				{
					const double angle = double(h->getHingeAngle(tA, tB));
					w[2] = std::max(w[2], std::max(double(h->getLowerLimit()) - angle, angle - double(h->getUpperLimit())));
				}
			}
		}
		if (withStabilizer)
		{
			EXPECT_EQ(stabilizer.getLastStats().stockHinges, 24);
			world.world().removeAction(&stabilizer);
		}
		importer.deleteAllData();  // the importer's hinges, bodies and shapes, out of the world
	}
	EXPECT_GT(worst[0][0], kUnheldSeparation);
	EXPECT_LE(worst[1][0], kDouble ? kSeparationTolerance : kHeldSeparation);
	EXPECT_LE(worst[1][1], kHeldMisalignment);
	EXPECT_LE(worst[1][2], kHeldOvershoot);
	std::printf(
		"spider.bullet, 5 s: without the stabilizer %.3g m, %.3g rad, %.3g rad past a stop; with it %.3g m, "
		"%.3g rad, %.3g rad\n",
		worst[0][0], worst[0][1], worst[0][2], worst[1][0], worst[1][1], worst[1][2]);
}
#endif  // QUATHINGE_HAVE_WORLD_IMPORTER

#if defined(QUATHINGE_HAVE_SCENES) && defined(QUATHINGE_HAVE_URDF)  // the URDF robots (urdfdom is optional)
TEST(StabilizerStock, RobotsBuiltAsBulletsImporterBuildsThemAreHeld)
{
	// kuka_iiwa, panda and minitaur with every revolute joint a btGeneric6DofSpring2Constraint hinge (the demo's 6dof2
	// kind, as Bullet's URDF importer builds them for rigid bodies) and the stabilizer's defaults, 3 s: every hinge
	// within the targets, its limits kept. A URDF fixed joint is a weld (every axis locked), projected only with
	// projectLockedConstraints: with it on, those hold as well.
	using namespace quathinge::scenes;
	for (const char* name : {"kuka_iiwa", "panda", "minitaur"})
	{
		const SceneSpec scene = makeScene(name);
		ASSERT_TRUE(scene.unavailable.empty()) << scene.unavailable;
		for (int locked = 0; locked < 2; ++locked)
		{
			Simulation sim(scene, quathinge::scenes::Kind::Generic6Dof2Stabilized);
			btQuaternionHingeStabilizerSettings settings;
			settings.projectLockedConstraints = locked != 0;
			sim.stabilizer()->setSettings(settings);
			double hinge[3] = {0, 0, 0}, weld = 0;  // m, rad, rad past a stop; m
			for (int i = 0; i < 180; ++i)
			{
				sim.step(1.0 / 60, 10);
				for (size_t j = 0; j < sim.joints.size(); ++j)
				{
					MeasuredJoint& m = sim.joints[j];
					const JointError e = measureJointError(m);
					if (scene.joints[j].hasLimit && scene.joints[j].lower == scene.joints[j].upper)
					{
						weld = std::max(weld, e.separation);
						continue;
					}
					trackTheta(m);
					hinge[0] = std::max(hinge[0], e.separation);
					hinge[1] = std::max(hinge[1], e.misalignmentDeg / kRadToDeg);
					if (m.hasLimit) hinge[2] = std::max({hinge[2], m.lower - m.theta, m.theta - m.upper});
				}
			}
			std::printf("[ figures  ] %s, 6-dof hinges%s: hinges %.2e m, %.2e rad, %.2e rad past a stop; welds %.2e m\n",
						name, locked ? " and welds" : "", hinge[0], hinge[1], hinge[2], weld);
			EXPECT_LE(hinge[0], kDouble ? kSeparationTolerance : kHeldSeparation) << name;
			EXPECT_LE(hinge[1], kHeldMisalignment) << name;
			EXPECT_LE(hinge[2], kHeldOvershoot) << name;
			if (locked)
			{
				EXPECT_LE(weld, kDouble ? kSeparationTolerance : kHeldSeparation) << name;
			}
		}
	}
}
#endif  // QUATHINGE_HAVE_SCENES && QUATHINGE_HAVE_URDF

#endif  // QUATHINGE_HAVE_STABILIZER
