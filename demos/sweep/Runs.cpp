// quathinge-sweep's runs (Sweep.h): the free runs, one CSV line each, and the matched-state runs (MatchedStates.h).
#include "MatchedStates.h"
#include "Simulation.h"
#include "Sweep.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <iterator>
#include <mutex>

namespace quathinge
{
namespace sweep
{
using namespace quathinge::scenes;

void writeMatched(std::ostream& csv, const std::vector<Job>& queue, const SweepSettings& sweepSettings)
{
	// one line per scene × basis × order × iterations × leader: both kinds' errors, the follower's from the
	// leader's state before every step
	csv << "scene,basis,order,dt,iterations,leader,skipped,blew_up,steps,stock_max_separation_m,"
		   "stock_rms_separation_m,stock_max_misalignment_deg,stock_rms_misalignment_deg,"
		   "quaternion_max_separation_m,quaternion_rms_separation_m,quaternion_max_misalignment_deg,"
		   "quaternion_rms_misalignment_deg\n";
	std::vector<Job> matchedJobs;  // the quaternion hinge's runs (each is compared with stock's here)
	std::copy_if(queue.begin(), queue.end(), std::back_inserter(matchedJobs),
				 [](const Job& job) { return job.variant.hasBasis; });
	std::mutex lock;
	runJobs(matchedJobs, sweepSettings.jobs, [&](const Job& job) {
		const SceneSpec scene = makeScene(job.sceneName, 1, sweepSettings.models);
		const double step = sweepSettings.dt > 0 ? sweepSettings.dt : sceneStep(scene);
		auto prepare = [&job](btDiscreteDynamicsWorld& world) {
			setBasis(world, job.variant.basis, job.angularFirst);  // touches only quaternion hinges
		};
		for (bool stockLeads : {true, false})
		{
			const Kind leader = stockLeads ? Kind::Stock : Kind::Quaternion;
			const Kind follower = stockLeads ? Kind::Quaternion : Kind::Stock;
			const MatchedRun run = runMatched(scene, leader, follower, step, job.iterations, sweepSettings.duration, prepare);
			const JointErrorStats& stock = stockLeads ? run.leader : run.follower;
			const JointErrorStats& quaternion = stockLeads ? run.follower : run.leader;
			std::lock_guard<std::mutex> guard(lock);
			csv << job.sceneName << ',' << job.variant.name << ','
				<< (job.angularFirst ? "angular-first" : "point-first") << ',' << step << ','
				<< job.iterations << ',' << (stockLeads ? "stock" : "quaternion") << ",\"" << run.skipped
				<< "\"," << run.blewUp << ',' << run.steps << ',' << stock.maxSeparation << ','
				<< stock.rmsSeparation() << ',' << stock.maxMisalignmentDeg << ','
				<< stock.rmsMisalignmentDeg() << ',' << quaternion.maxSeparation << ','
				<< quaternion.rmsSeparation() << ',' << quaternion.maxMisalignmentDeg << ','
				<< quaternion.rmsMisalignmentDeg() << '\n';
			csv.flush();
			std::cout << fmt::format(
							 "{:<22} {:<11} {:>4} it  on {}'s states: max sep stock {:.3e} "
							 "quaternion {:.3e} m\n",
							 job.sceneName, job.variant.name, job.iterations,
							 stockLeads ? "stock" : "quaternion", stock.maxSeparation,
							 quaternion.maxSeparation)
					  << std::flush;
		}
	});
}

void writeRuns(std::ostream& csv, const std::vector<Job>& queue, const SweepSettings& sweepSettings)
{
	csv << "scene,basis,order,dt,iterations,skipped,max_separation_m,rms_separation_m,max_misalignment_deg,"
		   "rms_misalignment_deg,energy_drift,max_out_of_plane_rad,blew_up,cpu_per_sim_s,max_joint_rms_swing_rate,"
		   "swing_mean_over_rms,mlcp_fallbacks,steps\n";
	std::mutex lock;
	runJobs(queue, sweepSettings.jobs, [&](const Job& job) {
		const SceneSpec scene = makeScene(job.sceneName, 1, sweepSettings.models);
		RunSettings settings;
		settings.dt = sweepSettings.dt > 0 ? sweepSettings.dt : sceneStep(scene);
		settings.iterations = job.iterations;
		settings.duration = sweepSettings.duration;
		settings.reference = false;
		if (job.variant.hasBasis)
			settings.prepare = [&job](btDiscreteDynamicsWorld& world) {
				setBasis(world, job.variant.basis, job.angularFirst);
			};
		// per joint: the swing rate (the relative angular velocity across the hinge axis) in joint frame A's x̂, ŷ
		// after each step — its mean and RMS show whether a misalignment grows as a steady drift (|mean| ≈ RMS)
		// or as an oscillation (|mean| ≪ RMS)
		std::vector<double> sumX, sumY, sum2;
		long samples = 0;
		settings.afterStep = [&](const std::vector<MeasuredJoint>& joints) {
			sumX.resize(joints.size(), 0);
			sumY.resize(joints.size(), 0);
			sum2.resize(joints.size(), 0);
			for (size_t k = 0; k < joints.size(); ++k)
			{
				const MeasuredJoint& j = joints[k];
				const btMatrix3x3 frame = j.a->getCenterOfMassTransform().getBasis() * j.frameA.getBasis();
				const btVector3 local = frame.transpose() * (j.b->getAngularVelocity() - j.a->getAngularVelocity());
				sumX[k] += double(local.x());
				sumY[k] += double(local.y());
				sum2[k] += double(local.x() * local.x() + local.y() * local.y());
			}
			++samples;
		};
		const Metrics m = runScene(scene, job.variant.kind, settings);
		double swingRms = 0, swingBias = 0;  // the joint with the largest RMS swing rate, and its |mean| / RMS
		for (size_t k = 0; k < sum2.size() && samples > 0; ++k)
		{
			const double rms = std::sqrt(sum2[k] / double(samples));
			if (rms <= swingRms) continue;
			swingRms = rms;
			const double mx = sumX[k] / double(samples), my = sumY[k] / double(samples);
			swingBias = std::sqrt(mx * mx + my * my) / rms;
		}
		std::lock_guard<std::mutex> guard(lock);
		csv << m.scene << ',' << job.variant.name << ',' << (job.angularFirst ? "angular-first" : "point-first")
			<< ',' << m.dt << ',' << m.iterations << ",\"" << m.skipped << "\"," << m.maxSeparation << ','
			<< m.rmsSeparation << ',' << m.maxMisalignmentDeg << ',' << m.rmsMisalignmentDeg << ',' << m.energyDrift
			<< ',' << m.maxOutOfPlaneRad << ',' << m.blewUp << ',' << m.cpuPerSimSecond << ',' << swingRms << ','
			<< swingBias << ',' << m.mlcpFallbacks << ',' << m.steps << '\n';
		csv.flush();
		std::cout << fmt::format("{:<22} {:<11} {:<13} {:>4} it  max sep {:.3e} m  max mis {:.3e} deg  oop {:.4f} rad{}\n",
								 m.scene, job.variant.name, job.angularFirst ? "angular-first" : "point-first",
								 m.iterations, m.maxSeparation, m.maxMisalignmentDeg, m.maxOutOfPlaneRad,
								 m.blewUp ? "  BLEW UP" : "")
				  << std::flush;
	});
}

}  // namespace sweep
}  // namespace quathinge
