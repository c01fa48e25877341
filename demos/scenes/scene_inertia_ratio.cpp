// Gazebo classic's inertia-ratio pendulum, and a family of it by mass ratio.
//
// Source: repository gazebosim/gazebo-classic (formerly osrf/gazebo), files test/worlds/inertia_ratio_pendulum.world
// (the world) and test/integration/physics_inertia_ratio.cc (the test: 3000 steps of 1 ms, each link's world
// orientation as ZYX Euler angles, the largest |pitch| and |yaw| — the out-of-plane angles — at most 0.21 rad).
// Values taken from the world file:
//   step 1 ms; gravity (0.1, 0, −9.81) m/s²: a lateral 0.1 m/s² along the hinge axes; ERP 0.2 (Bullet's default
//   solverInfo.m_erp, which the scene library leaves as it is), CFM 0; 250 iterations for its Bullet and ODE solvers;
//   SOR 1.4 for both — Bullet's sequential-impulse solver has no over-relaxation factor, so it is not reproduced.
//   model pose (0, 0, 0.9), roll π/4;
//   upper_link: pose in the model (0, 0, −0.05); 0.027 kg; inertia (2.2725e-5, 2.2725e-5, 4.5e-7) kg·m² about its
//     centre; a 0.01 × 0.01 × 0.1 m box along its z;
//   upper_joint: world → upper_link, at (0, 0, 0.05) in upper_link's frame, axis x;
//   lower_link: pose in the model (0, 0.17677669529663687, −0.2767766952966369), roll π/4 (so roll π/2 in world);
//     3.375 kg; inertia (0.071015625, 0.071015625, 0.00140625) kg·m²; a 0.05 × 0.05 × 0.5 m box along its z;
//   lower_joint: upper_link → lower_link, at (0, 0, 0.25) in lower_link's frame, axis x.
// Both links are uniform boxes of 2700 kg/m³, so the light:heavy mass ratio is 1:125 and the inertia ratio about the
// axis 1:3125. In world the upper link hangs 45° from the anchor at (0, 0, 0.9) and the lower link leaves its end
// horizontally along +y. Inertias are given (a btBoxShape's own inertia adds its 0.04 m collision margin, which would
// make the 1 cm link 60× stiffer to turn).
//
// The family (inertia_ratio_<N>): the same geometry with the upper link's mass (and inertia, same shape) set to
// 3.375/N kg, a light:heavy mass ratio of 1:N (N = 10 … 1000; Gazebo's world is N = 125).
#include "SceneSpec.h"

#include <cmath>
#include <string>

namespace quathinge
{
namespace scenes
{
SceneSpec inertiaRatioScene(double massRatio)
{
	SceneSpec s;
	const bool gazebo = massRatio <= 0;
	const double heavyMass = 3.375;
	const double lightMass = gazebo ? 0.027 : heavyMass / massRatio;
	s.name = gazebo ? "inertia_ratio" : "inertia_ratio_" + std::to_string(int(std::lround(massRatio)));
	s.description = gazebo ? "Gazebo classic's inertia_ratio_pendulum.world: 0.027 kg thin link on a fixed anchor, "
							 "3.375 kg link below it, lateral gravity 0.1 m/s² along the axes, 1 ms step"
						   : "Gazebo's inertia-ratio pendulum with a light:heavy mass ratio of 1:" +
								 std::to_string(int(std::lround(massRatio)));
	const btVector3 modelOrigin(0, 0, btScalar(0.9));
	const btQuaternion modelRoll(btVector3(1, 0, 0), btScalar(M_PI / 4));
	const btTransform model(modelRoll, modelOrigin);

	BodySpec upper;
	upper.mass = btScalar(lightMass);
	const double lightScale = lightMass / 0.027;  // the same box: inertia ∝ mass
	upper.localInertia = btVector3(btScalar(2.2725e-5 * lightScale), btScalar(2.2725e-5 * lightScale),
								   btScalar(4.5e-7 * lightScale));
	upper.halfExtents = btVector3(btScalar(0.005), btScalar(0.005), btScalar(0.05));
	upper.pose = model * btTransform(btQuaternion::getIdentity(), btVector3(0, 0, btScalar(-0.05)));

	BodySpec lower;
	lower.mass = btScalar(heavyMass);
	lower.localInertia = btVector3(btScalar(0.071015625), btScalar(0.071015625), btScalar(0.00140625));
	lower.halfExtents = btVector3(btScalar(0.025), btScalar(0.025), btScalar(0.25));
	lower.pose = model * btTransform(modelRoll, btVector3(0, btScalar(0.17677669529663687), btScalar(-0.2767766952966369)));
	s.bodies = {upper, lower};

	// Joint poses are in the child link's frame; the axis x is the same in every frame here (the rolls are about x).
	JointSpec top;
	top.parent = -1;
	top.child = 0;
	top.pivot = upper.pose * btVector3(0, 0, btScalar(0.05));
	top.axis = btVector3(1, 0, 0);
	JointSpec elbow;
	elbow.parent = 0;
	elbow.child = 1;
	elbow.pivot = lower.pose * btVector3(0, 0, btScalar(0.25));
	elbow.axis = btVector3(1, 0, 0);
	s.joints = {top, elbow};

	s.gravity = btVector3(btScalar(0.1), 0, btScalar(-9.81));
	s.duration = 3;
	s.dt = 0.001;
	s.outOfPlaneBound = 0.21;
	s.conservative = true;
	return s;
}

}  // namespace scenes
}  // namespace quathinge
