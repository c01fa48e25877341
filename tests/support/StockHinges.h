// The hinge kinds the stabilizer holds without a class swapped (tests/test_stabilizer_stock*.cpp): every kind built
// from the same frames and limits, the poses the tests put them in, and the targets they are held to.
#ifndef QUATHINGE_TESTS_STOCK_HINGES_H
#define QUATHINGE_TESTS_STOCK_HINGES_H

#include "support/World.h"

#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace qh_test
{
const double kPi = 3.14159265358979323846;
// The brief's targets for every hinge (float, 60 Hz, 10 iterations, defaults): pivots within 1e-5 m, axes within
// 1e-3 rad, stops within 1e-3 rad; double Bullet reaches kSeparationTolerance (StabilizerScene.h) as well.
const double kHeldSeparation = 1e-5;    // m
const double kHeldMisalignment = 1e-3;  // rad
const double kHeldOvershoot = 1e-3;     // rad past a stop
// The solver alone (no stabilizer) parts these chains by more than a millimetre: what the stabilizer is for.
const double kUnheldSeparation = 1e-3;  // m

inline btQuaternion randomUnit(std::mt19937& rng)
{
	std::normal_distribution<double> n(0, 1);
	return btQuaternion(btScalar(n(rng)), btScalar(n(rng)), btScalar(n(rng)), btScalar(n(rng))).normalized();
}

// A basis whose column `axis` is w (unit), the next column u ⟂ w, the last w × u: right-handed.
inline btMatrix3x3 basisWithAxis(int axis, const btVector3& w)
{
	const btVector3 u = w.cross(std::fabs(double(w.x())) < 0.9 ? btVector3(1, 0, 0) : btVector3(0, 1, 0)).normalized();
	const btVector3 cols[3] = {w, u, w.cross(u)};
	btMatrix3x3 m;
	for (int k = 0; k < 3; ++k)
		for (int r = 0; r < 3; ++r) m[r][(axis + k) % 3] = cols[k][r];
	return m;
}

// Locks a 6-dof's linear axes and every angle but `axis`, limited to [lo, hi] (lo > hi: free).
template <class Dof>
inline Dof* asHinge(Dof* d, int axis, btScalar lo, btScalar hi)
{
	d->setLinearLowerLimit(btVector3(0, 0, 0));
	d->setLinearUpperLimit(btVector3(0, 0, 0));
	btVector3 low(0, 0, 0), high(0, 0, 0);
	low[axis] = lo;
	high[axis] = hi;
	d->setAngularLowerLimit(low);
	d->setAngularUpperLimit(high);
	return d;
}

// A 6-dof hinge, free axis `axis`, limited to [lo, hi] (lo > hi: free): Bullet's URDF importer's revolute joint.
inline btGeneric6DofSpring2Constraint* dofHinge(btRigidBody& a, btRigidBody& b, const btTransform& fa, const btTransform& fb,
												int axis, RotateOrder order, btScalar lo, btScalar hi)
{
	return asHinge(new btGeneric6DofSpring2Constraint(a, b, fa, fb, order), axis, lo, hi);
}

inline btGeneric6DofConstraint* oldDofHinge(btRigidBody& a, btRigidBody& b, const btTransform& fa, const btTransform& fb,
											int axis, btScalar lo, btScalar hi)
{
	return asHinge(new btGeneric6DofConstraint(a, b, fa, fb, true), axis, lo, hi);
}

// Body transforms putting joint frame B turned by theta about joint frame A's column `axis`, B's pivot `offset` off
// A's (world), A anywhere.
inline void placeFrames(std::mt19937& rng, const btTransform& fa, const btTransform& fb, int axis, double theta,
						const btVector3& offset, const btQuaternion& swing, btTransform& tA, btTransform& tB)
{
	tA = btTransform(randomUnit(rng), btVector3(1, 2, 3));
	const btTransform frameA = tA * fa;
	const btVector3 w = frameA.getBasis().getColumn(axis);
	const btQuaternion turn(w, btScalar(theta));
	const btTransform frameB(swing * turn * frameA.getRotation(), frameA.getOrigin() + offset);
	tB = frameB * fb.inverse();
}

struct Kind
{
	std::string name;
	std::function<btTypedConstraint*(btRigidBody&, btRigidBody&, const btTransform&, const btTransform&, btScalar,
									 btScalar)>
		make;  // (a, b, fa, fb, lo, hi)
	int axis;  // the free axis of the frames (2 for a stock hinge)
};

// Every hinge kind: stock, 6dof2 in each rotation order about each axis, the old 6-dof about each axis.
inline std::vector<Kind> kinds()
{
	std::vector<Kind> k;
	k.push_back({"stock", [](btRigidBody& a, btRigidBody& b, const btTransform& fa, const btTransform& fb, btScalar lo, btScalar hi) {
					 auto* h = new btHingeConstraint(a, b, fa, fb, false);
					 h->setLimit(lo, hi);
					 return static_cast<btTypedConstraint*>(h);
				 },
				 2});
	for (int order = RO_XYZ; order <= RO_ZYX; ++order)
		for (int axis = 0; axis < 3; ++axis)
			k.push_back({"6dof2 order " + std::to_string(order) + " axis " + std::to_string(axis),
						 [order, axis](btRigidBody& a, btRigidBody& b, const btTransform& fa, const btTransform& fb,
									   btScalar lo, btScalar hi) {
							 return static_cast<btTypedConstraint*>(dofHinge(a, b, fa, fb, axis, RotateOrder(order), lo, hi));
						 },
						 axis});
	for (int axis = 0; axis < 3; ++axis)
		k.push_back({"6dof axis " + std::to_string(axis),
					 [axis](btRigidBody& a, btRigidBody& b, const btTransform& fa, const btTransform& fb, btScalar lo,
							btScalar hi) { return static_cast<btTypedConstraint*>(oldDofHinge(a, b, fa, fb, axis, lo, hi)); },
					 axis});
	return k;
}

// The middle axis of a 6-dof's rotation order: its Euler angle is an asin, within ±90°.
inline bool middleAxis(const Kind& k)
{
	if (k.name == "stock") return false;
	static const int middle[6] = {1, 2, 0, 2, 0, 1};  // XYZ, XZY, YXZ, YZX, ZXY, ZYX
	if (k.name.rfind("6dof2", 0) == 0) return middle[k.name[12] - '0'] == k.axis;
	return k.axis == 1;  // btGeneric6DofConstraint: XYZ
}
}  // namespace qh_test

#endif
