// A scene's Bullet world for one joint kind (Simulation.h): its bodies, the kind's joints or a loaded .bullet file,
// one step, and what the metrics read (rows, energy, positions). The multibody kind's trees: SimulationMultiBody.cpp.
#include "JointKinds.h"
#include "Simulation.h"

#include "quathinge/btQuaternionHingeConstraint.h"
#include "quathinge/btQuaternionHingeStabilizer.h"

#include <btBulletDynamicsCommon.h>

#include "BulletDynamics/Featherstone/btMultiBody.h"
#include "BulletDynamics/Featherstone/btMultiBodyConstraint.h"
#include "BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h"
#include "BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h"
#include "BulletDynamics/Featherstone/btMultiBodyLinkCollider.h"
#include "BulletDynamics/ConstraintSolver/btNNCGConstraintSolver.h"
#include "BulletDynamics/MLCPSolvers/btDantzigSolver.h"
#include "BulletDynamics/MLCPSolvers/btMLCPSolver.h"
#ifdef QUATHINGE_HAVE_WORLD_IMPORTER
#include <btBulletWorldImporter.h>
#endif

#include <cmath>
#include <memory>
#include <stdexcept>

namespace quathinge
{
namespace scenes
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

namespace
{
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

// A prismatic joint as pybullet's maximal-coordinate URDF import builds one, the same in every maximal-coordinate
// kind: btGeneric6DofSpring2Constraint whose frames' x axis is the slide, x free or limited to [lower, upper], the
// other two linear and the three angular axes locked. The multibody kind builds it as a prismatic link
// (SimulationMultiBody.cpp): here it is only measured.
void Simulation::addSlider(const SliderSpec& s, btRigidBody& a, btRigidBody& b)
{
	btVector3 y, z;
	btPlaneSpace1(s.axis, y, z);
	const btTransform frame(btMatrix3x3(s.axis.x(), y.x(), z.x(), s.axis.y(), y.y(), z.y(), s.axis.z(), y.z(), z.z()),
							s.pivot);
	const btTransform fa = a.getCenterOfMassTransform().inverse() * frame;
	const btTransform fb = b.getCenterOfMassTransform().inverse() * frame;
	sliders.push_back(MeasuredJoint{&a, &b, fa, fb, s.hasLimit, double(s.lower), double(s.upper)});
	if (m_multiBody) return;
	auto* d = new btGeneric6DofSpring2Constraint(a, b, fa, fb, RO_XYZ);
	d->setLinearLowerLimit(btVector3(s.hasLimit ? s.lower : btScalar(1), 0, 0));  // x free: lower > upper
	d->setLinearUpperLimit(btVector3(s.hasLimit ? s.upper : btScalar(-1), 0, 0));
	d->setAngularLowerLimit(btVector3(0, 0, 0));
	d->setAngularUpperLimit(btVector3(0, 0, 0));
	m_ownedJoints.emplace_back(d);
	m_world->addConstraint(d, true);
}

Simulation::Simulation(const SceneSpec& scene, Kind kind)
	: m_kind(kind),
	  m_multiBody(solverOf(kind) == SolverChoice::MultiBody),
	  m_factory(jointFactory(kind)),
	  m_gravity(scene.gravity),
	  m_config(new btDefaultCollisionConfiguration),
	  m_dispatcher(new btCollisionDispatcher(m_config.get())),
	  m_broadphase(new btDbvtBroadphase)
{
	if (m_multiBody)
	{
		if (!scene.bulletFile.empty()) throw std::runtime_error("multibody: a loaded .bullet scene has no tree description");
		auto* solver = new btMultiBodyConstraintSolver;
		m_solver.reset(solver);
		m_world.reset(new btMultiBodyDynamicsWorld(m_dispatcher.get(), m_broadphase.get(), solver, m_config.get()));
	}
	else if (solverOf(kind) == SolverChoice::MLCPDantzig)
	{
		// Dantzig's pivoting is O(n³) in a group's rows n: refused past kMlcpMaxRows (said in the skipped column)
		const size_t rows = 5 * scene.joints.size() + 6 * scene.sliders.size();
		if (!scene.bulletFile.empty() || rows > size_t(kMlcpMaxRows))
			throw std::runtime_error("mlcp: " + (scene.bulletFile.empty() ? std::to_string(rows) : std::string("a loaded file's")) +
									 " rows: past the Dantzig cap of " + std::to_string(kMlcpMaxRows) + " rows (O(n^3))");
		m_dantzig.reset(new btDantzigSolver);
		m_solver.reset(new btMLCPSolver(m_dantzig.get()));
		m_world.reset(new btDiscreteDynamicsWorld(m_dispatcher.get(), m_broadphase.get(), m_solver.get(), m_config.get()));
	}
	else
	{
		if (solverOf(kind) == SolverChoice::NNCG) m_solver.reset(new btNNCGConstraintSolver);
		else m_solver.reset(new btSequentialImpulseConstraintSolver);
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
			if (!scene.allowSleep) body->setActivationState(DISABLE_DEACTIVATION);
			if (!m_multiBody)
			{
				if (spec.collides) m_world->addRigidBody(body);
				else m_world->addRigidBody(body, 0, 0);  // no contacts
			}
			bodies.push_back(body);
		}
		if (m_multiBody)
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
			if (m_multiBody) break;
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
		for (const SliderSpec& s : scene.sliders)
			addSlider(s, s.parent < 0 ? *anchor : *bodies[size_t(s.parent)], *bodies[size_t(s.child)]);
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

btQuaternionHingeStabilizer* Simulation::stabilizer()
{
	return dynamic_cast<btQuaternionHingeStabilizer*>(m_action.get());
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
	if (m_multiBody) syncProxies();
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

int Simulation::mlcpFallbacks() const
{
	const auto* mlcp = dynamic_cast<const btMLCPSolver*>(m_solver.get());
	return mlcp ? mlcp->getNumFallbacks() : -1;
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

}  // namespace scenes
}  // namespace quathinge
