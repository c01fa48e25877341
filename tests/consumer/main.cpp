// A stock btHingeConstraint scene with the class name swapped: two boxes, one hinge, two seconds at 60 Hz.
// Exits 0 when the joint held (pivots within 1 cm) and the angle is finite.
#include <btBulletDynamicsCommon.h>
#include <quathinge/btQuaternionHingeConstraint.h>

#include <cmath>
#include <cstdio>

int main()
{
	btDefaultCollisionConfiguration config;
	btCollisionDispatcher dispatcher(&config);
	btDbvtBroadphase broadphase;
	btSequentialImpulseConstraintSolver solver;
	btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
	world.setGravity(btVector3(0, -10, 0));

	btBoxShape shape(btVector3(0.1, 0.5, 0.1));
	btVector3 inertia;
	shape.calculateLocalInertia(1, inertia);
	btRigidBody a(0, nullptr, &shape, btVector3(0, 0, 0));  // fixed
	btRigidBody b(1, nullptr, &shape, inertia);
	b.setWorldTransform(btTransform(btQuaternion(btVector3(0, 0, 1), SIMD_HALF_PI), btVector3(0.5, -0.5, 0)));
	world.addRigidBody(&a);
	world.addRigidBody(&b);

	// was: btHingeConstraint hinge(a, b, ...);
	btQuaternionHingeConstraint hinge(a, b, btVector3(0, -0.5, 0), btVector3(0, 0.5, 0), btVector3(0, 0, 1),
									  btVector3(0, 0, 1));
	world.addConstraint(&hinge, true);
	for (int i = 0; i < 120; ++i) world.stepSimulation(btScalar(1) / 60, 0, btScalar(1) / 60);

	const btVector3 pivotA = a.getCenterOfMassTransform() * hinge.getAFrame().getOrigin();
	const btVector3 pivotB = b.getCenterOfMassTransform() * hinge.getBFrame().getOrigin();
	const double separation = (pivotB - pivotA).length();
	const double angle = hinge.getHingeAngle();
	std::printf("consumer: sizeof(btScalar)=%zu angle=%.4f rad separation=%.2e m\n", sizeof(btScalar), angle, separation);
	world.removeConstraint(&hinge);
	return std::isfinite(angle) && separation < 0.01 ? 0 : 1;
}
