// quathinge-bench (issue 5): the quaternion hinge against the stock hinge, as Google Benchmark cases.
//
//   joint/<angle>/<config>/<kind>   getInfo1 + getInfo2 of one joint (what the solver asks of it every step), for
//                                   btHingeConstraint (stock), btGeneric6DofSpring2Constraint set up as a hinge (6dof2)
//                                   and btQuaternionHingeConstraint (quaternion), at hinge angles 0.5 and 3.0 rad, with
//                                   no limit, a limit not reached, a limit past its stop, a velocity motor, or both.
//   step/<scene>/<kind>             one full world step (stepSimulation, 60 Hz, 10 iterations) of a chain of 10, 100 or
//                                   1000 links, or of a crowd of 100 ragdolls on one ground, for stock, 6dof2,
//                                   quaternion and quaternion+stab (btQuaternionHingeStabilizer), and btMultiBody
//                                   revolute joints (reduced coordinates: every scene here is a tree). The world is built
//                                   and advanced a fixed number of steps first (the chain swinging, the ragdolls on the
//                                   ground), then a fixed number of single steps is timed (the same stretch of motion
//                                   for every kind and repetition). The robots and the chains of 10 and 100 also run
//                                   stock+stab and 6dof2+stab (the stabilizer on the app's own hinges), the robots
//                                   6dof2 too.
//
// QUATHINGE_BENCH_FTZ=1 runs every case with the thread's flush-to-zero and denormals-are-zero set (x86 MXCSR), as
// engines that set them for their physics thread do (Jolt's FPFlushDenormals): on an Intel host subnormal numbers in
// Bullet's solver slowed stock's chain of 1000 fourfold (docs/PERFORMANCE.md). Unset: the floating-point environment a
// default Bullet app has.
//
// Ratios against stock and the scaling plot: demos/bench_report.py; everything in one go: demos/make_bench.sh.
// --help, --scenes and --kinds: BenchArguments.h.
#include "BenchArguments.h"
#include "JointKinds.h"
#include "SceneSpec.h"
#include "Simulation.h"
#include "support/ScratchRows.h"

#include "quathinge/btQuaternionHingeConstraint.h"
#include "quathinge/btQuaternionHingeStabilizer.h"

#include <benchmark/benchmark.h>
#include <btBulletDynamicsCommon.h>

#if defined(__SSE__) || defined(__x86_64__)
#include <xmmintrin.h>
#define QUATHINGE_BENCH_HAVE_MXCSR 1
#endif

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

using namespace quathinge::scenes;
using qh_test::ScratchRows;

