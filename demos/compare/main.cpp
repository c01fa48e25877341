// quathinge-compare: runs scenes × joint kinds (× a sweep of step and iterations), prints a table, writes CSV and JSON.
// With no arguments it runs README's demo command (cmake/run-demo.sh): a representative subset that finishes well
// under a minute on two cores.
#include "JointKinds.h"
#include "Reference.h"
#include "SceneSpec.h"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <thread>
#include <unistd.h>

using namespace quathinge::scenes;

namespace
{
struct Job
{
	SceneSpec scene;
	Kind kind;
	RunSettings settings;
};

std::string figure(double v, const char* format = "{:.2e}") { return v < 0 ? "-" : fmt::format(format, v); }

void writeCsv(const std::string& path, const std::vector<Metrics>& results)
{
	std::ofstream out(path);
	out << "scene,kind,dt,iterations,skipped,max_separation_m,rms_separation_m,max_misalignment_deg,"
		   "rms_misalignment_deg,recovery_time_s,limit_violation_rad,final_theta_rad,energy_drift,trajectory_error,reference,blew_up,"
		   "blow_up_time_s,max_energy_gain,wall_per_sim_s,cpu_per_sim_s,"
		   "rows_per_step,steps,slider_separation_m,reference_error_m,reference_horizon_s,mlcp_fallbacks\n";
	for (const Metrics& m : results)
		out << m.scene << ',' << m.kind << ',' << m.dt << ',' << m.iterations << ",\"" << m.skipped << "\","
			<< m.maxSeparation << ',' << m.rmsSeparation << ',' << m.maxMisalignmentDeg << ',' << m.rmsMisalignmentDeg
			<< ',' << m.recoveryTime << ',' << m.limitViolation << ',' << m.finalTheta << ',' << m.energyDrift << ',' << m.trajectoryError << ",\"" << m.reference << "\"," << m.blewUp << ','
			<< m.blowUpTime << ',' << m.maxEnergyGain << ',' << m.wallPerSimSecond << ',' << m.cpuPerSimSecond << ',' << m.rowsPerStep << ',' << m.steps << ',' << m.maxSliderSeparation << ','
			<< m.referenceError << ',' << m.referenceHorizon << ',' << m.mlcpFallbacks << '\n';
}

void writeJson(const std::string& path, const std::vector<Metrics>& results)
{
	nlohmann::json runs = nlohmann::json::array();
	for (const Metrics& m : results)
	{
		nlohmann::json j = {{"scene", m.scene},
							{"kind", m.kind},
							{"dt", m.dt},
							{"iterations", m.iterations},
							{"skipped", m.skipped},
							{"max_separation_m", m.maxSeparation},
							{"rms_separation_m", m.rmsSeparation},
							{"max_misalignment_deg", m.maxMisalignmentDeg},
							{"rms_misalignment_deg", m.rmsMisalignmentDeg},
							{"recovery_time_s", m.recoveryTime},
							{"limit_violation_rad", m.limitViolation},
							{"final_theta_rad", m.finalTheta},
							{"energy_drift", m.energyDrift},
							{"trajectory_error", m.trajectoryError},
							{"reference", m.reference},
							{"blew_up", m.blewUp},
							{"blow_up_time_s", m.blowUpTime},
							{"max_energy_gain", m.maxEnergyGain},
							{"wall_per_sim_s", m.wallPerSimSecond},
							{"cpu_per_sim_s", m.cpuPerSimSecond},
							{"rows_per_step", m.rowsPerStep},
							{"steps", m.steps},
							{"slider_separation_m", m.maxSliderSeparation},
							{"reference_error_m", m.referenceError},
							{"reference_horizon_s", m.referenceHorizon},
							{"mlcp_fallbacks", m.mlcpFallbacks}};
		if (!m.series.empty())
		{
			nlohmann::json series = nlohmann::json::array();
			for (const SeriesPoint& p : m.series) series.push_back({p.t, p.separation, p.misalignmentDeg, p.energy});
			j["series"] = series;  // [t s, separation m, misalignment deg, energy J]
		}
		runs.push_back(j);
	}
	std::ofstream(path) << nlohmann::json{{"runs", runs}}.dump(1) << '\n';
}
}  // namespace

