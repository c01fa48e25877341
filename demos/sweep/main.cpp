// quathinge-sweep: the row-basis sweep (docs/ROW_BASIS.md). Runs scenes × row basis × row order × solver iterations
// with the bare quaternion hinge (and stock btHingeConstraint, or any other joint kind, at the same iterations) and writes
// one CSV line per run; with --analysis it writes instead, per scene × basis × order, the conditioning of the rows'
// K = J M⁻¹ Jᵀ at the start pose and the spectral radius of the Gauss–Seidel sweep on it; with --matched, per scene ×
// basis × order × iterations, stock and the quaternion hinge stepped from the same states (MatchedStates.h): once on
// stock's own trajectory, once on the quaternion hinge's.
//
// The basis is set through the in-tree hook quathinge::SolverRowBasisAccess (plugin/src/SolverRowBasis.h), not a
// public setter: it is the library's choice of how to present one constraint to the solver. The pieces: Sweep.h.
#include "SceneSpec.h"
#include "Sweep.h"

#include <CLI/CLI.hpp>

#include <fstream>
#include <iostream>

using namespace quathinge::scenes;
using namespace quathinge::sweep;

int main(int argc, char** argv)
{
	CLI::App app("quathinge-sweep: row basis × order × iterations over scenes, CSV out (docs/ROW_BASIS.md)");
	std::vector<std::string> sceneList = {"inertia_ratio"};
	std::vector<std::string> basisList = {"stock", "radial", "world", "heavy",
										  "decoupled", "jointframe", "radial-turned", "turned-at-static"};
	std::vector<std::string> orderList = {"point-first", "angular-first"};
	std::vector<int> iterationList = {10, 20, 50, 100, 250};
	double dt = -1, duration = -1;
	int jobs = 1;
	std::string out = "sweep.csv", models;
	bool analysis = false, matched = false;
	app.add_option("-s,--scenes", sceneList,
				   "scene names (quathinge-compare --list), inertia_ratio_<N> for the family: -s a b or --scenes a,b")
		->delimiter(',')
		->capture_default_str();
	app.add_option("-b,--bases", basisList,
				   "row bases of the bare quaternion hinge (radial world heavy decoupled jointframe radial-turned "
				   "turned-at-static radial-turned45 radial-turned90) or joint kinds (quathinge-compare --help: stock, "
				   "stock+mlcp, stock+nncg, multibody, multibody-damped, ...)")
		->capture_default_str();
	app.add_option("--orders", orderList, "point-first angular-first")->capture_default_str();
	app.add_option("-i,--iterations", iterationList, "solver iterations")->capture_default_str();
	app.add_option("--dt", dt, "time step (s); default: the scene's own (SceneSpec::dt), else 1/60");
	app.add_option("-d,--duration", duration, "simulated seconds (default: each scene's own)");
	app.add_option("-j,--jobs", jobs, "parallel runs")->capture_default_str()->check(CLI::PositiveNumber);
	app.add_option("-o,--out", out, "CSV file")->capture_default_str();
	app.add_option("--models", models, "models directory (default as quathinge-compare's)");
	app.add_flag("--analysis", analysis, "write the K analysis (conditioning, Gauss–Seidel spectral radius) instead");
	app.add_flag("--matched", matched,
				 "write matched-state runs instead: stock and each basis stepped from the same states, on each one's "
				 "trajectory (the rows compared without the trajectories they lead to)");
	app.footer(
		"Example: the bare quaternion hinge's radial basis against stock on Gazebo's inertia-ratio pendulum:\n"
		"  quathinge-sweep -s inertia_ratio -b stock radial -i 10 20 -o sweep.csv\n"
		"The manual (ROW_BASIS.md: the bases and this sweep's tables) is in " +
		manualDir());
	CLI11_PARSE(app, argc, argv);
	if (models.empty()) models = defaultModelsDir();

	std::vector<Variant> variants;
	try
	{
		for (const std::string& b : basisList) variants.push_back(parseVariant(b));
	}
	catch (const std::invalid_argument& e)
	{
		std::cerr << "quathinge-sweep: --bases: " << e.what() << '\n';
		return 2;
	}
	std::vector<bool> orders;
	for (const std::string& o : orderList)
	{
		if (o != "point-first" && o != "angular-first")
		{
			std::cerr << "quathinge-sweep: --orders: unknown order '" << o << "' (point-first angular-first)\n";
			return 2;
		}
		orders.push_back(o == "angular-first");
	}

	SweepSettings settings;
	settings.dt = dt;
	settings.duration = duration;
	settings.jobs = jobs;
	settings.models = models;
	std::ofstream csv(out);
	if (analysis)
	{
		writeAnalysis(csv, sceneList, variants, orders, settings);
		return 0;
	}
	// every run of scene × iterations × variant × order (a kind without a row basis has one order)
	std::vector<Job> queue;
	for (const std::string& name : sceneList)
		for (int iterations : iterationList)
			for (const Variant& v : variants)
				for (bool angularFirst : orders)
				{
					if (!v.hasBasis && angularFirst) continue;
					queue.push_back({name, v, angularFirst, iterations});
				}
	if (matched) writeMatched(csv, queue, settings);
	else writeRuns(csv, queue, settings);
	return 0;
}
