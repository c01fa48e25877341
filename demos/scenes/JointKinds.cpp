// Builds a scene's world for one joint kind, steps it, and measures it (JointKinds.h).
#include "JointKinds.h"
#include "Simulation.h"

#include "quathinge/btQuaternionHingeConstraint.h"
#include "quathinge/btQuaternionHingeStabilizer.h"

#include <btBulletDynamicsCommon.h>

#include "BulletDynamics/Featherstone/btMultiBody.h"
#include "BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h"
#include "BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h"
#include "BulletDynamics/Featherstone/btMultiBodyJointLimitConstraint.h"
#include "BulletDynamics/Featherstone/btMultiBodyJointMotor.h"
#include "BulletDynamics/Featherstone/btMultiBodyLinkCollider.h"
#ifdef QUATHINGE_HAVE_WORLD_IMPORTER
#include <btBulletWorldImporter.h>
#endif

#include <chrono>
#include <ctime>
#include <cmath>
#include <fstream>
#include <memory>
#include <iomanip>
#include <sstream>
#include <cstdio>
#include <stdexcept>

namespace quathinge
{
namespace scenes
{
std::vector<Kind> allKinds()
{
	return {Kind::Stock, Kind::Generic6Dof2, Kind::Quaternion, Kind::QuaternionStabilized, Kind::MultiBody};
}

std::string kindName(Kind kind)
{
	switch (kind)
	{
		case Kind::Stock: return "stock";
		case Kind::Generic6Dof2: return "6dof2";
		case Kind::Quaternion: return "quaternion";
		case Kind::QuaternionStabilized: return "quaternion+stab";
		case Kind::MultiBody: return "multibody";
		case Kind::QuaternionStabilizedEnergy: return "quaternion+stab+energy";
	}
	return "?";
}

Kind parseKind(const std::string& name)
{
	for (Kind k : allKinds())
		if (kindName(k) == name) return k;
	if (name == kindName(Kind::QuaternionStabilizedEnergy)) return Kind::QuaternionStabilizedEnergy;
	throw std::invalid_argument("parseKind: kind: unknown joint kind '" + name +
								"' (stock, 6dof2, quaternion, quaternion+stab, multibody, quaternion+stab+energy)");
}

namespace
{
// θ of a measured joint from its frames (MATH.md Q11, computed here without the plugin), continued across ±π.
void trackTheta(MeasuredJoint& j)
{
	const btMatrix3x3 rel = (j.a->getCenterOfMassTransform().getBasis() * j.frameA.getBasis())
								.transposeTimes(j.b->getCenterOfMassTransform().getBasis() * j.frameB.getBasis());
	btQuaternion q;
	rel.getRotation(q);
	if (q.w() < 0) q = -q;
	const double raw = 2 * std::atan2(double(q.z()), double(q.w()));
	if (!j.thetaValid) j.theta = raw;
	else j.theta += std::remainder(raw - j.theta, 2 * M_PI);
	j.thetaValid = true;
}

btCollisionShape* makeShape(Shape shape, const btVector3& halfExtents, const std::vector<btVector3>& points)
{
	switch (shape)
	{
		case Shape::Capsule:
		{
			const btScalar radius = halfExtents.x();
			return new btCapsuleShape(radius, btMax(btScalar(0), 2 * (halfExtents.y() - radius)));
		}
		case Shape::Sphere: return new btSphereShape(halfExtents.x());
		case Shape::Cylinder: return new btCylinderShape(halfExtents);
		case Shape::ConvexHull:
		{
			if (points.empty()) throw std::runtime_error("scene: a convex hull shape without points");
			auto* hull = new btConvexHullShape(&points[0].x(), int(points.size()), sizeof(btVector3));
			hull->optimizeConvexHull();  // the hull's vertices only (a mesh has many inside)
			return hull;
		}
		case Shape::Box: break;
	}
	return new btBoxShape(halfExtents);
}

// The compound of `parts`; its pieces go to `owned` (a compound does not own its children).
btCollisionShape* makeCompound(const std::vector<ShapePart>& parts, std::vector<std::unique_ptr<btCollisionShape>>& owned)
{
	std::unique_ptr<btCompoundShape> compound(new btCompoundShape(true, int(parts.size())));
	for (const ShapePart& part : parts)
	{
		owned.emplace_back(makeShape(part.shape, part.halfExtents, part.points));
		compound->addChildShape(part.local, owned.back().get());
	}
	return compound.release();
}

btCollisionShape* makeShape(const BodySpec& spec, std::vector<std::unique_ptr<btCollisionShape>>& owned)
{
	if (!spec.parts.empty()) return makeCompound(spec.parts, owned);
	return makeShape(spec.shape, spec.halfExtents, {});
}

btTransform jointFrame(const btVector3& pivot, const btVector3& axis)
{
	btVector3 x, y;
	btPlaneSpace1(axis, x, y);
	return btTransform(btMatrix3x3(x.x(), y.x(), axis.x(), x.y(), y.y(), axis.y(), x.z(), y.z(), axis.z()), pivot);
}

// The joint frame (world, t = 0) built into the child: the parent's, moved by childPivotOffset and turned by
// childFrameTwist (both zero for an assembled joint).
btTransform childFrame(const JointSpec& j)
{
	return jointFrame(j.pivot + j.childPivotOffset, j.axis) * btTransform(j.childFrameTwist);
}

}  // namespace

Simulation::Simulation(const SceneSpec& scene, Kind kind)
	: m_kind(kind),
	  m_factory(jointFactory(kind)),
	  m_gravity(scene.gravity),
	  m_config(new btDefaultCollisionConfiguration),
	  m_dispatcher(new btCollisionDispatcher(m_config.get())),
	  m_broadphase(new btDbvtBroadphase)
{
	if (kind == Kind::MultiBody)
	{
		if (!scene.bulletFile.empty()) throw std::runtime_error("multibody: a loaded .bullet scene has no tree description");
		if (!isTree(scene)) throw std::runtime_error("multibody: scene has a closed loop");
		auto* solver = new btMultiBodyConstraintSolver;
		m_solver.reset(solver);
		m_world.reset(new btMultiBodyDynamicsWorld(m_dispatcher.get(), m_broadphase.get(), solver, m_config.get()));
	}
	else
	{
		m_solver.reset(new btSequentialImpulseConstraintSolver);
		m_world.reset(new btDiscreteDynamicsWorld(m_dispatcher.get(), m_broadphase.get(), m_solver.get(), m_config.get()));
	}
	m_world->setGravity(scene.gravity);
	if (!scene.bulletFile.empty())
	{
		loadBulletFile(scene);
	}
	else
	{
		if (scene.ground)
		{
			m_shapes.emplace_back(new btStaticPlaneShape(btVector3(0, 1, 0), 0));
			m_ownedBodies.emplace_back(new btRigidBody(0, nullptr, m_shapes.back().get()));
			m_world->addRigidBody(m_ownedBodies.back().get());
		}
		// the world anchor: a small sphere, or the shapes fixed to the world (drawn; it takes part in no contact)
		if (scene.worldParts.empty()) m_shapes.emplace_back(new btSphereShape(btScalar(0.01)));
		else
		{
			btCollisionShape* world = makeCompound(scene.worldParts, m_shapes);
			m_shapes.emplace_back(world);
		}
		btCollisionShape* anchorShape = m_shapes.back().get();
		m_ownedBodies.emplace_back(new btRigidBody(0, nullptr, anchorShape));
		btRigidBody* anchor = m_ownedBodies.back().get();  // "the world" for joints with parent −1
		anchor->setCollisionFlags(anchor->getCollisionFlags() | btCollisionObject::CF_NO_CONTACT_RESPONSE);
		m_world->addRigidBody(anchor, 0, 0);
		for (const BodySpec& spec : scene.bodies)
		{
			btCollisionShape* shape = makeShape(spec, m_shapes);
			m_shapes.emplace_back(shape);
			btVector3 inertia = spec.localInertia;
			if (spec.mass > 0 && inertia.isZero()) m_shapes.back()->calculateLocalInertia(spec.mass, inertia);
			btRigidBody::btRigidBodyConstructionInfo info(spec.mass, nullptr, m_shapes.back().get(), inertia);
			info.m_startWorldTransform = spec.pose;
			info.m_friction = btScalar(0.8);
			m_ownedBodies.emplace_back(new btRigidBody(info));
			btRigidBody* body = m_ownedBodies.back().get();
			body->setLinearVelocity(spec.linearVelocity);
			body->setAngularVelocity(spec.angularVelocity);
			body->setActivationState(DISABLE_DEACTIVATION);
			if (kind != Kind::MultiBody)
			{
				if (spec.collides) m_world->addRigidBody(body);
				else m_world->addRigidBody(body, 0, 0);  // no contacts
			}
			bodies.push_back(body);
		}
		if (kind == Kind::MultiBody)
		{
			buildMultiBodies(scene, anchor);
			for (const JointSpec& j : scene.joints)
			{
				btRigidBody& a = j.parent < 0 ? *anchor : *bodies[size_t(j.parent)];
				btRigidBody& b = *bodies[size_t(j.child)];
				const btTransform frame = jointFrame(j.pivot, j.axis);
				MeasuredJoint measured{&a, &b, a.getCenterOfMassTransform().inverse() * frame,
									   b.getCenterOfMassTransform().inverse() * childFrame(j)};
				measured.hasLimit = j.hasLimit;
				measured.lower = j.lower;
				measured.upper = j.upper;
				trackTheta(measured);
				joints.push_back(measured);
			}
		}
		for (const JointSpec& j : scene.joints)
		{
			if (kind == Kind::MultiBody) break;
			btRigidBody& a = j.parent < 0 ? *anchor : *bodies[size_t(j.parent)];
			btRigidBody& b = *bodies[size_t(j.child)];
			const btTransform frame = jointFrame(j.pivot, j.axis);
			const btTransform fa = a.getCenterOfMassTransform().inverse() * frame;
			const btTransform fb = b.getCenterOfMassTransform().inverse() * childFrame(j);
			btTypedConstraint* c = m_factory->makeHinge(j, a, b, fa, fb, m_beforeStep);
			m_ownedJoints.emplace_back(c);
			m_world->addConstraint(c, true);
			m_compared.push_back(c);
			MeasuredJoint measured{&a, &b, fa, fb};
			measured.hasLimit = j.hasLimit;
			measured.lower = j.lower;
			measured.upper = j.upper;
			// θ at the start: the child frame's twist about z (limit scenes start away from 0)
			trackTheta(measured);
			joints.push_back(measured);
		}
	}
	if (m_factory)
	{
		m_action = m_factory->makeAction();
		if (m_action) m_world->addAction(m_action.get());
	}
}

const btQuaternionHingeStabilizer* Simulation::stabilizer() const
{
	return dynamic_cast<const btQuaternionHingeStabilizer*>(m_action.get());
}

Simulation::~Simulation()
{
	if (m_action) m_world->removeAction(m_action.get());
	if (auto* mbWorld = dynamic_cast<btMultiBodyDynamicsWorld*>(m_world.get()))
	{
		for (auto& c : m_mbConstraints) mbWorld->removeMultiBodyConstraint(c.get());
		for (auto& c : m_colliders) mbWorld->removeCollisionObject(c.get());
		for (auto& mb : m_multiBodies) mbWorld->removeMultiBody(mb.get());
	}
	for (auto& c : m_ownedJoints) m_world->removeConstraint(c.get());
	for (auto& b : m_ownedBodies) m_world->removeRigidBody(b.get());
#ifdef QUATHINGE_HAVE_WORLD_IMPORTER
	if (m_importer)
	{
		for (int i = m_world->getNumConstraints() - 1; i >= 0; --i) m_world->removeConstraint(m_world->getConstraint(i));
		m_importer->deleteAllData();
	}
#endif
}

void Simulation::ImporterDeleter::operator()(btBulletWorldImporter* importer) const
{
#ifdef QUATHINGE_HAVE_WORLD_IMPORTER
	delete importer;
#else
	(void)importer;  // never set without the importer
#endif
}

void Simulation::loadBulletFile(const SceneSpec& scene)
{
#ifdef QUATHINGE_HAVE_WORLD_IMPORTER
	m_importer.reset(new btBulletWorldImporter(m_world.get()));
	if (!m_importer->loadFile(scene.bulletFile.c_str())) throw std::runtime_error("cannot load " + scene.bulletFile);
	m_world->setGravity(scene.gravity);
	for (int i = 0; i < m_world->getNumCollisionObjects(); ++i)
	{
		btRigidBody* body = btRigidBody::upcast(m_world->getCollisionObjectArray()[i]);
		if (body && body->getInvMass() > 0)
		{
			body->setActivationState(DISABLE_DEACTIVATION);
			bodies.push_back(body);
		}
	}
	// The file's stock hinges become this kind's joints.
	btAlignedObjectArray<btHingeConstraint*> stock;
	for (int i = 0; i < m_world->getNumConstraints(); ++i)
		if (m_world->getConstraint(i)->getConstraintType() == HINGE_CONSTRAINT_TYPE)
			stock.push_back(static_cast<btHingeConstraint*>(m_world->getConstraint(i)));
	for (int i = 0; i < stock.size(); ++i)
	{
		// measured from the stock frames, the same for every kind; stock's angle with useReferenceFrameA = false is
		// −θ, so its limits map to [−high, −low] on θ
		btHingeConstraint* h = stock[i];
		const btScalar sign = h->getUseReferenceFrameA() ? 1 : -1;
		btScalar lo = h->getLowerLimit() * sign, hi = h->getUpperLimit() * sign;
		if (lo > hi) btSwap(lo, hi);
		MeasuredJoint measured{&h->getRigidBodyA(), &h->getRigidBodyB(), h->getAFrame(), h->getBFrame()};
		measured.hasLimit = h->hasLimit();
		measured.lower = lo;
		measured.upper = hi;
		trackTheta(measured);
		joints.push_back(measured);
	}
	for (btTypedConstraint* c : m_factory->replaceStockHinges(*m_world, stock, m_beforeStep))
	{
		m_ownedJoints.emplace_back(c);
		m_compared.push_back(c);
	}
	for (int i = 0; i < stock.size(); ++i)  // the stock hinges the kind kept
		for (int k = 0; k < m_world->getNumConstraints(); ++k)
			if (m_world->getConstraint(k) == stock[i]) m_compared.push_back(stock[i]);
#else
	(void)scene;
	throw std::runtime_error("built without the Bullet world importer (libbullet-extras-dev)");
#endif
}

void Simulation::step(double dt, int iterations)
{
	for (const auto& update : m_beforeStep) update(btScalar(dt));
	m_world->getSolverInfo().m_numIterations = iterations;
	m_world->stepSimulation(btScalar(dt), 0, btScalar(dt));
	if (m_kind == Kind::MultiBody) syncProxies();
}

void Simulation::buildMultiBodies(const SceneSpec& scene, btRigidBody* anchor)
{
	// One multibody per connected tree: fixed base at the world when a joint hangs from it, else the tree's root body
	// as a floating base. Links in breadth-first order, so a parent always precedes its children.
	const int n = int(scene.bodies.size());
	std::vector<int> parentJoint(size_t(n), -1);
	for (size_t k = 0; k < scene.joints.size(); ++k)
	{
		const JointSpec& j = scene.joints[k];
		const btQuaternion& tw = j.childFrameTwist;
		if (btFabs(tw.x()) > SIMD_EPSILON || btFabs(tw.y()) > SIMD_EPSILON || !j.childPivotOffset.isZero())
			throw std::runtime_error("multibody: a reduced-coordinate joint cannot start misaligned");
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
				for (const JointSpec& j : scene.joints)
					if (j.parent == parent && !placed[size_t(j.child)])
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
			const JointSpec& j = scene.joints[size_t(parentJoint[size_t(body)])];
			const btTransform parentPose = j.parent < 0 ? btTransform::getIdentity() : scene.bodies[size_t(j.parent)].pose;
			const btTransform& childPose = scene.bodies[size_t(body)].pose;
			const int parentLink = j.parent < 0 || j.parent == root ? -1 : linkOf[size_t(j.parent)];
			const btMatrix3x3 rc = childPose.getBasis(), rp = parentPose.getBasis();
			mb->setupRevolute(int(i), bodies[size_t(body)]->getInvMass() > 0 ? 1 / bodies[size_t(body)]->getInvMass() : 0,
							  bodies[size_t(body)]->getLocalInertia(), parentLink,
							  childPose.getRotation().inverse() * parentPose.getRotation(), rc.transpose() * j.axis,
							  rp.transpose() * (j.pivot - parentPose.getOrigin()), rc.transpose() * (childPose.getOrigin() - j.pivot),
							  true);
			m_proxyOf[size_t(body)] = {mb, int(i)};
		}
		mb->finalizeMultiDof();  // sizes the velocity buffers: velocities are set after it
		if (!fixedBase)
		{
			mb->setBaseVel(baseSpec->linearVelocity);
			mb->setBaseOmega(baseSpec->angularVelocity);
		}
		mb->setLinearDamping(0);
		mb->setAngularDamping(0);
		mb->setHasSelfCollision(false);
		// joint angles: θ starts at the child frame's twist about the axis (q = θ − φ); rates from the body velocities
		for (size_t i = 0; i < order.size(); ++i)
		{
			const int body = order[i];
			const JointSpec& j = scene.joints[size_t(parentJoint[size_t(body)])];
			const btVector3 wParent = j.parent < 0 ? btVector3(0, 0, 0) : scene.bodies[size_t(j.parent)].angularVelocity;
			mb->setJointVel(int(i), (scene.bodies[size_t(body)].angularVelocity - wParent).dot(j.axis));
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
	for (auto& c : m_mbConstraints)
	{
		c->finalizeMultiDof();  // allocates the constraint's Jacobians (not done by its constructor)
		mbWorld->addMultiBodyConstraint(c.get());
	}
	syncProxies();
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

int Simulation::rows()
{
	int total = m_mbRows;  // multibody: joints are coordinates, not rows; limits and motors are one row each
	for (btTypedConstraint* c : m_compared)
	{
		if (!c->isEnabled()) continue;
		if (const btQuaternionHingeConstraint* hinge = btQuaternionHingeConstraint::upcast(c))
			total += hinge->getNumRowsLastStep();
		else
		{
			btTypedConstraint::btConstraintInfo1 info;
			c->getInfo1(&info);
			total += info.m_numConstraintRows;
		}
	}
	return total;
}

double Simulation::energy() const
{
	double e = 0;
	for (const btRigidBody* b : bodies)
	{
		if (b->getInvMass() == 0) continue;  // static: no energy exchanged
		const double m = 1.0 / double(b->getInvMass());
		const btVector3 w = b->getAngularVelocity();
		const btMatrix3x3& R = b->getCenterOfMassTransform().getBasis();
		const btVector3 wl = R.transpose() * w;
		const btVector3 invI = b->getInvInertiaDiagLocal();
		double rot = 0;
		for (int k = 0; k < 3; ++k)
			if (invI[k] > 0) rot += double(wl[k]) * wl[k] / double(invI[k]);
		e += 0.5 * m * double(b->getLinearVelocity().length2()) + 0.5 * rot -
			 m * double(m_gravity.dot(b->getCenterOfMassPosition()));
	}
	return e;
}

bool Simulation::finiteAndBounded() const
{
	for (const btRigidBody* b : bodies)
	{
		const btVector3 p = b->getCenterOfMassPosition(), v = b->getLinearVelocity();
		if (!std::isfinite(double(p.length2() + v.length2()))) return false;
		if (double(p.length()) > kRunawayDistance || double(v.length()) > kRunawaySpeed) return false;
	}
	return true;
}

std::vector<btVector3> Simulation::positions() const
{
	std::vector<btVector3> p;
	for (const btRigidBody* b : bodies) p.push_back(b->getCenterOfMassPosition());
	return p;
}

namespace
{
// This thread's CPU time (s): the run time of a step even when other processes share the cores.
double threadCpuSeconds()
{
	timespec ts{};
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
	return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// The process's resident set size in kB (Linux /proc), for soak runs; −1 where unavailable.
long residentKb()
{
	std::ifstream statm("/proc/self/statm");
	long pages = -1, resident = -1;
	if (!(statm >> pages >> resident)) return -1;
	return resident * 4;  // 4 KiB pages
}

// Downward zero crossings of the pendulum bob's horizontal position, for the period.
struct PeriodMeter
{
	double lastX = 0, lastT = 0;
	std::vector<double> crossings;
	void add(double t, double x)
	{
		if (lastT > 0 && lastX > 0 && x <= 0) crossings.push_back(lastT + (t - lastT) * lastX / (lastX - x));
		lastX = x;
		lastT = t;
	}
	double period() const
	{
		if (crossings.size() < 2) return -1;
		return (crossings.back() - crossings.front()) / double(crossings.size() - 1);
	}
};
}  // namespace

Metrics runScene(const SceneSpec& scene, Kind kind, const RunSettings& settings)
{
	Metrics m;
	m.scene = scene.name;
	m.kind = kindName(kind);
	m.dt = settings.dt;
	m.iterations = settings.iterations;
	if (!scene.unavailable.empty())
	{
		m.skipped = scene.unavailable;
		return m;
	}
	const double duration = settings.duration > 0 ? settings.duration : scene.duration;
	std::unique_ptr<Simulation> sim, reference;
	try
	{
		sim.reset(new Simulation(scene, kind));
		if (settings.reference && scene.reference == Reference::FineStep) reference.reset(new Simulation(scene, kind));
	}
	catch (const std::exception& e)
	{
		m.skipped = e.what();
		return m;
	}
	const int steps = int(std::lround(duration / settings.dt));
	// the reference from the other precision's build: read whole before the run (it is a separate process)
	std::vector<std::vector<double>> external;
	bool useExternal = reference && !settings.referenceExe.empty();
	std::string externalFailure, externalPrecision = "unknown";
	if (useExternal) try
	{
		reference.reset();
		std::ostringstream cmd;
		cmd << '"' << settings.referenceExe << "\" --dump-reference -s \"" << settings.sceneArgument << "\" -k \""
			<< kindName(kind) << "\" --dt " << std::setprecision(17) << settings.dt << " --dump-steps " << steps
			<< " --seed " << settings.seed << " --models \"" << settings.modelsDir << '"';
		FILE* pipe = popen(cmd.str().c_str(), "r");
		if (!pipe) throw std::runtime_error("runScene: cannot run the reference: " + cmd.str());
		char line[1 << 16];
		while (std::fgets(line, sizeof line, pipe))
		{
			if (line[0] == '#')  // "# precision double": which Bullet the reference ran in
			{
				std::istringstream header(line + 1);
				std::string word;
				header >> word >> externalPrecision;
				continue;
			}
			std::istringstream in(line);
			std::vector<double> values;
			double v;
			while (in >> v) values.push_back(v);
			external.push_back(values);
		}
		const int status = pclose(pipe);
		if (status != 0 || int(external.size()) != steps)
			throw std::runtime_error("the reference (" + cmd.str() + ") gave " + std::to_string(external.size()) +
									 " of " + std::to_string(steps) + " steps, status " + std::to_string(status));
	}
	catch (const std::exception& e)
	{
		useExternal = false;  // said in the results instead of a trajectory error
		externalFailure = e.what();
	}
	const double e0 = sim->energy();
	// energy scale: the potential energy a body could exchange over the scene's size, plus the initial kinetic energy;
	// gravity counts as at least kEnergyScaleGravity, so a weightless scene at rest (the flipped starts) still has one
	double scale = 0;
	{
		double extent = 0;
		for (const btVector3& p : sim->positions())
			for (const btVector3& q : sim->positions()) extent = std::max(extent, double((p - q).length()));
		double pe = 0;
		for (const btRigidBody* b : sim->bodies)
		{
			if (b->getInvMass() == 0) continue;
			const double mass = 1.0 / double(b->getInvMass());
			scale += mass * std::max(double(scene.gravity.length()), kEnergyScaleGravity) * std::max(extent, 1.0);
			pe -= mass * double(scene.gravity.dot(b->getCenterOfMassPosition()));
		}
		scale += std::fabs(e0 - pe);  // the initial kinetic energy
		if (scale == 0) scale = 1;
	}
	double sumSep2 = 0, sumMis2 = 0, maxEnergy = 0, sumTraj2 = 0, maxTraj = 0;
	long samples = 0, rows = 0;
	PeriodMeter period;
	double wall = 0, cpu = 0;
	for (int i = 1; i <= steps; ++i)
	{
		const auto start = std::chrono::steady_clock::now();
		const double cpuStart = threadCpuSeconds();
		sim->step(settings.dt, settings.iterations);
		cpu += threadCpuSeconds() - cpuStart;
		wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
		rows += sim->rows();
		const double t = i * settings.dt;
		const double e = sim->energy();
		// blow-up (JointKinds.h): a non-finite, far-flung or too fast body, or a runaway — the energy grew past
		// kRunawayEnergyGain × the system's energy scale
		// (a joint that stays on its manifold while spinning ever faster, as explicit Featherstone can at a large step)
		if (std::isfinite(e)) m.maxEnergyGain = std::max(m.maxEnergyGain, (e - e0) / scale);
		if (!sim->finiteAndBounded() || !std::isfinite(e) || e - e0 > kRunawayEnergyGain * scale)
		{
			m.blewUp = true;
			m.blowUpTime = t;
			break;
		}
		double stepSep = 0, stepMis = 0;
		for (MeasuredJoint& j : sim->joints)
		{
			if (j.hasLimit)
			{
				trackTheta(j);
				const double past = std::max({j.lower - j.theta, j.theta - j.upper, 0.0});
				m.limitViolation = std::max(m.limitViolation, past);
			}
			const btVector3 pa = j.a->getCenterOfMassTransform() * j.frameA.getOrigin();
			const btVector3 pb = j.b->getCenterOfMassTransform() * j.frameB.getOrigin();
			const btVector3 za = j.a->getCenterOfMassTransform().getBasis() * j.frameA.getBasis().getColumn(2);
			const btVector3 zb = j.b->getCenterOfMassTransform().getBasis() * j.frameB.getBasis().getColumn(2);
			const double sep = double((pb - pa).length());
			// atan2(|za × zb|, za·zb): accurate near 0 (btVector3::angle's acos of a float dot product bottoms out at
			// √(2ε) = 4.9e-4 rad = 0.028°, which read as a misalignment floor)
			const double mis = std::atan2(double(za.cross(zb).length()), double(za.dot(zb))) * 180.0 / M_PI;
			sumSep2 += sep * sep;
			sumMis2 += mis * mis;
			++samples;
			stepSep = std::max(stepSep, sep);
			stepMis = std::max(stepMis, mis);
		}
		m.maxSeparation = std::max(m.maxSeparation, stepSep);
		if (stepMis < 1.0 && m.recoveryTime < 0) m.recoveryTime = t;
		if (stepMis >= 1.0) m.recoveryTime = -1;
		m.maxMisalignmentDeg = std::max(m.maxMisalignmentDeg, stepMis);
		if (scene.conservative) maxEnergy = std::max(maxEnergy, std::fabs(e - e0) / scale);
		if (scene.reference == Reference::PendulumPeriod) period.add(t, double(sim->bodies[0]->getCenterOfMassPosition().x()));
		if (reference || useExternal)
		{
			const std::vector<btVector3> a = sim->positions();
			std::vector<double> b;
			if (useExternal)
				b = external[size_t(i - 1)];
			else
			{
				for (int k = 0; k < 16; ++k) reference->step(settings.dt / 16, 100);
				for (const btVector3& p : reference->positions())
					for (int c = 0; c < 3; ++c) b.push_back(double(p[c]));
			}
			if (b.size() != 3 * a.size())
			{
				useExternal = false;
				externalFailure = "the reference has another number of bodies";
				maxTraj = -1;
				break;
			}
			double err2 = 0;
			for (size_t k = 0; k < a.size(); ++k)
				for (int c = 0; c < 3; ++c) err2 += (double(a[k][c]) - b[3 * k + size_t(c)]) * (double(a[k][c]) - b[3 * k + size_t(c)]);
			const double err = std::sqrt(err2 / double(std::max<size_t>(1, a.size())));
			sumTraj2 += err * err;
			maxTraj = std::max(maxTraj, err);
		}
		if (settings.series) m.series.push_back({t, stepSep, stepMis, e});
		if (settings.memoryEvery > 0 && i % settings.memoryEvery == 0)
		{
			m.rssLastKb = residentKb();
			if (m.rssFirstKb < 0) m.rssFirstKb = m.rssLastKb;
		}
		m.steps = i;
	}
	if (!sim->joints.empty())
	{
		trackTheta(sim->joints[0]);
		m.finalTheta = sim->joints[0].theta;
	}
	if (samples)
	{
		m.rmsSeparation = std::sqrt(sumSep2 / double(samples));
		m.rmsMisalignmentDeg = std::sqrt(sumMis2 / double(samples));
	}
	if (scene.conservative) m.energyDrift = maxEnergy;
	if (scene.reference == Reference::PendulumPeriod)
	{
		const double measured = period.period();
		m.reference = "exact period (elliptic integral)";
		m.trajectoryError = measured > 0 ? std::fabs(measured - scene.exactPeriod) / scene.exactPeriod : -1;
	}
	else if (useExternal)
	{
		m.reference = "same kind, dt/16, 100 iterations, " + externalPrecision + " precision (" + settings.referenceExe + ")";
		m.trajectoryError = maxTraj;
	}
	else if (!externalFailure.empty())
		m.reference = "failed: " + externalFailure;
	else if (reference)
	{
		m.reference = sizeof(btScalar) == 8 ? "same kind, dt/16, 100 iterations (double)"
											: "same kind, dt/16, 100 iterations (float: no --reference-exe)";
		m.trajectoryError = maxTraj;
	}
	else
		m.reference = scene.reference == Reference::None ? "none (contacts, or a start off the hinge: no fixed answer)" : "not run (--no-reference)";
	m.wallPerSimSecond = m.steps ? wall / (m.steps * settings.dt) : 0;
	m.cpuPerSimSecond = m.steps ? cpu / (m.steps * settings.dt) : 0;
	m.rowsPerStep = m.steps ? double(rows) / m.steps : 0;
	return m;
}

std::vector<std::vector<btVector3>> fineStepReference(const SceneSpec& scene, Kind kind, double dt, int steps)
{
	Simulation reference(scene, kind);
	std::vector<std::vector<btVector3>> out;
	for (int i = 0; i < steps; ++i)
	{
		for (int k = 0; k < 16; ++k) reference.step(dt / 16, 100);
		out.push_back(reference.positions());
	}
	return out;
}

}  // namespace scenes
}  // namespace quathinge