int main(int argc, char** argv)
{
	CLI::App app{
		"quathinge-compare: stock btHingeConstraint against btQuaternionHingeConstraint (and more) on the "
		"scene library; error against run time"};
	std::vector<std::string> scenes;
	const std::vector<std::string> built = sceneNames();  // the defaults this build has (spider: the world importer)
	for (const char* name : {"pendulum", "chain10", "heavy100", "flipped179", "limit_across_pi", "four_bar", "spider"})
		if (std::find(built.begin(), built.end(), name) != built.end()) scenes.push_back(name);
	std::vector<std::string> kinds;
	for (Kind k : allKinds()) kinds.push_back(kindName(k));
	double dt = 1.0 / 60, duration = -1;
	int iterations = 10;
	unsigned seed = 1;
	unsigned jobs = std::max(1u, std::thread::hardware_concurrency());
	std::vector<double> sweepSteps;
	std::vector<int> sweepIterations;
	std::string out = "quathinge-out", models = "";
	bool noReference = false, series = false, list = false;
	long soak = 0;
	std::string referenceExe, dumpReference, referenceDir, writeReferenceDir;
	double referenceDt = kReferenceStep;
	int dumpSteps = 0;
	app.add_option("-s,--scenes", scenes, "scene names (--list shows them), or URDF paths: -s a b or --scenes a,b")
		->delimiter(',')
		->capture_default_str();
	app.add_option("-k,--kinds", kinds, "joint kinds (below; PEERS.md for the peers' settings): -k a b or --kinds a,b")
		->delimiter(',')
		->capture_default_str();
	app.add_option("--dt", dt, "time step (s)")->capture_default_str()->check(CLI::PositiveNumber);
	app.add_option("-i,--iterations", iterations, "solver iterations")->capture_default_str()->check(CLI::PositiveNumber);
	app.add_option("-d,--duration", duration, "simulated seconds (default: each scene's own)");
	app.add_option("--seed", seed, "seed for scenes with randomness")->capture_default_str();
	app.add_option("--sweep-dt", sweepSteps, "sweep these time steps (s) — with --sweep-iterations traces error against run time");
	app.add_option("--sweep-iterations", sweepIterations, "sweep these iteration counts");
	app.add_option("-j,--jobs", jobs, "parallel runs")->capture_default_str()->check(CLI::PositiveNumber);
	app.add_option("-o,--out", out,
				   "output folder for results.csv and results.json, relative to the current directory "
				   "(created if missing)")
		->capture_default_str();
	app.add_option("--models", models, "directory of the models (default: $QUATHINGE_MODELS_DIR, else the installed share/quathinge/models, else the source tree's demos/models)");
	app.add_flag("--no-reference", noReference, "skip the fine-step reference runs (faster; no trajectory error)");
	app.add_flag("--series", series, "record time series (separation, misalignment, energy) in the JSON");
	app.add_flag("--list", list, "list the scenes and exit");
	app.add_option("--soak", soak,
				   "soak: run each scene x kind for this many steps (no reference), checking for NaN, "
				   "energy and resident memory")
		->check(CLI::PositiveNumber);
	app.add_option("--reference-exe", referenceExe,
				   "take the fine-step references from this quathinge-compare (the double-precision build's); default: "
				   "run them here, in this build's precision");
	app.add_flag("--dump-reference",
				 "print the fine-step reference trajectory of the first scene and kind (every body's "
				 "position after each of --dump-steps steps of --dt) and exit");
	app.add_option("--dump-steps", dumpSteps, "coarse steps for --dump-reference");
	app.add_option("--reference-dir", referenceDir,
				   "measure reference_error_m against the common references DIR/<scene>.ref (--write-reference)");
	app.add_option("--write-reference", writeReferenceDir,
				   "write each scene's common reference to DIR/<scene>.ref (run it in the double build: PEERS.md), "
				   "print its step, halving change, divergence time and horizon, and exit (-d: its length, default the "
				   "scene's duration)");
	app.add_option("--reference-dt", referenceDt, "the common reference's step (s)")->capture_default_str()->check(CLI::PositiveNumber);
	app.footer("Joint kinds (-k, --kinds):" + kindsHelp() + "\n" +
			   "\nExample: compare stock and the stabilized hinge on two chains at 200 Hz and 20 iterations:\n"
			   "  quathinge-compare -s heavy1000 chain30 -k stock quaternion+stab --dt 0.005 -i 20 -o my-run\n"
			   "writes my-run/results.csv and my-run/results.json under the current directory and prints the table.\n"
			   "Defaults: 60 Hz (--dt 0.0166667), 10 iterations, each scene's own duration, the kinds stock 6dof2 "
			   "quaternion quaternion+stab multibody stock+stab 6dof2+stab, output in ./quathinge-out.\n"
			   "\nThe manual (PEERS.md: the peers and the common reference; ENERGY.md: energy; RESULTS.md: the tables "
			   "this program makes) is in " +
			   manualDir());
	CLI11_PARSE(app, argc, argv);

	if (models.empty()) models = defaultModelsDir();
	if (list)
	{
		for (const std::string& name : sceneNames())
			std::cout << fmt::format("{:<16} {}\n", name, makeScene(name, seed, models).description);
		return 0;
	}
	if (app.count("--dump-reference"))
	{
		try
		{
			const SceneSpec scene = makeScene(scenes.at(0), seed, models);
			std::cout << "# precision " << (sizeof(btScalar) == 8 ? "double" : "float") << '\n';
			for (const auto& positions : fineStepReference(scene, parseKind(kinds.at(0)), dt, dumpSteps))
			{
				for (const btVector3& p : positions)
					std::cout << fmt::format("{:.17g} {:.17g} {:.17g} ", double(p.x()), double(p.y()), double(p.z()));
				std::cout << '\n';
			}
			return 0;
		}
		catch (const std::exception& e)
		{
			std::cerr << "quathinge-compare: --dump-reference: " << e.what() << '\n';
			return 2;
		}
	}
	if (!writeReferenceDir.empty())
	{
		std::filesystem::create_directories(writeReferenceDir);
		std::cout << "scene,kind,precision,step_s,iterations,horizon_s,halving_change_m,divergence_time_s,halving_time_s\n";
		for (const std::string& name : scenes)
			try
			{
				const ReferenceTrajectory r = makeReference(makeScene(name, seed, models), referenceDt, duration);
				writeReference(r, writeReferenceDir + "/" + name + ".ref");
				std::cout << fmt::format("{},{},{},{:.6g},{},{:.10g},{:.3g},{:.4g},{:.4g}\n", name, r.kind, r.precision, r.step,
										 r.iterations, r.horizon, r.halvingChange, r.divergenceTime, r.halvingTime)
						  << std::flush;
			}
			catch (const std::exception& e)
			{
				std::cerr << "quathinge-compare: --write-reference: " << name << ": " << e.what() << '\n';
				return 2;
			}
		return 0;
	}
	if (sweepSteps.empty()) sweepSteps = {dt};
	if (sweepIterations.empty()) sweepIterations = {iterations};

	std::vector<Job> queue;
	try
	{
		for (const std::string& name : scenes)
		{
			const SceneSpec scene = makeScene(name, seed, models);
			for (const std::string& k : kinds)
				for (double h : sweepSteps)
					for (int it : sweepIterations)
					{
						RunSettings settings;
						settings.dt = h;
						settings.iterations = it;
						settings.duration = duration;
						settings.reference = !noReference;
						settings.series = series;
						settings.referenceExe = referenceExe;
						settings.sceneArgument = name;
						settings.modelsDir = models;
						settings.seed = seed;
						if (!referenceDir.empty()) settings.referenceFile = referenceDir + "/" + name + ".ref";
						if (soak > 0)
						{
							settings.duration = double(soak) * h;
							settings.reference = false;
							settings.memoryEvery = int(std::max(1L, soak / 20));
						}
						queue.push_back({scene, parseKind(k), settings});
					}
		}
	}
	catch (const std::invalid_argument& e)
	{
		std::cerr << "quathinge-compare: " << e.what() << '\n';
		return 2;
	}

	// Run in parallel: each job builds its own world; results keep the queue's order.
	std::vector<Metrics> results(queue.size());
	std::atomic<size_t> next{0}, done{0};
	std::mutex printMutex;
	const bool tty = isatty(2);
	auto worker = [&] {
		for (size_t i; (i = next++) < queue.size();)
		{
			results[i] = runScene(queue[i].scene, queue[i].kind, queue[i].settings);
			const size_t finished = ++done;
			if (tty)
			{
				std::lock_guard<std::mutex> lock(printMutex);
				const int width = 30, filled = int(width * finished / queue.size());
				std::cerr << fmt::format("\r[{}{}] {}/{} {:<40}", std::string(size_t(filled), '#'),
										 std::string(size_t(width - filled), '.'), finished, queue.size(),
										 results[i].scene + " " + results[i].kind)
						  << std::flush;
			}
		}
	};
	std::vector<std::thread> threads;
	for (unsigned t = 0; t < std::min<size_t>(jobs, queue.size()); ++t) threads.emplace_back(worker);
	for (std::thread& t : threads) t.join();
	if (tty) std::cerr << '\n';

	std::cout << fmt::format("{:<16} {:<16} {:>8} {:>4} {:>10} {:>10} {:>10} {:>8} {:>9} {:>10} {:>10} {:>9} {:>9} {:>9} {:>6}\n",
							 "scene", "kind", "dt", "it", "max sep m", "rms sep m", "max mis°", "recov s", "limit rad",
							 "energy", "traj err", "blow-up s", "wall ms/s", "cpu ms/s", "rows");
	for (const Metrics& m : results)
	{
		if (!m.skipped.empty())
		{
			std::cout << fmt::format("{:<16} {:<16} skipped: {}\n", m.scene, m.kind, m.skipped);
			continue;
		}
		std::cout << fmt::format("{:<16} {:<16} {:>8.5f} {:>4} {:>10} {:>10} {:>10} {:>8} {:>9} {:>10} {:>10} {:>9} {:>9.2f} {:>9.2f} {:>6.1f}\n",
								 m.scene, m.kind, m.dt, m.iterations, figure(m.maxSeparation), figure(m.rmsSeparation),
								 figure(m.maxMisalignmentDeg), figure(m.recoveryTime, "{:.3f}"),
								 figure(m.limitViolation, "{:.1e}"), figure(m.energyDrift), figure(m.trajectoryError),
								 m.blewUp ? fmt::format("{:.2f}", m.blowUpTime) : "-", 1e3 * m.wallPerSimSecond,
								 1e3 * m.cpuPerSimSecond, m.rowsPerStep);
	}
	bool sliders = false;
	for (const Metrics& m : results)
		if (m.skipped.empty() && m.maxSliderSeparation >= 0)
		{
			if (!sliders)
				std::cout << "\nprismatic joints (not compared: the same 6-dof constraint in every maximal-coordinate kind, a "
							 "prismatic link in multibody), largest distance off their slide line:\n";
			sliders = true;
			std::cout << fmt::format("  {:<16} {:<16} {} m\n", m.scene, m.kind, figure(m.maxSliderSeparation));
		}
	for (const Metrics& m : results)
		if (m.skipped.empty() && (m.referenceHorizon > 0 || m.mlcpFallbacks >= 0))
			std::cout << fmt::format("  {:<16} {:<16} common-reference error {} m over {} s; MLCP fallbacks {} of {} steps\n",
									 m.scene, m.kind, figure(m.referenceError), figure(m.referenceHorizon, "{:.3g}"),
									 m.mlcpFallbacks >= 0 ? std::to_string(m.mlcpFallbacks) : "-", m.steps);
	std::cout << "\ntrajectory reference per scene:\n";
	for (size_t i = 0; i < results.size(); ++i)
		if (results[i].skipped.empty() && (i == 0 || results[i].scene != results[i - 1].scene))
			std::cout << fmt::format("  {:<16} {}\n", results[i].scene, results[i].reference);
	if (soak > 0)
	{
		std::cout << "\nsoak: steps, blow-up, energy drift, resident memory at the first and last of 20 samples (kB)\n";
		for (const Metrics& m : results)
			if (m.skipped.empty())
				std::cout << fmt::format("{:<16} {:<16} {:>9} steps  blow-up {}  energy {}  max sep {}  rss {} -> {} kB\n", m.scene,
										 m.kind, m.steps, m.blewUp ? "YES" : "no", figure(m.energyDrift), figure(m.maxSeparation),
										 m.rssFirstKb, m.rssLastKb);
	}
	std::filesystem::create_directories(out);
	writeCsv(out + "/results.csv", results);
	writeJson(out + "/results.json", results);
	if (soak > 0)
		for (const Metrics& m : results)
			if (m.blewUp)
			{
				std::cerr << "quathinge-compare: soak failed: " << m.scene << " " << m.kind << " blew up at t = " << m.blowUpTime
						  << " s\n";
				return 1;
			}
	std::cout << fmt::format(
		"\nwrote {0}/results.csv and {0}/results.json ({1} runs). energy: max |E-E0| / energy "
		"scale; traj err: m against the fine-step reference, or relative period error; wall/cpu ms/s: "
		"milliseconds of wall / this thread's CPU time per simulated second; rows: solver rows per step.\n",
		out, results.size());
	std::cout << fmt::format(
		"blow-up s: time of the first step with a non-finite state, a body beyond {:g} m or faster "
		"than {:g} m/s, or a runaway: energy above its start by more than {:g}x the energy scale "
		"(sum of m g max(extent, 1 m) plus the initial kinetic energy; max_energy_gain in the JSON).\n",
		kRunawayDistance, kRunawaySpeed, kRunawayEnergyGain);
	return 0;
}
