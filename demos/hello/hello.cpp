// Hello QuatHinge: a chain of five 1 kg links on stock btHingeConstraints carrying a 1000 kg load, released
// horizontally and run for 5 s at 60 Hz (Bullet's default 10 solver iterations), once as it is and once with a
// btQuaternionHingeStabilizer added to the world. Prints each run's largest joint separation (m): how far apart the
// two bodies' pivots of a hinge came, the largest over every hinge and step. Build: CMakeLists.txt beside this file.
#include <quathinge/btQuaternionHingeStabilizer.h>

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <vector>

namespace
{
// Where a hinge's frame on `body` is in the world.
btVector3 pivot(const btRigidBody& body, const btTransform& frame)
{
	return body.getCenterOfMassTransform() * frame.getOrigin();
}

double largestSeparation(bool stabilized)
{
	btDefaultCollisionConfiguration configuration;
	btCollisionDispatcher dispatcher(&configuration);
	btDbvtBroadphase broadphase;
	btSequentialImpulseConstraintSolver solver;
	btDiscreteDynamicsWorld world(&dispatcher, &broadphase, &solver, &configuration);
	world.setGravity(btVector3(0, btScalar(-9.81), 0));

	// five 0.5 m links along +x from a pivot at the origin, then the load (a 0.2 m cube), each hinged about z
	btBoxShape linkShape(btVector3(btScalar(0.25), btScalar(0.05), btScalar(0.05)));
	btBoxShape loadShape(btVector3(btScalar(0.1), btScalar(0.1), btScalar(0.1)));
	std::vector<std::unique_ptr<btRigidBody>> bodies;
	std::vector<std::unique_ptr<btHingeConstraint>> hinges;
	const btVector3 axis(0, 0, 1), front(btScalar(0.25), 0, 0);
	for (int i = 0; i < 6; ++i)
	{
		const bool load = i == 5;
		const btScalar mass = load ? 1000 : 1;
		btBoxShape* shape = load ? &loadShape : &linkShape;
		btVector3 inertia(0, 0, 0);
		shape->calculateLocalInertia(mass, inertia);
		btRigidBody::btRigidBodyConstructionInfo info(mass, nullptr, shape, inertia);
		info.m_startWorldTransform.setOrigin(btVector3(load ? btScalar(2.6) : btScalar(0.25 + 0.5 * i), 0, 0));
		bodies.emplace_back(new btRigidBody(info));
		world.addRigidBody(bodies.back().get(), 1, 0);  // no contacts: the joints alone
		const btVector3 back(load ? btScalar(-0.1) : btScalar(-0.25), 0, 0);
		hinges.emplace_back(i == 0 ? new btHingeConstraint(*bodies[0], back, axis)  // to the world
								   : new btHingeConstraint(*bodies[i - 1], *bodies[i], front, back, axis, axis));
		world.addConstraint(hinges.back().get(), true);
	}

	btQuaternionHingeStabilizer stabilizer;  // holds the world's stock hinges as they are: no class swapped
	if (stabilized) world.addAction(&stabilizer);
	double largest = 0;
	for (int step = 0; step < 300; ++step)
	{
		world.stepSimulation(btScalar(1) / 60, 0);  // one 60 Hz step per call
		for (const auto& h : hinges)
			largest = std::max(
				largest,
				double((pivot(h->getRigidBodyA(), h->getAFrame()) - pivot(h->getRigidBodyB(), h->getBFrame())).length()));
	}
	if (stabilized) world.removeAction(&stabilizer);
	for (const auto& h : hinges) world.removeConstraint(h.get());
	for (const auto& b : bodies) world.removeRigidBody(b.get());
	return largest;
}
}  // namespace

int main()
{
	const double stock = largestSeparation(false), stabilized = largestSeparation(true);
	std::printf("stock hinges:                  largest joint separation %.3g m\n", stock);
	std::printf("stock hinges + the stabilizer: largest joint separation %.3g m\n", stabilized);
	return stabilized < stock ? 0 : 1;
}
