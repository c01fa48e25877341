// quathinge-bench's own command line, in front of Google Benchmark's: --help (its cases, kinds, an example, what the
// timings mean), and --scenes / --kinds (-s / -k, the names quathinge-compare and quathinge-viewer take: -k a b or
// --kinds a,b), turned into a --benchmark_filter. Every other argument goes on to Google Benchmark.
#ifndef QUATHINGE_BENCH_ARGUMENTS_H
#define QUATHINGE_BENCH_ARGUMENTS_H

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

namespace quathinge
{
namespace bench
{
/// The arguments for Google Benchmark, or what to do instead.
struct Arguments
{
	std::vector<std::string> passOn;  // argv[0] first
	bool help = false;
	std::string error;  // a refused argument: print it and exit 1
};

/// `name`'s characters that a regular expression would read as operators, escaped.
inline std::string escapeRegex(const std::string& name)
{
	std::string out;
	for (char c : name)
	{
		if (std::strchr(".+*?()[]{}|^$\\", c)) out += '\\';
		out += c;
	}
	return out;
}

inline std::string alternatives(const std::vector<std::string>& names)
{
	std::string out;
	for (const std::string& n : names) out += (out.empty() ? "" : "|") + escapeRegex(n);
	return "(" + out + ")";
}

/// Reads argv: --help/-h, --scenes/-s and --kinds/-k (values as separate arguments up to the next option, comma
/// lists, or --kinds=a,b), the rest passed on. `kinds`: the kind names the cases use (anything else is refused).
inline Arguments parseArguments(int argc, char** argv, const std::vector<std::string>& kinds)
{
	Arguments a;
	a.passOn.push_back(argc > 0 ? argv[0] : "quathinge-bench");
	std::vector<std::string> scenes, chosenKinds;
	bool filter = false;
	for (int i = 1; i < argc; ++i)
	{
		const std::string arg = argv[i];
		std::vector<std::string>* list = nullptr;
		std::string inline_;
		for (const char* name : {"--scenes", "-s", "--kinds", "-k"})
		{
			const std::string n = name;
			if (arg == n || arg.rfind(n + "=", 0) == 0)
			{
				list = n == "--scenes" || n == "-s" ? &scenes : &chosenKinds;
				if (arg.size() > n.size()) inline_ = arg.substr(n.size() + 1);
				break;
			}
		}
		if (arg == "--help" || arg == "-h")
			a.help = true;
		else if (list)
		{
			std::vector<std::string> values;
			if (!inline_.empty()) values.push_back(inline_);
			while (inline_.empty() && i + 1 < argc && argv[i + 1][0] != '-') values.push_back(argv[++i]);
			if (values.empty()) a.error = arg + " needs at least one name";
			for (const std::string& v : values)
				for (size_t start = 0; start <= v.size();)
				{
					const size_t comma = std::min(v.find(',', start), v.size());
					if (comma > start) list->push_back(v.substr(start, comma - start));
					start = comma + 1;
				}
		}
		else
		{
			filter = filter || arg.rfind("--benchmark_filter", 0) == 0;
			a.passOn.push_back(arg);
		}
	}
	for (const std::string& k : chosenKinds)
		if (std::find(kinds.begin(), kinds.end(), k) == kinds.end()) a.error = "unknown kind " + k + " (--help lists them)";
	if (filter && (!scenes.empty() || !chosenKinds.empty()))
		a.error = "--scenes/--kinds and --benchmark_filter: give one or the other";
	if (a.error.empty() && (!scenes.empty() || !chosenKinds.empty()))
	{
		// a case with a fixed iteration count is listed and matched with "/iterations:N" after its kind
		const std::string kindPart =
			(chosenKinds.empty() ? std::string("[^/]+") : alternatives(chosenKinds)) + "(/iterations:[0-9]+)?";
		std::vector<std::string> stepScenes;
		bool joints = scenes.empty();  // kinds alone: the per-joint cases too
		for (const std::string& s : scenes)
		{
			if (s == "joint")
				joints = true;
			else
				stepScenes.push_back(s);
		}
		std::string regex;
		if (joints) regex = "^joint/.*/" + kindPart + "$";
		if (!stepScenes.empty() || scenes.empty())
			regex += (regex.empty() ? "" : "|") + std::string("^step/") +
					 (scenes.empty() ? std::string("[^/]+") : alternatives(stepScenes)) + "/" + kindPart + "$";
		a.passOn.push_back("--benchmark_filter=" + regex);
	}
	return a;
}

/// The help text: `caseNames` are every registered case (joint/… and step/…), `manual` where the manual is.
inline std::string helpText(const std::vector<std::string>& caseNames, const std::vector<std::string>& kinds,
							const std::string& manual)
{
	std::vector<std::string> scenes;
	for (const std::string& n : caseNames)
		if (n.rfind("step/", 0) == 0)
		{
			const std::string scene = n.substr(5, n.find('/', 5) - 5);
			if (std::find(scenes.begin(), scenes.end(), scene) == scenes.end()) scenes.push_back(scene);
		}
	std::string text =
		"quathinge-bench: the quaternion hinge against stock, as Google Benchmark cases (" +
		std::to_string(caseNames.size()) +
		" in this build)\n\n"
		"Usage: quathinge-bench [--scenes S...] [--kinds K...] [Google Benchmark options]\n\n"
		"Cases:\n"
		"  joint/<angle>/<config>/<kind>  getInfo1 + getInfo2 of one joint (what the solver asks of it each step) at\n"
		"                                 the hinge angles a0.5 and a3.0 rad; config: free, limit (not reached),\n"
		"                                 limit past its stop, motor, or both; kind: stock 6dof2 quaternion\n"
		"  step/<scene>/<kind>            one world step (stepSimulation, 60 Hz, 10 iterations) after a fixed warm-up,\n"
		"                                 a fixed number of steps timed\n\n"
		"Options (all others go to Google Benchmark, listed below):\n"
		"  -s, --scenes S...   these step scenes (and `joint` for the per-joint cases): -s chain100 ragdolls100 or\n"
		"                      --scenes chain100,ragdolls100; default: every case\n"
		"  -k, --kinds K...    these kinds: -k stock quaternion+stab or --kinds stock,quaternion+stab; default: all\n"
		"  -h, --help          this text\n\n"
		"Step scenes in this build:";
	for (const std::string& s : scenes) text += " " + s;
	text += "\nKinds:";
	for (const std::string& k : kinds) text += " " + k;
	text +=
		"\n  (stock: btHingeConstraint; 6dof2: btGeneric6DofSpring2Constraint as a hinge; quaternion:\n"
		"  btQuaternionHingeConstraint; +stab: with btQuaternionHingeStabilizer; multibody: btMultiBody revolute)\n\n"
		"Example: one step of the 100-link chain, stock against the stabilized quaternion hinge, 5 repetitions:\n"
		"  quathinge-bench --scenes chain100 --kinds stock,quaternion+stab --benchmark_repetitions=5\n\n"
		"The timings: Time is wall-clock and CPU the process's CPU time per case (a joint's getInfo1 + getInfo2 in ns,\n"
		"a world step in us), the mean over the timed iterations; with --benchmark_repetitions the _median and _min\n"
		"rows (the fastest repetition: on a shared machine other work only adds time). Compare kinds as ratios within\n"
		"one run, not across runs or machines. QUATHINGE_BENCH_FTZ=1 sets flush-to-zero and denormals-are-zero.\n"
		"The manual (PERFORMANCE.md: the tables this program makes, demos/make_bench.sh) is in " +
		manual +
		"\n\n"
		"Google Benchmark's options:\n";
	return text;
}
}  // namespace bench
}  // namespace quathinge

#endif
