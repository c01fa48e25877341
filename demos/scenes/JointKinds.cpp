// Builds a scene's world for one joint kind, steps it, and measures it (JointKinds.h).
#include "JointKinds.h"

#include "quathinge/btQuaternionHingeConstraint.h"
#include "quathinge/btQuaternionHingeStabilizer.h"

#include <btBulletDynamicsCommon.h>
#ifdef QUATHINGE_HAVE_WORLD_IMPORTER
#include <btBulletWorldImporter.h>
#endif

#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>

namespace quathinge
{
namespace scenes
{
std::vector<Kind> allKinds() { return {Kind::Stock, Kind::Generic6Dof2, Kind::Quaternion, Kind::QuaternionStabilized}; }

std::string kindName(Kind kind)
{
	switch (kind)
	{
		case Kind::Stock: return "stock";
		case Kind::Generic6Dof2: return "6dof2";
		case Kind::Quaternion: return "quaternion";
		case Kind::QuaternionStabilized: return "quaternion+stab";
	}
	return "?";
}

Kind parseKind(const std::string& name)
{
	for (Kind k : allKinds())
		if (kindName(k) == name) return k;
	throw std::invalid_argument("parseKind: kind: unknown joint kind '" + name +
								"' (stock, 6dof2, quaternion, quaternion+stab)");
}

namespace
{
// One measured joint: the two bodies and the joint frames in them (the same for every kind).
struct MeasuredJoint
{
	btRigidBody* a;
	btRigidBody* b;
	btTransform frameA, frameB;
	bool hasLimit = false;
	double lower = 0, upper = 0;  // θ, rad
	double theta = 0;             // continuous θ measured from the frames (independent of the kind's own angle)
	bool thetaValid = false;
};

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

btTransform jointFrame(const btVector3& pivot, const btVector3& axis)
{
	btVector3 x, y;
	btPlaneSpace1(axis, x, y);
	return btTransform(btMatrix3x3(x.x(), y.x(), axis.x(), x.y(), y.y(), axis.y(), x.z(), y.z(), axis.z()), pivot);
}

// A world with one kind of joint in it.
class Simulation
{
public:
	Simulation(const SceneSpec& scene, Kind kind);
	~Simulation();
	void step(double dt, int iterations);
	int rows();
	double energy() const;
	bool finiteAndBounded() const;
	std::vector<btVector3> positions() const;
	std::vector<MeasuredJoint> joints;
	std::vector<btRigidBody*> bodies;  // the scene's dynamic bodies, in scene order

private:
	btTypedConstraint* makeJoint(const JointSpec& j, btRigidBody& a, btRigidBody& b, const btTransform& fa,
								 const btTransform& fb);
	void loadBulletFile(const SceneSpec& scene);
	Kind m_kind;
	btVector3 m_gravity;
	std::unique_ptr<btDefaultCollisionConfiguration> m_config;
	std::unique_ptr<btCollisionDispatcher> m_dispatcher;
	std::unique_ptr<btDbvtBroadphase> m_broadphase;
	std::unique_ptr<btSequentialImpulseConstraintSolver> m_solver;
	std::unique_ptr<btDiscreteDynamicsWorld> m_world;
	std::vector<std::unique_ptr<btCollisionShape>> m_shapes;
	std::vector<std::unique_ptr<btRigidBody>> m_ownedBodies;
	std::vector<std::unique_ptr<btTypedConstraint>> m_ownedJoints;
	std::vector<btTypedConstraint*> m_compared;  // the joints being compared (rows counted)
	std::unique_ptr<btQuaternionHingeStabilizer> m_stabilizer;
	struct StockServo
	{
		btHingeConstraint* joint;
		btScalar target, maxSpeed, maxTorque;
	};
	std::vector<StockServo> m_stockServos;
#ifdef QUATHINGE_HAVE_WORLD_IMPORTER
	std::unique_ptr<btBulletWorldImporter> m_importer;
#endif
};

Simulation::Simulation(const SceneSpec& scene, Kind kind)
	: m_kind(kind),
	  m_gravity(scene.gravity),
	  m_config(new btDefaultCollisionConfiguration),
	  m_dispatcher(new btCollisionDispatcher(m_config.get())),
	  m_broadphase(new btDbvtBroadphase),
	  m_solver(new btSequentialImpulseConstraintSolver)
{
	m_world.reset(new btDiscreteDynamicsWorld(m_dispatcher.get(), m_broadphase.get(), m_solver.get(), m_config.get()));
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
		m_shapes.emplace_back(new btSphereShape(btScalar(0.01)));
		btCollisionShape* anchorShape = m_shapes.back().get();
		m_ownedBodies.emplace_back(new btRigidBody(0, nullptr, anchorShape));
		btRigidBody* anchor = m_ownedBodies.back().get();  // "the world" for joints with parent −1
		anchor->setCollisionFlags(anchor->getCollisionFlags() | btCollisionObject::CF_NO_CONTACT_RESPONSE);
		m_world->addRigidBody(anchor, 0, 0);
		for (const BodySpec& spec : scene.bodies)
		{
			m_shapes.emplace_back(new btBoxShape(spec.halfExtents));
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
			if (spec.collides) m_world->addRigidBody(body);
			else m_world->addRigidBody(body, 0, 0);  // no contacts
			bodies.push_back(body);
		}
		for (const JointSpec& j : scene.joints)
		{
			btRigidBody& a = j.parent < 0 ? *anchor : *bodies[size_t(j.parent)];
			btRigidBody& b = *bodies[size_t(j.child)];
			const btTransform frame = jointFrame(j.pivot, j.axis);
			const btTransform fa = a.getCenterOfMassTransform().inverse() * frame;
			const btTransform fb = b.getCenterOfMassTransform().inverse() * frame * btTransform(j.childFrameTwist);
			btTypedConstraint* c = makeJoint(j, a, b, fa, fb);
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
	if (kind == Kind::QuaternionStabilized)
	{
		m_stabilizer.reset(new btQuaternionHingeStabilizer);
		m_world->addAction(m_stabilizer.get());
	}
}

Simulation::~Simulation()
{
	if (m_stabilizer) m_world->removeAction(m_stabilizer.get());
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

btTypedConstraint* Simulation::makeJoint(const JointSpec& j, btRigidBody& a, btRigidBody& b, const btTransform& fa,
										 const btTransform& fb)
{
	switch (m_kind)
	{
		case Kind::Stock:
		{
			// useReferenceFrameA: getHingeAngle() = θ, the spec's angle
			auto* h = new btHingeConstraint(a, b, fa, fb, true);
			if (j.hasLimit) h->setLimit(j.lower, j.upper);
			if (j.drive == Drive::Velocity) h->enableAngularMotor(true, j.target, j.maxEffort);
			if (j.drive == Drive::Servo)
			{
				h->enableMotor(true);
				m_stockServos.push_back({h, j.target, j.maxSpeed, j.maxEffort});
			}
			return h;
		}
		case Kind::Generic6Dof2:
		{
			auto* d = new btGeneric6DofSpring2Constraint(a, b, fa, fb, RO_XYZ);
			d->setLinearLowerLimit(btVector3(0, 0, 0));
			d->setLinearUpperLimit(btVector3(0, 0, 0));
			if (j.hasLimit)
			{
				d->setAngularLowerLimit(btVector3(0, 0, j.lower));
				d->setAngularUpperLimit(btVector3(0, 0, j.upper));
			}
			else
			{
				d->setAngularLowerLimit(btVector3(0, 0, 1));  // z free (lower > upper)
				d->setAngularUpperLimit(btVector3(0, 0, -1));
			}
			if (j.drive != Drive::None)
			{
				d->enableMotor(5, true);
				if (j.drive == Drive::Velocity)
				{
					d->setTargetVelocity(5, j.target);
					d->setMaxMotorForce(5, j.maxEffort * 60);  // an impulse per 1/60 s step as a torque
				}
				else
				{
					d->setServo(5, true);
					d->setServoTarget(5, j.target);
					d->setTargetVelocity(5, j.maxSpeed);
					d->setMaxMotorForce(5, j.maxEffort);
				}
			}
			return d;
		}
		case Kind::Quaternion:
		case Kind::QuaternionStabilized:
		{
			auto* q = new btQuaternionHingeConstraint(a, b, fa, fb, true);
			if (j.hasLimit) q->setLimit(j.lower, j.upper);
			if (j.drive == Drive::Velocity) q->enableAngularMotor(true, j.target, j.maxEffort);
			if (j.drive == Drive::Servo) q->setServoTarget(j.target, j.maxSpeed, j.maxEffort);
			return q;
		}
	}
	return nullptr;
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
		btHingeConstraint* h = stock[i];
		joints.push_back({&h->getRigidBodyA(), &h->getRigidBodyB(), h->getAFrame(), h->getBFrame()});
		btTypedConstraint* replacement = nullptr;
		if (m_kind == Kind::Quaternion || m_kind == Kind::QuaternionStabilized)
			replacement = new btQuaternionHingeConstraint(*h);
		else if (m_kind == Kind::Generic6Dof2)
		{
			auto* d = new btGeneric6DofSpring2Constraint(h->getRigidBodyA(), h->getRigidBodyB(), h->getAFrame(), h->getBFrame(), RO_XYZ);
			d->setLinearLowerLimit(btVector3(0, 0, 0));
			d->setLinearUpperLimit(btVector3(0, 0, 0));
			// stock's angle with useReferenceFrameA = false is −θ: its limits map to [−high, −low] on θ
			const btScalar sign = h->getUseReferenceFrameA() ? 1 : -1;
			btScalar lo = h->getLowerLimit() * sign, hi = h->getUpperLimit() * sign;
			if (lo > hi) btSwap(lo, hi);
			if (h->hasLimit())
			{
				d->setAngularLowerLimit(btVector3(0, 0, lo));
				d->setAngularUpperLimit(btVector3(0, 0, hi));
			}
			else
			{
				d->setAngularLowerLimit(btVector3(0, 0, 1));
				d->setAngularUpperLimit(btVector3(0, 0, -1));
			}
			if (h->getEnableAngularMotor())
			{
				d->enableMotor(5, true);
				d->setTargetVelocity(5, sign * h->getMotorTargetVelocity());
				d->setMaxMotorForce(5, h->getMaxMotorImpulse() * 60);
			}
			replacement = d;
		}
		if (replacement)
		{
			m_world->removeConstraint(h);
			m_world->addConstraint(replacement, true);
			m_ownedJoints.emplace_back(replacement);
			m_compared.push_back(replacement);
		}
		else
			m_compared.push_back(h);
	}
#else
	(void)scene;
	throw std::runtime_error("built without the Bullet world importer (libbullet-extras-dev)");
#endif
}

void Simulation::step(double dt, int iterations)
{
	for (const StockServo& s : m_stockServos)
	{
		// stock's way to hold an angle: set the motor target every tick, clamped to the servo's speed
		s.joint->setMaxMotorImpulse(s.maxTorque * btScalar(dt));
		s.joint->setMotorTarget(s.target, btScalar(dt));
		const btScalar v = s.joint->getMotorTargetVelocity();
		s.joint->setMotorTargetVelocity(btMax(-s.maxSpeed, btMin(s.maxSpeed, v)));
	}
	m_world->getSolverInfo().m_numIterations = iterations;
	m_world->stepSimulation(btScalar(dt), 0, btScalar(dt));
}

int Simulation::rows()
{
	int total = 0;
	for (btTypedConstraint* c : m_compared)
	{
		if (!c->isEnabled()) continue;
		if (c->getConstraintType() == QUATERNION_HINGE_CONSTRAINT_TYPE)
			total += static_cast<btQuaternionHingeConstraint*>(c)->getNumRowsLastStep();
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
		if (p.length() > 1e3 || v.length() > 1e4) return false;
	}
	return true;
}

std::vector<btVector3> Simulation::positions() const
{
	std::vector<btVector3> p;
	for (const btRigidBody* b : bodies) p.push_back(b->getCenterOfMassPosition());
	return p;
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
	const double e0 = sim->energy();
	// energy scale: the potential energy a body could exchange over the scene's size, plus the initial kinetic energy
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
			scale += mass * double(scene.gravity.length()) * std::max(extent, 1.0);
			pe -= mass * double(scene.gravity.dot(b->getCenterOfMassPosition()));
		}
		scale += std::fabs(e0 - pe);  // the initial kinetic energy
		if (scale == 0) scale = 1;
	}
	double sumSep2 = 0, sumMis2 = 0, maxEnergy = 0, sumTraj2 = 0, maxTraj = 0;
	long samples = 0, rows = 0;
	PeriodMeter period;
	double wall = 0;
	for (int i = 1; i <= steps; ++i)
	{
		const auto start = std::chrono::steady_clock::now();
		sim->step(settings.dt, settings.iterations);
		wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
		rows += sim->rows();
		const double t = i * settings.dt;
		if (!sim->finiteAndBounded())
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
			const double mis = double(za.angle(zb)) * 180.0 / M_PI;
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
		const double e = sim->energy();
		if (scene.conservative) maxEnergy = std::max(maxEnergy, std::fabs(e - e0) / scale);
		if (scene.reference == Reference::PendulumPeriod) period.add(t, double(sim->bodies[0]->getCenterOfMassPosition().x()));
		if (reference)
		{
			for (int k = 0; k < 16; ++k) reference->step(settings.dt / 16, 100);
			const std::vector<btVector3> a = sim->positions(), b = reference->positions();
			double err2 = 0;
			for (size_t k = 0; k < a.size(); ++k) err2 += double((a[k] - b[k]).length2());
			const double err = std::sqrt(err2 / double(std::max<size_t>(1, a.size())));
			sumTraj2 += err * err;
			maxTraj = std::max(maxTraj, err);
		}
		if (settings.series) m.series.push_back({t, stepSep, stepMis, e});
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
	else if (reference)
	{
		m.reference = "same kind, dt/16, 100 iterations";
		m.trajectoryError = maxTraj;
	}
	m.wallPerSimSecond = m.steps ? wall / (m.steps * settings.dt) : 0;
	m.rowsPerStep = m.steps ? double(rows) / m.steps : 0;
	return m;
}

}  // namespace scenes
}  // namespace quathinge