namespace
{
// ---- Per joint -------------------------------------------------------------------------------------------------------

enum class JointType
{
	Stock,
	Generic6Dof2,
	Quaternion
};

const char* jointTypeName(JointType t)
{
	switch (t)
	{
		case JointType::Stock: return "stock";
		case JointType::Generic6Dof2: return "6dof2";
		case JointType::Quaternion: return "quaternion";
	}
	return "?";
}

struct JointConfig
{
	const char* name;
	bool limit;        // a limit is set
	bool limitActive;  // the angle is past the upper stop (else well inside the range)
	bool motor;        // velocity motor on
};

const JointConfig kJointConfigs[] = {
	{"free", false, false, false},
	{"limit_inside", true, false, false},
	{"limit_active", true, true, false},
	{"motor", false, false, true},
	{"limit_active+motor", true, true, true},
};
const double kJointAngles[] = {0.5, 3.0};

/// Two dynamic boxes joined at a pivot about a tilted axis, body B turned by `angle` about it, with a small joint
/// error (pivot separation, axis misalignment) and relative angular velocity, as a joint mid-solve.
class JointFixture
{
public:
	JointFixture(JointType type, const JointConfig& config, double angle)
		: m_shape(btVector3(btScalar(0.1), btScalar(0.3), btScalar(0.1)))
	{
		btVector3 inertia;
		m_shape.calculateLocalInertia(2, inertia);
		const btVector3 axis = btVector3(1, 2, 3).normalized();
		const btVector3 pivot(btScalar(0.2), btScalar(1.0), btScalar(-0.3));
		const btTransform poseA(btQuaternion(btVector3(btScalar(0.3), 1, btScalar(-0.2)).normalized(), btScalar(0.7)),
								btVector3(0, btScalar(1.3), btScalar(-0.2)));
		const btTransform poseB0(btQuaternion(btVector3(-1, btScalar(0.4), btScalar(0.5)).normalized(), btScalar(1.1)),
								 btVector3(btScalar(0.4), btScalar(0.7), btScalar(-0.4)));
		btVector3 x, y;
		btPlaneSpace1(axis, x, y);
		const btTransform frame(btMatrix3x3(x.x(), y.x(), axis.x(), x.y(), y.y(), axis.y(), x.z(), y.z(), axis.z()), pivot);
		const btTransform frameInA = poseA.inverse() * frame;
		const btTransform frameInB = poseB0.inverse() * frame;
		// B turned by θ about the hinge (world), then a little off the joint: 0.02 rad about a swing axis, 5 mm.
		const btTransform turn = btTransform(btQuaternion(axis, btScalar(angle)), pivot) *
								 btTransform(btQuaternion::getIdentity(), -pivot);
		const btTransform error(btQuaternion(x, btScalar(0.02)), btVector3(btScalar(0.005), 0, 0));
		const btTransform poseB = error * turn * poseB0;
		m_a.reset(new btRigidBody(btRigidBody::btRigidBodyConstructionInfo(2, nullptr, &m_shape, inertia)));
		m_b.reset(new btRigidBody(btRigidBody::btRigidBodyConstructionInfo(2, nullptr, &m_shape, inertia)));
		m_a->setCenterOfMassTransform(poseA);
		m_b->setCenterOfMassTransform(poseB);
		m_a->setAngularVelocity(btVector3(btScalar(0.3), btScalar(-0.2), btScalar(0.1)));
		m_b->setAngularVelocity(btVector3(btScalar(-0.1), btScalar(0.4), btScalar(0.9)));
		m_a->setLinearVelocity(btVector3(btScalar(0.1), 0, 0));
		m_b->setLinearVelocity(btVector3(0, btScalar(-0.2), 0));
		m_a->updateInertiaTensor();
		m_b->updateInertiaTensor();

		// θ (useReferenceFrameA: the angle of B about +axis relative to A, the same convention for all three)
		const btScalar theta = btScalar(angle);
		// Past the upper stop by 0.05 rad, or inside [θ − 1, θ + 0.12]: a range that does not cross ±π (6dof2 wraps its
		// limits into (−π, π] and would free the joint), with θ outside the quaternion hinge's speculative margin.
		m_low = theta - 1;
		m_high = config.limitActive ? theta - btScalar(0.05) : theta + btScalar(0.12);
		const btScalar low = m_low, high = m_high;
		const btScalar motorSpeed = 1, motorImpulse = btScalar(0.5);
		switch (type)
		{
			case JointType::Stock:
			{
				auto* h = new btHingeConstraint(*m_a, *m_b, frameInA, frameInB, true);
				if (config.limit) h->setLimit(low, high);
				if (config.motor) h->enableAngularMotor(true, motorSpeed, motorImpulse);
				m_joint.reset(h);
				break;
			}
			case JointType::Generic6Dof2:
			{
				auto* d = new btGeneric6DofSpring2Constraint(*m_a, *m_b, frameInA, frameInB, RO_XYZ);
				d->setLinearLowerLimit(btVector3(0, 0, 0));
				d->setLinearUpperLimit(btVector3(0, 0, 0));
				// 6dof2's z angle is −θ (Bullet 3.24's matrixToEulerXYZ reads the transposed element): the same limit
				// and motor on it are [−high, −low] and −speed.
				if (config.limit)
				{
					d->setAngularLowerLimit(btVector3(0, 0, -high));
					d->setAngularUpperLimit(btVector3(0, 0, -low));
				}
				else
				{
					d->setAngularLowerLimit(btVector3(0, 0, 1));  // z free (lower > upper)
					d->setAngularUpperLimit(btVector3(0, 0, -1));
				}
				if (config.motor)
				{
					d->enableMotor(5, true);
					d->setTargetVelocity(5, -motorSpeed);
					d->setMaxMotorForce(5, motorImpulse * 60);
				}
				m_joint.reset(d);
				break;
			}
			case JointType::Quaternion:
			{
				auto* q = new btQuaternionHingeConstraint(*m_a, *m_b, frameInA, frameInB, true);
				if (config.limit) q->setLimit(low, high);
				if (config.motor) q->enableAngularMotor(true, motorSpeed, motorImpulse);
				m_joint.reset(q);
				break;
			}
		}
	}

