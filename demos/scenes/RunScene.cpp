// Running a scene with one kind (runScene, JointKinds.h): stepping its Simulation, measuring every step against
// the references (fine-step, another build's, the exact period), and the fine-step reference trajectory itself.
#include "JointKinds.h"
#include "Reference.h"
#include "Simulation.h"

#include <btBulletDynamicsCommon.h>

#include <algorithm>
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

JointError measureJointError(const MeasuredJoint& j)
{
	const btVector3 pa = j.a->getCenterOfMassTransform() * j.frameA.getOrigin();
	const btVector3 pb = j.b->getCenterOfMassTransform() * j.frameB.getOrigin();
	const btVector3 za = j.a->getCenterOfMassTransform().getBasis() * j.frameA.getBasis().getColumn(2);
	const btVector3 zb = j.b->getCenterOfMassTransform().getBasis() * j.frameB.getBasis().getColumn(2);
	// atan2(|za × zb|, za·zb): accurate near 0 (btVector3::angle's acos of a float dot product bottoms out at
	// √(2ε) = 4.9e-4 rad = 0.028°, which read as a misalignment floor)
	return {double((pb - pa).length()), std::atan2(double(za.cross(zb).length()), double(za.dot(zb))) * 180.0 / M_PI};
}

namespace
{
// A slider's child's joint origin relative to the parent's (d = p_B − p_A) and the slide, frame A's x axis (world).
void sliderFrames(const MeasuredJoint& j, btVector3& d, btVector3& xa)
{
	d = j.b->getCenterOfMassTransform() * j.frameB.getOrigin() - j.a->getCenterOfMassTransform() * j.frameA.getOrigin();
	xa = j.a->getCenterOfMassTransform().getBasis() * j.frameA.getBasis().getColumn(0);
}
}  // namespace

double measureSliderSeparation(const MeasuredJoint& j)
{
	btVector3 d, xa;
	sliderFrames(j, d, xa);
	return double((d - d.dot(xa) * xa).length());
}

double measureSliderPastLimits(const MeasuredJoint& j)
{
	if (!j.hasLimit) return 0;
	btVector3 d, xa;
	sliderFrames(j, d, xa);
	const double x = double(d.dot(xa));
	return std::max({0.0, j.lower - x, x - j.upper});
}

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
		if (settings.prepare) settings.prepare(sim->world());
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
	// the common reference (Reference.h): its samples land on every perSample-th step
	ReferenceTrajectory common;
	long perSample = 0;
	std::string commonFailure;
	if (!settings.referenceFile.empty()) try
		{
			common = readReference(settings.referenceFile);
			const double ratio = common.sampleDt / settings.dt;
			perSample = std::lround(ratio);
			if (perSample < 1 || std::fabs(ratio - double(perSample)) > 1e-6 * ratio)
				throw std::runtime_error("its sample interval is no whole number of steps of dt");
			if (common.samples.front().size() != 3 * sim->bodies.size())
				throw std::runtime_error("it has another number of bodies");
			m.referenceHorizon = common.horizon;
			m.referenceError = 0;
		}
		catch (const std::exception& e)
		{
			perSample = 0;
			commonFailure = e.what();
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
	JointErrorStats errors;
	double maxEnergy = 0, maxTraj = 0;
	long rows = 0;
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
		if (scene.outOfPlaneBound >= 0)
			for (const btRigidBody* b : sim->bodies)
			{
				// ZYX Euler angles of the body's orientation R: pitch = asin(−R₂₀), yaw = atan2(R₁₀, R₀₀)
				const btMatrix3x3& r = b->getCenterOfMassTransform().getBasis();
				const double pitch = std::asin(std::max(-1.0, std::min(1.0, -double(r[2][0]))));
				const double yaw = std::atan2(double(r[1][0]), double(r[0][0]));
				m.maxOutOfPlaneRad = std::max({m.maxOutOfPlaneRad, std::fabs(pitch), std::fabs(yaw)});
			}
		if (settings.afterStep) settings.afterStep(sim->joints);
		double stepSep = 0, stepMis = 0;  // this step's largest (the series, the recovery time)
		for (MeasuredJoint& j : sim->joints)
		{
			if (j.hasLimit)
			{
				trackTheta(j);
				const double past = std::max({j.lower - j.theta, j.theta - j.upper, 0.0});
				m.limitViolation = std::max(m.limitViolation, past);
			}
			const JointError error = measureJointError(j);
			errors.add(error);
			stepSep = std::max(stepSep, error.separation);
			stepMis = std::max(stepMis, error.misalignmentDeg);
		}
		for (const MeasuredJoint& j : sim->sliders)
			m.maxSliderSeparation = std::max(m.maxSliderSeparation, measureSliderSeparation(j));
		if (stepMis < 1.0 && m.recoveryTime < 0) m.recoveryTime = t;
		if (stepMis >= 1.0) m.recoveryTime = -1;
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
			maxTraj = std::max(maxTraj, err);
		}
		if (perSample > 0 && i % perSample == 0 && size_t(i / perSample) <= common.samples.size())
		{
			std::vector<double> here;
			for (const btVector3& p : sim->positions())
				for (int c = 0; c < 3; ++c) here.push_back(double(p[c]));
			m.referenceError = std::max(m.referenceError, trajectoryDistance({here}, {common.samples[size_t(i / perSample - 1)]}, 1));
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
	m.maxSeparation = errors.maxSeparation;
	m.maxMisalignmentDeg = errors.maxMisalignmentDeg;
	m.rmsSeparation = errors.rmsSeparation();
	m.rmsMisalignmentDeg = errors.rmsMisalignmentDeg();
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
	if (!commonFailure.empty()) m.reference = "failed: " + settings.referenceFile + ": " + commonFailure;
	else if (perSample > 0)
	{
		m.reference = "common reference " + common.kind + ", " + common.precision + ", dt " + std::to_string(common.step) +
					  ", over " + std::to_string(common.horizon) + " s";
		if (m.blewUp || m.steps * settings.dt < common.horizon - 1e-9) m.referenceError = -1;  // not over the horizon
	}
	m.mlcpFallbacks = sim->mlcpFallbacks();
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
