// The common reference trajectory (Reference.h): recording, the halving and divergence checks, the file.
#include "Reference.h"
#include "Simulation.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace quathinge
{
namespace scenes
{
Kind referenceKindOf(const SceneSpec& scene)
{
	bool misaligned = false;
	for (const JointSpec& j : scene.joints)
		if (!j.childPivotOffset.isZero() || btFabs(j.childFrameTwist.x()) > SIMD_EPSILON ||
			btFabs(j.childFrameTwist.y()) > SIMD_EPSILON)
			misaligned = true;
	if (!scene.bulletFile.empty() || misaligned || !isTree(scene)) return kLoopReferenceKind;
	return Kind::MultiBody;
}

SceneSpec kickedScene(const SceneSpec& scene, double radians)
{
	SceneSpec kicked = scene;
	if (scene.joints.empty()) return kicked;
	const btQuaternion turn(scene.joints[0].axis, btScalar(radians));
	const btTransform about(btQuaternion::getIdentity(), scene.joints[0].pivot);
	const btTransform move = about * btTransform(turn) * about.inverse();
	const btMatrix3x3 r(turn);
	for (BodySpec& b : kicked.bodies)
	{
		b.pose = move * b.pose;
		b.linearVelocity = r * b.linearVelocity;
		b.angularVelocity = r * b.angularVelocity;
	}
	for (JointSpec& j : kicked.joints)
	{
		j.pivot = move * j.pivot;
		j.axis = r * j.axis;
		j.childPivotOffset = r * j.childPivotOffset;
	}
	for (SliderSpec& s : kicked.sliders)
	{
		s.pivot = move * s.pivot;
		s.axis = r * s.axis;
	}
	return kicked;
}

ReferenceTrajectory recordTrajectory(const SceneSpec& scene, Kind kind, double step, int iterations, double sampleDt,
									 double duration)
{
	const double ratio = sampleDt / step;
	const long perSample = std::lround(ratio);
	if (perSample < 1 || std::fabs(ratio - double(perSample)) > 1e-6 * ratio)
		throw std::runtime_error("recordTrajectory: step: the sample interval is no whole number of steps");
	Simulation sim(scene, kind);
	sim.setMaxCoordinateVelocity(kReferenceMaxCoordinateVelocity);
	ReferenceTrajectory out;
	out.scene = scene.name;
	out.kind = kindName(kind);
	out.precision = sizeof(btScalar) == 8 ? "double" : "float";
	out.step = step;
	out.iterations = iterations;
	out.sampleDt = sampleDt;
	out.horizon = duration;
	const long samples = std::lround(std::floor(duration / sampleDt + 1e-9));
	for (long k = 1; k <= samples; ++k)
	{
		for (long i = 0; i < perSample; ++i) sim.step(step, iterations);
		std::vector<double> row;
		for (const btVector3& p : sim.positions())
			for (int c = 0; c < 3; ++c) row.push_back(double(p[c]));
		out.samples.push_back(row);
	}
	return out;
}

namespace
{
double rmsDistance(const std::vector<double>& a, const std::vector<double>& b)
{
	double sum = 0;
	for (size_t i = 0; i < a.size() && i < b.size(); ++i) sum += (a[i] - b[i]) * (a[i] - b[i]);
	const double bodies = double(std::max<size_t>(1, a.size() / 3));
	return std::sqrt(sum / bodies);
}
}  // namespace

double trajectoryDistance(const std::vector<std::vector<double>>& a, const std::vector<std::vector<double>>& b,
						  size_t samples)
{
	double worst = 0;
	for (size_t k = 0; k < samples && k < a.size() && k < b.size(); ++k)
	{
		const double d = rmsDistance(a[k], b[k]);
		if (!std::isfinite(d)) return std::numeric_limits<double>::infinity();
		worst = std::max(worst, d);
	}
	return worst;
}

ReferenceTrajectory makeReference(const SceneSpec& scene, double step, double duration)
{
	const Kind kind = referenceKindOf(scene);
	const double length = duration > 0 ? duration : scene.duration;
	// Richardson extrapolation of the first-order integrator: R(h) = 2 r(h/2) − r(h) cancels the error's term in h;
	// the half-step check is R(h/2) = 2 r(h/4) − r(h/2)
	auto record = [&](const SceneSpec& s, double h) {
		return recordTrajectory(s, kind, h, kReferenceIterations, kReferenceSample, length);
	};
	auto extrapolate = [](const ReferenceTrajectory& coarse, ReferenceTrajectory fine) {
		for (size_t k = 0; k < fine.samples.size() && k < coarse.samples.size(); ++k)
			for (size_t i = 0; i < fine.samples[k].size(); ++i)
				fine.samples[k][i] = 2 * fine.samples[k][i] - coarse.samples[k][i];
		return fine;
	};
	const ReferenceTrajectory r1 = record(scene, step), r2 = record(scene, step / 2), r4 = record(scene, step / 4);
	ReferenceTrajectory ref = extrapolate(r1, r2);
	ref.step = step;
	const ReferenceTrajectory half = extrapolate(r2, r4);
	const ReferenceTrajectory kicked = record(kickedScene(scene, kDivergenceKick), step / 2);
	const ReferenceTrajectory& plain = r2;  // the kicked run's unkicked twin
	size_t horizon = ref.samples.size();
	for (size_t k = 0; k < ref.samples.size(); ++k)
	{
		if (ref.divergenceTime < 0 && rmsDistance(plain.samples[k], kicked.samples[k]) > kDivergenceThreshold)
			ref.divergenceTime = double(k + 1) * ref.sampleDt;
		if (ref.halvingTime < 0 && !(rmsDistance(ref.samples[k], half.samples[k]) <= kHalvingTolerance))
			ref.halvingTime = double(k + 1) * ref.sampleDt;
		if (ref.divergenceTime >= 0 || ref.halvingTime >= 0)
		{
			horizon = k;  // the samples before it
			break;
		}
	}
	// the other event, if it comes later, is still said
	for (size_t k = horizon; k < ref.samples.size(); ++k)
	{
		if (ref.divergenceTime < 0 && rmsDistance(plain.samples[k], kicked.samples[k]) > kDivergenceThreshold)
			ref.divergenceTime = double(k + 1) * ref.sampleDt;
		if (ref.halvingTime < 0 && !(rmsDistance(ref.samples[k], half.samples[k]) <= kHalvingTolerance))
			ref.halvingTime = double(k + 1) * ref.sampleDt;
	}
	horizon = std::max<size_t>(horizon, 1);
	ref.samples.resize(horizon);
	ref.horizon = double(horizon) * ref.sampleDt;
	ref.halvingChange = trajectoryDistance(ref.samples, half.samples, horizon);
	return ref;
}

void writeReference(const ReferenceTrajectory& r, const std::string& path)
{
	std::ofstream out(path);
	if (!out) throw std::runtime_error("writeReference: path: cannot write " + path);
	out << std::setprecision(17) << "# quathinge reference trajectory (demos/scenes/Reference.h)\n"
		<< "# scene " << r.scene << "\n# kind " << r.kind << "\n# precision " << r.precision << "\n# step " << r.step
		<< "\n# iterations " << r.iterations << "\n# sample_dt " << r.sampleDt << "\n# horizon " << r.horizon
		<< "\n# halving_change " << r.halvingChange << "\n# halving_time " << r.halvingTime
		<< "\n# divergence_time " << r.divergenceTime
		<< "\n# divergence_threshold " << kDivergenceThreshold << "\n# divergence_kick " << kDivergenceKick << '\n';
	for (const std::vector<double>& row : r.samples)
	{
		for (size_t i = 0; i < row.size(); ++i) out << (i ? " " : "") << row[i];
		out << '\n';
	}
}

ReferenceTrajectory readReference(const std::string& path)
{
	std::ifstream in(path);
	if (!in) throw std::runtime_error("readReference: path: cannot read " + path);
	ReferenceTrajectory r;
	std::string line;
	while (std::getline(in, line))
	{
		std::istringstream words(line);
		if (line.rfind("# ", 0) == 0)
		{
			std::string hash, key;
			words >> hash >> key;
			if (key == "scene") words >> r.scene;
			else if (key == "kind") words >> r.kind;
			else if (key == "precision") words >> r.precision;
			else if (key == "step") words >> r.step;
			else if (key == "iterations") words >> r.iterations;
			else if (key == "sample_dt") words >> r.sampleDt;
			else if (key == "horizon") words >> r.horizon;
			else if (key == "halving_change") words >> r.halvingChange;
			else if (key == "divergence_time") words >> r.divergenceTime;
			else if (key == "halving_time") words >> r.halvingTime;
			continue;
		}
		std::vector<double> row;
		for (double v; words >> v;) row.push_back(v);
		if (!row.empty()) r.samples.push_back(row);
	}
	if (r.sampleDt <= 0 || r.samples.empty()) throw std::runtime_error("readReference: path: no reference in " + path);
	return r;
}

}  // namespace scenes
}  // namespace quathinge
