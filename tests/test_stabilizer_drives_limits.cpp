// btQuaternionHingeStabilizer (docs/MATH.md Q13, Q14) with the joints' drives and limits: motors and servos still
// reach their targets, violated limits end at their stops, limited and free islands converge side by side.
// One line of intent opens each test; scenes and named tolerances: support/StabilizerScene.h. Built when
// QuatHinge::Stabilizer is (QUATHINGE_HAVE_STABILIZER).
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/StabilizerScene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

using namespace qh_test;

TEST(Stabilizer, MotorStillReachesItsSpeed)
{
	// A velocity motor drives a hinged wheel to its target speed with the stabilizer on: the projection acts only
	// across the hinge axis, never along it.
	const btScalar targetSpeed = 5;  // rad/s
	StabilizerScene scene;
	btRigidBody* wheel = scene.box(btVector3(0.4, 0.1, 0.4), 2, btVector3(0, 5, 0));
	btRigidBody* arm = scene.box(btVector3(0.05, 0.4, 0.05), 1, btVector3(0, 5.5, 0));
	btQuaternionHingeConstraint* axle = scene.hinge(*arm, *wheel, btVector3(0, -0.5, 0), btVector3(0, 0, 0),
													btVector3(0, 1, 0), btVector3(0, 1, 0));
	scene.hingeToWorld(*arm, btVector3(0, 0.4, 0), btVector3(1, 0, 0));
	axle->enableAngularMotor(true, targetSpeed, 10);
	btQuaternionHingeStabilizer stabilizer;
	scene.addAction(&stabilizer);
	for (int i = 0; i < 120; ++i) scene.world().stepSimulation(kTimeStep, 0);
	const btVector3 axis = arm->getCenterOfMassTransform().getBasis() * btVector3(0, 1, 0);
	const btScalar relativeSpeed = (wheel->getAngularVelocity() - arm->getAngularVelocity()).dot(axis);
	// rad/s: 1% of the target; the motor has ample impulse and 2 s to get there.
	EXPECT_NEAR(btFabs(relativeSpeed), targetSpeed, btScalar(0.05));
	double separation, misalignment;
	scene.jointErrors(separation, misalignment);
	EXPECT_LE(separation, kSeparationTolerance);
}

TEST(Stabilizer, ServoStillReachesItsAngle)
{
	// A position servo turns a hinged bar to its target angle with the stabilizer on.
	const btScalar target = 1;  // rad
	StabilizerScene scene;
	scene.world().setGravity(btVector3(0, 0, 0));
	btRigidBody* bar = scene.box(btVector3(0.5, 0.05, 0.05), 1, btVector3(0.5, 5, 0));
	btQuaternionHingeConstraint* h = scene.hingeToWorld(*bar, btVector3(-0.5, 0, 0), btVector3(0, 0, 1));
	h->setServoTarget(target, 2, 100);
	btQuaternionHingeStabilizer stabilizer;
	scene.addAction(&stabilizer);
	for (int i = 0; i < 120; ++i) scene.world().stepSimulation(kTimeStep, 0);
	// rad: the servo reaches its target in one step once within reach; 1e-3 leaves room for the solver's iterations.
	EXPECT_NEAR(h->getMultiTurnAngle(), target, btScalar(1e-3));
	double separation, misalignment;
	scene.jointErrors(separation, misalignment);
	EXPECT_LE(separation, kSeparationTolerance);
}

TEST(Stabilizer, ViolatedLimitIsProjectedBackToItsStop)
{
	// A hinge pushed against its upper stop by gravity and an app's torque ends every step at the stop, not past it.
	// (The torque, 20 times gravity's about the pivot, makes Bullet's 10 iterations leave the joint past the stop:
	// gravity alone no longer does, since a speculative stop row no longer bounces a joint resting on it.)
	StabilizerScene scene;
	btRigidBody* bar = scene.box(btVector3(0.5, 0.05, 0.05), 5, btVector3(0.5, 5, 0));
	btQuaternionHingeConstraint* h = scene.hingeToWorld(*bar, btVector3(-0.5, 0, 0), btVector3(0, 0, 1));
	const btScalar upper = btScalar(0.3);
	h->setLimit(-upper, upper);
	btQuaternionHingeStabilizer stabilizer;
	scene.addAction(&stabilizer);
	btScalar worstExcess = 0;
	int stepsAtStop = 0;
	for (int i = 0; i < 120; ++i)
	{
		bar->applyTorque(btVector3(0, 0, -500));  // N·m, the way gravity turns the bar (−25 N·m about the pivot)
		scene.world().stepSimulation(kTimeStep, 0);
		const btScalar angle = h->getHingeAngle();
		worstExcess = std::max(worstExcess, btFabs(angle) - upper);
		if (stabilizer.getLastStats().activeLimitRows > 0) ++stepsAtStop;
	}
	EXPECT_GT(stepsAtStop, 0);                             // the limit row was projected
	EXPECT_LE(worstExcess, btScalar(kResidualTolerance));  // rad past the stop
}