	btTypedConstraint& joint() { return *m_joint; }
	btScalar low() const { return m_low; }
	btScalar high() const { return m_high; }

	/// getInfo1 + getInfo2, as the solver calls them every step; returns the row count.
	int rows(ScratchRows& scratch)
	{
		btTypedConstraint::btConstraintInfo1 info1;
		m_joint->getInfo1(&info1);
		if (info1.m_numConstraintRows > 0) m_joint->getInfo2(&scratch.info);
		return info1.m_numConstraintRows;
	}

private:
	btBoxShape m_shape;
	std::unique_ptr<btRigidBody> m_a, m_b;
	std::unique_ptr<btTypedConstraint> m_joint;
	btScalar m_low = 0, m_high = 0;
};

void benchJoint(benchmark::State& state, JointType type, JointConfig config, double angle)
{
	JointFixture fixture(type, config, angle);
	// Rows as the sequential-impulse solver hands them to getInfo2 (zeroed Jacobians and errors, bounds ±∞, rowskip 16,
	// 60 Hz, erp 0.2). Not re-zeroed between calls: every call of one joint writes the same entries, and zeroing is
	// the solver's cost (measured by the step cases), not the joint's.
	ScratchRows scratch;
	// The configuration is what it says. Stock and quaternion: 5 rows, one more for an active limit or a motor (stock
	// shares one row between them). 6dof2 reports two limit rows whenever a limit is set (its bounds decide which
	// acts), so its angle is checked against the limit instead.
	const int rows = fixture.rows(scratch);
	const int expected = 5 + (config.limitActive ? 1 : 0) + (config.motor ? 1 : 0) -
						 (type == JointType::Stock && config.limitActive && config.motor ? 1 : 0) +
						 (type == JointType::Generic6Dof2 && config.limit ? 2 - (config.limitActive ? 1 : 0) : 0);
	std::string wrong;
	if (rows != expected) wrong = "row count " + std::to_string(rows) + ", expected " + std::to_string(expected);
	if (type == JointType::Generic6Dof2 && config.limit)
	{
		const btScalar angle = -static_cast<btGeneric6DofSpring2Constraint&>(fixture.joint()).getAngle(2);  // θ
		const bool past = angle > fixture.high(), inside = angle >= fixture.low() && angle <= fixture.high();
		if (config.limitActive ? !past : !inside) wrong = "6dof2 angle " + std::to_string(angle) + " not where the limit expects it";
	}
	if (!wrong.empty())
	{
		state.SkipWithError(wrong.c_str());
		return;
	}
	for (auto _ : state)
	{
		benchmark::DoNotOptimize(fixture.rows(scratch));
		benchmark::ClobberMemory();
	}
	state.counters["rows"] = rows;
}

// ---- Full steps ------------------------------------------------------------------------------------------------------

const double kStepDt = 1.0 / 60;
const int kIterations = 10;

/// `count` ragdolls (ragdollScene with seeds 1..count) on a grid 2.5 m apart, on one ground.
SceneSpec ragdollCrowd(int count)
{
	SceneSpec crowd;
	crowd.name = "ragdolls" + std::to_string(count);
	crowd.description = std::to_string(count) + " ragdolls dropped side by side onto one ground";
	crowd.ground = true;
	crowd.reference = Reference::None;
	const int side = int(std::ceil(std::sqrt(double(count))));
	for (int i = 0; i < count; ++i)
	{
		const SceneSpec one = ragdollScene(unsigned(i + 1));
		crowd.duration = one.duration;
		const btVector3 offset(btScalar(2.5) * btScalar(i % side - side / 2), 0, btScalar(2.5) * btScalar(i / side - side / 2));
		const int base = int(crowd.bodies.size());
		for (BodySpec b : one.bodies)
		{
			b.pose.setOrigin(b.pose.getOrigin() + offset);
			crowd.bodies.push_back(b);
		}
		for (JointSpec j : one.joints)
		{
			if (j.parent >= 0) j.parent += base;
			j.child += base;
			j.pivot += offset;
			crowd.joints.push_back(j);
		}
	}
	return crowd;
}

struct StepScene
{
	SceneSpec scene;
	int warmup;             // steps before timing
	int timed;              // steps timed (a fixed count, so every kind times the same stretch of simulated time)
	bool everyKind = true;  // false: stock, quaternion and quaternion+stab only (the robots and the scenes at rest)
	// > 0: the stabilizer projects only the joints of the scene's first `heroBodies` bodies (setFilter): one ragdoll
	// of a crowd, what an app stabilizes when only its hero needs it
	int heroBodies = 0;
	// the stabilizer also projects the contacts (projectContacts), and with them the point constraints
	bool projectContacts = false;
	// also run stock+stab, 6dof2 and 6dof2+stab (the stabilizer on the app's own hinges, and the bare 6dof2 step it
	// adds to)
	bool stabilizedStock = false;
};

// Keeps the joints that hold one of the hero's bodies.
struct HeroFilter : btQuaternionHingeStabilizerFilter
{
	std::vector<const btRigidBody*> hero;
	bool needsStabilization(const btTypedConstraint& joint) const override
	{
		for (const btRigidBody* b : hero)
			if (b == &joint.getRigidBodyA() || b == &joint.getRigidBodyB()) return true;
		return false;
	}
};

void benchStep(benchmark::State& state, const StepScene* spec, Kind kind)
{
	std::unique_ptr<Simulation> built;
	try
	{
		built.reset(new Simulation(spec->scene, kind));
	}
	catch (const std::exception& e)  // a kind that cannot express the scene (multibody: loops) says why
	{
		state.SkipWithError(e.what());
		for (auto _ : state)
		{}
		return;
	}
	Simulation& sim = *built;
	if (spec->projectContacts && sim.stabilizer())
	{
		btQuaternionHingeStabilizerSettings settings = sim.stabilizer()->getSettings();
		settings.projectContacts = settings.projectPointConstraints = true;
		sim.stabilizer()->setSettings(settings);
	}
	HeroFilter heroFilter;
	if (spec->heroBodies > 0 && sim.stabilizer())
	{
		heroFilter.hero.assign(sim.bodies.begin(), sim.bodies.begin() + spec->heroBodies);
		sim.stabilizer()->setFilter(&heroFilter);
	}
	for (int i = 0; i < spec->warmup; ++i) sim.step(kStepDt, kIterations);
	// the stabilizer's work per step: Newton iterations (the most any island used), factorizations (all islands), the
	// islands it computed (not those at rest, replayed) and the limit and contact rows it projected
	double stabIterations = 0, stabFactorizations = 0, stabIslands = 0, stabLimitRows = 0, stabContactRows = 0;
	for (auto _ : state)
	{
		sim.step(kStepDt, kIterations);
		if (const btQuaternionHingeStabilizer* stab = sim.stabilizer())
		{
			const btQuaternionHingeStabilizerStats& stats = stab->getLastStats();
			stabIterations += stats.iterations;
			stabFactorizations += stats.factorizations;
			stabIslands += stats.islands - stats.restingIslands;
			stabLimitRows += stats.activeLimitRows;
			stabContactRows += stats.contactRows;
		}
	}
	if (!sim.finiteAndBounded())
	{
		state.SkipWithError("the world blew up");
		return;
	}
	const double joints = double(spec->scene.joints.size());
	state.counters["joints"] = joints;
	state.counters["rows"] = sim.rows();
	// contact points at the end (ragdolls: the kinds tumble differently, so their contact work differs too)
	btDispatcher& dispatcher = *sim.world().getDispatcher();
	int contacts = 0;
	for (int i = 0; i < dispatcher.getNumManifolds(); ++i) contacts += dispatcher.getManifoldByIndexInternal(i)->getNumContacts();
	state.counters["contacts"] = contacts;
	if (sim.stabilizer())
	{
		state.counters["stab_newton"] = benchmark::Counter(stabIterations, benchmark::Counter::kAvgIterations);
		state.counters["stab_factorizations"] = benchmark::Counter(stabFactorizations, benchmark::Counter::kAvgIterations);
		state.counters["stab_islands"] = benchmark::Counter(stabIslands, benchmark::Counter::kAvgIterations);
		state.counters["stab_limit_rows"] = benchmark::Counter(stabLimitRows, benchmark::Counter::kAvgIterations);
		state.counters["stab_contact_rows"] = benchmark::Counter(stabContactRows, benchmark::Counter::kAvgIterations);
		state.counters["stab_joints"] = sim.stabilizer()->getLastStats().joints;  // projected (the hero's, if filtered)
	}
	// time per joint-step, as a rate: items/s = joint-steps per second
	state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(joints));
}

