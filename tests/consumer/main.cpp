// A stock Bullet program with the class name swapped: two boxes, one hinge, two seconds at 60 Hz.
// HINGE_CLASS picks the joint; build with -DHINGE_CLASS=btHingeConstraint and it is Bullet's own, unchanged.
// Prints the hinge angle and sizeof(btScalar) (consumer_test.sh checks the precision the package handed over);
// exits 0 when the angle is finite and the joint held (pivots within 1 cm).
#include <btBulletDynamicsCommon.h>
#include <quathinge/btQuaternionHingeConstraint.h>

#include <cmath>
#include <cstdio>

#ifndef HINGE_CLASS
#define HINGE_CLASS btQuaternionHingeConstraint  // was: btHingeConstraint
#endif

int main()
{
	btDefaultCollisionConfiguration config;
	btCollisionDispatcher dispatcher(&config);
	btDbvtBroadphase broadphase;
	btSequentialImpulseConstraintSolver solver;
	btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
	world.setGravity(btVector3(0, -10, 0));

	// a: fixed upright box at the origin; b: the same box lying horizontal, its bottom end at a's top end.
	btBoxShape shape(btVector3(0.1, 0.5, 0.1));
	btVector3 inertia;
	shape.calculateLocalInertia(1, inertia);
	btRigidBody* a = new btRigidBody(0, nullptr, &shape, btVector3(0, 0, 0));
	btRigidBody* b = new btRigidBody(1, nullptr, &shape, inertia);
	b->setWorldTransform(btTransform(btQuaternion(btVector3(0, 0, 1), SIMD_HALF_PI), btVector3(-0.5, 0.5, 0)));
	world.addRigidBody(a);
	world.addRigidBody(b);

	HINGE_CLASS* hinge = new HINGE_CLASS(*a, *b, btVector3(0, 0.5, 0), btVector3(0, -0.5, 0), btVector3(0, 0, 1),
										 btVector3(0, 0, 1));
	world.addConstraint(hinge, true);
	for (int i = 0; i < 120; ++i) world.stepSimulation(btScalar(1) / 60, 0, btScalar(1) / 60);

	const btVector3 pivotA = a->getCenterOfMassTransform() * hinge->getAFrame().getOrigin();
	const btVector3 pivotB = b->getCenterOfMassTransform() * hinge->getBFrame().getOrigin();
	const double separation = (pivotB - pivotA).length();
	const double angle = hinge->getHingeAngle();
	std::printf("consumer: sizeof(btScalar)=%zu angle=%.4f rad separation=%.2e m\n", sizeof(btScalar), angle, separation);

	world.removeConstraint(hinge);
	world.removeRigidBody(b);
	world.removeRigidBody(a);
	delete hinge;
	delete b;
	delete a;
	return std::isfinite(angle) && separation < 0.01 ? 0 : 1;
}
