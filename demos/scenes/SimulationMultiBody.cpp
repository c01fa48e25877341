// The multibody kinds (Kind::MultiBody, Kind::MultiBodyDamped): a scene's trees as btMultiBody revolute joints
// (Featherstone, reduced coordinates) — its sliders as prismatic joints, as pybullet's default URDF import builds
// them — its loops closed by btMultiBodyPoint2Point (as pybullet's createConstraint(JOINT_POINT2POINT) closes them),
// and the proxy rigid bodies that mirror their links for the metrics.
#include "Simulation.h"

#include <btBulletDynamicsCommon.h>

#include "BulletDynamics/Featherstone/btMultiBody.h"
#include "BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h"
#include "BulletDynamics/Featherstone/btMultiBodyJointLimitConstraint.h"
#include "BulletDynamics/Featherstone/btMultiBodyJointMotor.h"
#include "BulletDynamics/Featherstone/btMultiBodyLinkCollider.h"
#include "BulletDynamics/Featherstone/btMultiBodyPoint2Point.h"

#include <stdexcept>
#include <vector>

namespace quathinge
{
namespace scenes
{
void Simulation::buildMultiBodies(const SceneSpec& scene, btRigidBody* anchor)
{
	// One multibody per connected tree: fixed base at the world when a joint hangs from it, else the tree's root body
	// as a floating base. Links in breadth-first order, so a parent always precedes its children.
	// The tree's edges: the hinges, then the sliders as prismatic joints (a JointSpec each: parent, child, pivot, axis
	// and limits; `prismatic` tells which).
	std::vector<JointSpec> edges = scene.joints;
	std::vector<bool> prismatic(edges.size(), false);
	for (const SliderSpec& s : scene.sliders)
	{
		JointSpec j;
		j.parent = s.parent;
		j.child = s.child;
		j.pivot = s.pivot;
		j.axis = s.axis;
		j.hasLimit = s.hasLimit;
		j.lower = s.lower;
		j.upper = s.upper;
		edges.push_back(j);
		prismatic.push_back(true);
	}
	const int n = int(scene.bodies.size());
	// A joint that joins two bodies already connected (union-find over the world, −1, and the bodies) closes a loop:
	// it is no link of the tree but a btMultiBodyPoint2Point at its pivot (its axis held by the tree, as in a planar
	// linkage; a point-to-point closure frees a closing hinge's axis otherwise).
	std::vector<int> group(size_t(n + 1));
	for (int i = 0; i <= n; ++i) group[size_t(i)] = i;
	auto find = [&group](int body) {
		int g = body + 1;
		while (group[size_t(g)] != g) g = group[size_t(g)] = group[size_t(group[size_t(g)])];
		return g;
	};
	std::vector<bool> closing(edges.size(), false);
	for (size_t k = 0; k < edges.size(); ++k)
	{
		const int a = find(edges[k].parent), b = find(edges[k].child);
		if (a == b) closing[k] = true;
		else group[size_t(b)] = a;
	}
	std::vector<int> parentJoint(size_t(n), -1);
	for (size_t k = 0; k < edges.size(); ++k)
	{
		if (closing[k]) continue;
		const JointSpec& j = edges[k];
		const btQuaternion& tw = j.childFrameTwist;
		if (btFabs(tw.x()) > SIMD_EPSILON || btFabs(tw.y()) > SIMD_EPSILON || !j.childPivotOffset.isZero())
			throw std::runtime_error("multibody: a reduced-coordinate joint cannot start misaligned");
		if (parentJoint[size_t(j.child)] >= 0) throw std::runtime_error("multibody: a body has two parent joints");
		parentJoint[size_t(j.child)] = int(k);
	}
	m_proxyOf.assign(size_t(n), LinkRef{nullptr, -1});
	std::vector<bool> placed(size_t(n), false);
	auto* mbWorld = static_cast<btMultiBodyDynamicsWorld*>(m_world.get());
	(void)anchor;  // the world is the fixed base's frame (identity), as the anchor's
	// roots: the world (parent −1 joints) and bodies without a parent joint
	std::vector<int> roots{-1};
	for (int b = 0; b < n; ++b)
		if (parentJoint[size_t(b)] < 0) roots.push_back(b);
	for (int root : roots)
	{
		std::vector<int> order;  // bodies in this tree, breadth first
		std::vector<int> frontier{root};
		while (!frontier.empty())
		{
			std::vector<int> next;
			for (int parent : frontier)
				for (size_t k = 0; k < edges.size(); ++k)
					if (const JointSpec& j = edges[k]; !closing[k] && j.parent == parent && !placed[size_t(j.child)])
					{
						placed[size_t(j.child)] = true;
						order.push_back(j.child);
						next.push_back(j.child);
					}
			frontier = next;
		}
		if (root >= 0) placed[size_t(root)] = true;
		if (root < 0 && order.empty()) continue;
		const bool fixedBase = root < 0;
		const BodySpec* baseSpec = fixedBase ? nullptr : &scene.bodies[size_t(root)];
		btRigidBody* baseBody = fixedBase ? nullptr : bodies[size_t(root)];
		const btVector3 baseInertia = fixedBase ? btVector3(0, 0, 0) : baseBody->getLocalInertia();
		auto* mb = new btMultiBody(int(order.size()), fixedBase ? 0 : baseSpec->mass, baseInertia, fixedBase, false);
		m_multiBodies.emplace_back(mb);
		const btTransform basePose = fixedBase ? btTransform::getIdentity() : baseSpec->pose;
		mb->setBaseWorldTransform(basePose);
		if (!fixedBase) m_proxyOf[size_t(root)] = {mb, -1};
		std::vector<int> linkOf(size_t(n), -1);
		for (size_t i = 0; i < order.size(); ++i) linkOf[size_t(order[i])] = int(i);
		for (size_t i = 0; i < order.size(); ++i)
		{
			const int body = order[i];
			const JointSpec& j = edges[size_t(parentJoint[size_t(body)])];
			const btTransform parentPose = j.parent < 0 ? btTransform::getIdentity() : scene.bodies[size_t(j.parent)].pose;
			const btTransform& childPose = scene.bodies[size_t(body)].pose;
			const int parentLink = j.parent < 0 || j.parent == root ? -1 : linkOf[size_t(j.parent)];
			const btMatrix3x3 rc = childPose.getBasis(), rp = parentPose.getBasis();
			const btScalar mass = bodies[size_t(body)]->getInvMass() > 0 ? 1 / bodies[size_t(body)]->getInvMass() : 0;
			if (prismatic[size_t(parentJoint[size_t(body)])])
				mb->setupPrismatic(int(i), mass, bodies[size_t(body)]->getLocalInertia(), parentLink,
								   childPose.getRotation().inverse() * parentPose.getRotation(), rc.transpose() * j.axis,
								   rp.transpose() * (j.pivot - parentPose.getOrigin()),
								   rc.transpose() * (childPose.getOrigin() - j.pivot), true);
			else
				mb->setupRevolute(int(i), mass, bodies[size_t(body)]->getLocalInertia(), parentLink,
								  childPose.getRotation().inverse() * parentPose.getRotation(), rc.transpose() * j.axis,
								  rp.transpose() * (j.pivot - parentPose.getOrigin()),
								  rc.transpose() * (childPose.getOrigin() - j.pivot), true);
			m_proxyOf[size_t(body)] = {mb, int(i)};
		}
		mb->finalizeMultiDof();  // sizes the velocity buffers: velocities are set after it
		if (!fixedBase)
		{
			mb->setBaseVel(baseSpec->linearVelocity);
			mb->setBaseOmega(baseSpec->angularVelocity);
		}
		if (m_kind == Kind::MultiBody)  // MultiBodyDamped keeps the constructor's kMultiBodyDefaultDamping
		{
			mb->setLinearDamping(0);
			mb->setAngularDamping(0);
		}
		mb->setHasSelfCollision(false);
		// joint angles: θ starts at the child frame's twist about the axis (q = θ − φ); rates from the body velocities
		for (size_t i = 0; i < order.size(); ++i)
		{
			const int body = order[i];
			const JointSpec& j = edges[size_t(parentJoint[size_t(body)])];
			if (prismatic[size_t(parentJoint[size_t(body)])])
			{
				// a slider's rate: the child's velocity along the axis relative to the parent's point under its pivot
				const BodySpec* parent = j.parent < 0 ? nullptr : &scene.bodies[size_t(j.parent)];
				const btVector3 vParent = parent ? parent->linearVelocity + parent->angularVelocity.cross(
																				scene.bodies[size_t(body)].pose.getOrigin() -
																				parent->pose.getOrigin())
												 : btVector3(0, 0, 0);
				mb->setJointVel(int(i), (scene.bodies[size_t(body)].linearVelocity - vParent).dot(j.axis));
			}
			else
			{
				const btVector3 wParent = j.parent < 0 ? btVector3(0, 0, 0) : scene.bodies[size_t(j.parent)].angularVelocity;
				mb->setJointVel(int(i), (scene.bodies[size_t(body)].angularVelocity - wParent).dot(j.axis));
			}
			const btScalar phi = j.childFrameTwist.getAngle() * (j.childFrameTwist.z() >= 0 ? 1 : -1);
			if (j.hasLimit)
			{
				m_mbConstraints.emplace_back(new btMultiBodyJointLimitConstraint(mb, int(i), j.lower - phi, j.upper - phi));
				++m_mbRows;
			}
			if (j.drive == Drive::Velocity)
			{
				auto* motor = new btMultiBodyJointMotor(mb, int(i), j.target, 0);
				m_mbConstraints.emplace_back(motor);
				m_beforeStep.push_back([motor, torque = j.maxEffort](btScalar dt) { motor->setMaxAppliedImpulse(torque * dt); });
				++m_mbRows;
			}
			else if (j.drive == Drive::Servo)
			{
				auto* motor = new btMultiBodyJointMotor(mb, int(i), 0, 0);
				motor->setPositionTarget(j.target - phi, btScalar(0.2));
				motor->setVelocityTarget(0, btScalar(0.2));
				motor->setRhsClamp(j.maxSpeed);  // the velocity it asks for: at most the servo's speed
				m_mbConstraints.emplace_back(motor);
				m_beforeStep.push_back([motor, torque = j.maxEffort](btScalar dt) { motor->setMaxAppliedImpulse(torque * dt); });
				++m_mbRows;
			}
		}
		// A collider per body: Bullet assigns multibody constraints (limits, motors) to islands through them. Bodies that
		// take no part in contacts get an empty collision filter.
		for (int k = -1; k < int(order.size()); ++k)
		{
			const int body = k < 0 ? root : order[size_t(k)];
			if (body < 0) continue;
			auto* collider = new btMultiBodyLinkCollider(mb, k);
			collider->setCollisionShape(bodies[size_t(body)]->getCollisionShape());
			collider->setWorldTransform(scene.bodies[size_t(body)].pose);
			collider->setFriction(btScalar(0.8));
			m_colliders.emplace_back(collider);
			const bool collides = scene.bodies[size_t(body)].collides;
			mbWorld->addCollisionObject(collider, collides ? int(btBroadphaseProxy::DefaultFilter) : 0,
										collides ? int(btBroadphaseProxy::AllFilter) : 0);
			if (k < 0) mb->setBaseCollider(collider);
			else mb->getLink(k).m_collider = collider;
		}
		mbWorld->addMultiBody(mb);
	}
	// the loops' closing joints: a point-to-point constraint at the pivot, between the child's link and the parent's
	// link (or the world point)
	for (size_t k = 0; k < edges.size(); ++k)
	{
		if (!closing[k]) continue;
		const JointSpec& j = edges[k];
		const LinkRef child = m_proxyOf[size_t(j.child)];
		if (!child.mb) throw std::runtime_error("multibody: a loop closes on a body outside every tree");
		const btVector3 pivotInChild = scene.bodies[size_t(j.child)].pose.inverse() * j.pivot;
		if (j.parent < 0)
			m_mbConstraints.emplace_back(new btMultiBodyPoint2Point(child.mb, child.link, nullptr, pivotInChild, j.pivot));
		else
		{
			const LinkRef parent = m_proxyOf[size_t(j.parent)];
			m_mbConstraints.emplace_back(new btMultiBodyPoint2Point(child.mb, child.link, parent.mb, parent.link, pivotInChild,
																	scene.bodies[size_t(j.parent)].pose.inverse() * j.pivot));
		}
		m_mbRows += 3;
	}
	for (auto& c : m_mbConstraints)
	{
		c->finalizeMultiDof();  // allocates the constraint's Jacobians (not done by its constructor)
		mbWorld->addMultiBodyConstraint(c.get());
	}
	syncProxies();
}

void Simulation::setMaxCoordinateVelocity(double rate)
{
	for (auto& mb : m_multiBodies) mb->setMaxCoordinateVelocity(btScalar(rate));
}

void Simulation::syncProxies()
{
	btAlignedObjectArray<btQuaternion> scratchQ;
	btAlignedObjectArray<btVector3> scratchM;
	std::vector<btVector3> omega, vel;
	btMultiBody* velocitiesOf = nullptr;
	for (size_t b = 0; b < m_proxyOf.size(); ++b)
	{
		const LinkRef& ref = m_proxyOf[b];
		if (!ref.mb) continue;
		if (velocitiesOf != ref.mb)
		{
			ref.mb->forwardKinematics(scratchQ, scratchM);
			omega.assign(size_t(ref.mb->getNumLinks() + 1), btVector3(0, 0, 0));
			vel.assign(size_t(ref.mb->getNumLinks() + 1), btVector3(0, 0, 0));
			ref.mb->compTreeLinkVelocities(omega.data(), vel.data());
			velocitiesOf = ref.mb;
		}
		const btTransform pose =
			ref.link < 0 ? ref.mb->getBaseWorldTransform() : ref.mb->getLink(ref.link).m_cachedWorldTransform;
		bodies[b]->setCenterOfMassTransform(pose);
		bodies[b]->setAngularVelocity(pose.getBasis() * omega[size_t(ref.link + 1)]);
		bodies[b]->setLinearVelocity(pose.getBasis() * vel[size_t(ref.link + 1)]);
	}
}

}  // namespace scenes
}  // namespace quathinge