/// The fastest repetition, reported next to the median: on a shared machine other work only ever adds time.
double minimum(const std::vector<double>& v) { return v.empty() ? 0 : *std::min_element(v.begin(), v.end()); }

std::vector<std::string> g_caseNames;  // every registered case, for --help and --kinds

void registerAll()
{
	for (double angle : kJointAngles)
		for (const JointConfig& config : kJointConfigs)
			for (JointType type : {JointType::Stock, JointType::Generic6Dof2, JointType::Quaternion})
			{
				char angleName[16];
				std::snprintf(angleName, sizeof(angleName), "a%.1f", angle);
				const std::string name = std::string("joint/") + angleName + "/" + config.name + "/" + jointTypeName(type);
				g_caseNames.push_back(name);
				benchmark::RegisterBenchmark(name.c_str(), benchJoint, type, config, angle)
					->Unit(benchmark::kNanosecond)
					->ComputeStatistics("min", minimum);
			}

	// Built once; each case builds its own world from them. Warm-up: the chains swing for half a second, the ragdolls
	// land (they touch the ground after about 0.55 s). Then a fixed number of steps is timed (Iterations): the
	// scenes are not stationary (the ragdolls come to rest), and a count chosen by time would give the faster kinds
	// a longer, different stretch of the motion. Each repetition rebuilds the world and times the same stretch.
	// The scenes at rest: 500 links hanging still, awake (the stabilizer should find nothing to do) and allowed to
	// sleep (Bullet deactivates them during the warm-up). The robots (demos/models): 3 s at 60 Hz from their start
	// pose, falling under gravity on their fixed base, as the comparison demo runs them.
	static const std::vector<StepScene> scenes = [] {
		std::vector<StepScene> list = {
			{chainScene(10, 1), 30, 3000, true, 0, false, true},
			{chainScene(100, 1), 30, 600, true, 0, false, true},
			{chainScene(1000, 1), 30, 100},
			{ragdollCrowd(100), 60, 150},
			// the same crowd with only the first ragdoll stabilized (setFilter)
			{[] {
				 SceneSpec crowd = ragdollCrowd(100);
				 crowd.name += "_hero";
				 return crowd;
			 }(),
			 60, 150, false, int(ragdollScene(1).bodies.size())},
			// the same crowd with the contacts projected too (projectContacts: ground and part against part)
			{[] {
				 SceneSpec crowd = ragdollCrowd(100);
				 crowd.name += "_contacts";
				 return crowd;
			 }(),
			 60, 150, false, 0, true},
			{restScene(50, 10, false), 180, 300, false},
			{restScene(50, 10, true), 180, 300, false},
		};
		const std::vector<std::string> built = sceneNames();  // without urdfdom or the world importer: fewer
		for (const char* robot : {"kuka_iiwa", "pendulum5", "humanoid", "base_2", "quadruped", "two_joint_robot",
								  "minitaur", "r2d2", "panda", "spider"})
		{
			if (std::find(built.begin(), built.end(), robot) == built.end()) continue;
			SceneSpec scene = makeScene(robot, 1);
			if (scene.unavailable.empty()) list.push_back({scene, 0, 180, false, 0, false, true});
		}
		return list;
	}();
	for (const StepScene& s : scenes)
		for (Kind kind : {Kind::Stock, Kind::Generic6Dof2, Kind::Quaternion, Kind::QuaternionStabilized, Kind::MultiBody,
						  Kind::StockStabilized, Kind::Generic6Dof2Stabilized})
		{
			if (!s.everyKind && ((kind == Kind::Generic6Dof2 && !s.stabilizedStock) || kind == Kind::MultiBody)) continue;
			// the stabilizer on the app's own hinges (docs/STABILIZED_JOINTS.md, its cost against quaternion+stab):
			// the robots and the shorter chains; not in bench_report.py's tables
			const bool stabilizedStock = kind == Kind::StockStabilized || kind == Kind::Generic6Dof2Stabilized;
			if (stabilizedStock && !s.stabilizedStock) continue;
			const std::string name = "step/" + s.scene.name + "/" + kindName(kind);
			g_caseNames.push_back(name);
			benchmark::RegisterBenchmark(name.c_str(), benchStep, &s, kind)
				->Unit(benchmark::kMicrosecond)
				->Iterations(s.timed)
				->ComputeStatistics("min", minimum);
		}
}
}  // namespace

