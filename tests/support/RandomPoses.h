// Seeded random orientations, vectors and numbers for the row tests that check C and J at given transforms
// (tests/test_jacobian_fd.cpp, test_stabilizer_locked.cpp, test_stabilizer_euler_locks.cpp,
// test_stabilizer_cone_limits.cpp), and two boxes for a constraint to join (the bodies' own poses are not read).
#ifndef QUATHINGE_TESTS_RANDOM_POSES_H
#define QUATHINGE_TESTS_RANDOM_POSES_H

#include <btBulletDynamicsCommon.h>

#include <random>

namespace qh_test
{
/// A rotation uniform over SO(3): a normalized quaternion of four normal deviates.
inline btQuaternion randomUnit(std::mt19937& rng)
{
	std::normal_distribution<double> n(0, 1);
	return btQuaternion(btScalar(n(rng)), btScalar(n(rng)), btScalar(n(rng)), btScalar(n(rng))).normalized();
}

struct RandomPoses
{
	std::mt19937 rng;
	std::uniform_real_distribution<double> u{-1, 1};
	btBoxShape shape{btVector3(btScalar(0.2), btScalar(0.1), btScalar(0.1))};
	btRigidBody a{1, nullptr, &shape}, b{1, nullptr, &shape};
	explicit RandomPoses(unsigned seed) : rng(seed) {}
	double number() { return u(rng); }  // uniform in [−1, 1)
	btVector3 vec(double s) { return btVector3(btScalar(s * u(rng)), btScalar(s * u(rng)), btScalar(s * u(rng))); }
	btQuaternion unit() { return randomUnit(rng); }
};
}  // namespace qh_test

#endif