// The largest speed (m/s) at which a hinge's two pivots move apart: |v_B + ω_B × r_B − v_A − ω_A × r_A|, from the bodies.
double pivotSpeedApart(const StabilizerScene& scene)
{
	double worst = 0;
	for (const btQuaternionHingeConstraint* h : scene.hinges())
	{
		const btRigidBody& a = h->getRigidBodyA();
		const btRigidBody& b = h->getRigidBodyB();
		const btVector3 pivotA = a.getCenterOfMassTransform() * h->getAFrame().getOrigin();
		const btVector3 pivotB = b.getCenterOfMassTransform() * h->getBFrame().getOrigin();
		const btVector3 va = a.getVelocityInLocalPoint(pivotA - a.getCenterOfMassPosition());
		const btVector3 vb = b.getVelocityInLocalPoint(pivotB - b.getCenterOfMassPosition());
		worst = std::max(worst, double((vb - va).length()));
	}
	return worst;
}

TEST(Stabilizer, IslandsWithAndWithoutLimitsConvergeInOneWorld)
{
	// An island with limit slots (6-row blocks) and one without (5-row blocks) are both put back on their joints, and
	// the limited one at its stops, by the same stabilizer in the same steps.
	StabilizerScene scene;
	// Heights 5 and 10 m (3 m chains: they never meet), so that float's rounding floor stays below the tolerance.
	std::vector<btRigidBody*> unlimited = scene.chain(6, 1, 5);  // no limits: 5-row blocks
	const size_t firstLimited = scene.hinges().size();
	std::vector<btRigidBody*> limited = scene.chain(6);  // every hinge limited: 6-row blocks
	const btScalar stop = btScalar(0.25);                // rad: the horizontal chain falls past it at once
	for (size_t i = firstLimited; i < scene.hinges().size(); ++i) scene.hinges()[i]->setLimit(-stop, stop);
	// Both chains assembled off their joints (4 cm, 10°): one stabilize() call removes both errors.
	for (btRigidBody* link : {unlimited[3], limited[3]})
	{
		btTransform t = link->getCenterOfMassTransform();
		t.setOrigin(t.getOrigin() + btVector3(0.02, 0.03, -0.01));
		t.setRotation(btQuaternion(btVector3(1, 0, 1).normalized(), btScalar(10 / kRadToDeg)) * t.getRotation());
		link->setCenterOfMassTransform(t);
	}
	btQuaternionHingeStabilizer stabilizer;
	const btQuaternionHingeStabilizerStats first = stabilizer.stabilize(&scene.world());
	EXPECT_EQ(first.islands, 2);
	EXPECT_EQ(first.rows, 6 * 5 + 6 * 6);  // 5 rows per free joint; 5 and a limit slot per limited joint
	EXPECT_GT(first.residualBefore, btScalar(0.02));
	EXPECT_LE(first.residualAfter, kResidualTolerance);
	EXPECT_EQ(first.numericalIssues, 0);
	double separation, misalignment;
	scene.jointErrors(separation, misalignment);
	EXPECT_LE(separation, kSeparationTolerance);
	EXPECT_LE(misalignment, kMisalignmentToleranceDeg);

	// Then both swing for 2 s with the stabilizer as an action.
	scene.addAction(&stabilizer);
	int stepsAtStop = 0;
	btScalar worstExcess = 0;
	double worstSeparation = 0, worstMisalignment = 0, worstPivotSpeed = 0;
	for (int i = 0; i < 120; ++i)
	{
		scene.world().stepSimulation(kTimeStep, 0);
		const btQuaternionHingeStabilizerStats& s = stabilizer.getLastStats();
		EXPECT_EQ(s.islands, 2);
		EXPECT_LE(s.residualAfter, kResidualTolerance);
		// the velocities too (here the velocity stage also takes limit rows out of a factorized K by solves:
		// solveDeltasWithoutDroppedRows): each pivot's two sides move together, measured from the bodies
		EXPECT_LE(s.velocityResidualAfter, kResidualTolerance / kTimeStep);
		worstPivotSpeed = std::max(worstPivotSpeed, pivotSpeedApart(scene));
		EXPECT_EQ(s.numericalIssues, 0);
		if (s.activeLimitRows > 0) ++stepsAtStop;
		for (size_t k = firstLimited; k < scene.hinges().size(); ++k)
			worstExcess = std::max(worstExcess, btFabs(scene.hinges()[k]->getMultiTurnAngle()) - stop);
		scene.jointErrors(separation, misalignment);
		worstSeparation = std::max(worstSeparation, separation);
		worstMisalignment = std::max(worstMisalignment, misalignment);
	}
	ASSERT_TRUE(scene.allFinite());
	EXPECT_GT(stepsAtStop, 0);                             // the limit rows were projected
	EXPECT_LE(worstExcess, btScalar(kResidualTolerance));  // rad past a stop
	EXPECT_LE(worstSeparation, kSeparationTolerance);
	EXPECT_LE(worstMisalignment, kMisalignmentToleranceDeg);
	EXPECT_LE(worstPivotSpeed, kResidualTolerance / kTimeStep);  // m/s
}

#endif  // QUATHINGE_HAVE_STABILIZER
