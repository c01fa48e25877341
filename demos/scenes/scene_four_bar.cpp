// A four-bar linkage: crank, coupler and rocker hinged to each other and to the world — a closed loop whose planar
// hinges are redundant in 3-D (four hinges, one degree of freedom). It starts on its constraints in velocity too: the
// coupler's and rocker's rates follow from the crank's by the loop's kinematics, so no kind's first solve has to
// project an inconsistent start (which made the trajectory depend on how far that solve converged).
#include "SceneSpec.h"

namespace quathinge
{
namespace scenes
{
namespace
{
BodySpec barBetween(const btVector3& from, const btVector3& to)
{
	BodySpec b;
	const btVector3 d = to - from;
	b.halfExtents = btVector3(btScalar(0.03), d.length() / 2, btScalar(0.03));
	b.pose = btTransform(shortestArcQuat(btVector3(0, 1, 0), d.normalized()), (from + to) / 2);
	return b;
}
}  // namespace

SceneSpec fourBarScene()
{
	SceneSpec s;
	s.name = "four_bar";
	s.description = "four-bar linkage (closed loop, redundant constraints), crank spun at 3 rad/s";
	const btVector3 a(0, 0, 0), b(0, btScalar(0.5), 0), c(1, btScalar(0.8), 0), d(1, 0, 0);
	s.bodies = {barBetween(a, b), barBetween(b, c), barBetween(c, d)};
	// crank at w1 about z; the pivot c moves alike on the coupler (w2) and the rocker (w3):
	// v_b + w2 z × (c − b) = w3 z × (c − d), two equations (x, y) in w2, w3
	const btScalar w1 = -3;
	const btVector3 z(0, 0, 1), vb = (z * w1).cross(b - a), cb = c - b, cd = c - d;
	// z × r = (−r_y, r_x): w2 (−cb_y, cb_x) − w3 (−cd_y, cd_x) = −vb
	const btScalar m00 = -cb.y(), m01 = cd.y(), m10 = cb.x(), m11 = -cd.x();
	const btScalar det = m00 * m11 - m01 * m10;
	const btScalar w2 = (-vb.x() * m11 + vb.y() * m01) / det, w3 = (-vb.y() * m00 + vb.x() * m10) / det;
	auto spin = [&](BodySpec& body, const btVector3& pivot, const btVector3& pivotVelocity, btScalar w) {
		body.angularVelocity = z * w;
		body.linearVelocity = pivotVelocity + (z * w).cross(body.pose.getOrigin() - pivot);
	};
	spin(s.bodies[0], a, btVector3(0, 0, 0), w1);
	spin(s.bodies[1], b, vb, w2);
	spin(s.bodies[2], d, btVector3(0, 0, 0), w3);
	JointSpec j;
	j.axis = z;
	j.parent = -1, j.child = 0, j.pivot = a;
	s.joints.push_back(j);
	j.parent = 0, j.child = 1, j.pivot = b;
	s.joints.push_back(j);
	j.parent = 1, j.child = 2, j.pivot = c;
	s.joints.push_back(j);
	j.parent = -1, j.child = 2, j.pivot = d;
	s.joints.push_back(j);
	s.conservative = true;
	s.duration = 4;
	return s;
}

}  // namespace scenes
}  // namespace quathinge