int main(int argc, char** argv)
{
	if (const char* ftz = std::getenv("QUATHINGE_BENCH_FTZ"); ftz && std::string(ftz) == "1")
	{
#ifdef QUATHINGE_BENCH_HAVE_MXCSR
		_mm_setcsr(_mm_getcsr() | 0x8040);  // FTZ (bit 15) and DAZ (bit 6)
		std::fprintf(stderr, "quathinge-bench: flush-to-zero and denormals-are-zero set (QUATHINGE_BENCH_FTZ=1)\n");
#else
		std::fprintf(stderr, "quathinge-bench: QUATHINGE_BENCH_FTZ=1 needs an x86 MXCSR: ignored\n");
#endif
	}
	registerAll();
	std::vector<std::string> kinds;  // the cases' last name part
	for (const std::string& n : g_caseNames)
		if (std::find(kinds.begin(), kinds.end(), n.substr(n.rfind('/') + 1)) == kinds.end())
			kinds.push_back(n.substr(n.rfind('/') + 1));
	quathinge::bench::Arguments arguments = quathinge::bench::parseArguments(argc, argv, kinds);
	if (!arguments.error.empty())
	{
		std::fprintf(stderr, "quathinge-bench: %s\n", arguments.error.c_str());
		return 1;
	}
	if (arguments.help)
	{
		std::fputs(quathinge::bench::helpText(g_caseNames, kinds, manualDir()).c_str(), stdout);
		std::fflush(stdout);
		arguments.passOn.push_back("--help");  // Google Benchmark's own options follow (it exits)
	}
	std::vector<char*> args;
	for (std::string& a : arguments.passOn) args.push_back(a.data());
	int count = int(args.size());
	args.push_back(nullptr);  // argv[argc], as main's
	benchmark::Initialize(&count, args.data());
	if (benchmark::ReportUnrecognizedArguments(count, args.data())) return 1;
	benchmark::RunSpecifiedBenchmarks();
	benchmark::Shutdown();
	return 0;
}
