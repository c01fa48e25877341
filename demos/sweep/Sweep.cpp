// quathinge-sweep's variants and job queue (Sweep.h).
#include "Sweep.h"

#include "quathinge/btQuaternionHingeConstraint.h"

#include <atomic>
#include <stdexcept>
#include <thread>

namespace quathinge
{
namespace sweep
{
using scenes::Kind;
using scenes::parseKind;

Variant parseVariant(const std::string& name)
{
	for (int b = 0; b < int(RowBasis::Count); ++b)
		if (name == rowBasisName(RowBasis(b))) return {name, Kind::Quaternion, true, RowBasis(b)};
	try
	{
		return {name, parseKind(name), false, RowBasis::Radial};
	}
	catch (const std::invalid_argument& e)
	{
		throw std::invalid_argument("unknown basis or kind '" + name +
									"' (radial world heavy decoupled jointframe radial-turned "
									"turned-at-static radial-turned45 radial-turned90, or " +
									e.what() + ")");
	}
}

void setBasis(btDiscreteDynamicsWorld& world, RowBasis basis, bool angularFirst)
{
	for (int i = 0; i < world.getNumConstraints(); ++i)
		if (btQuaternionHingeConstraint* q = btQuaternionHingeConstraint::upcast(world.getConstraint(i)))
			SolverRowBasisAccess::set(*q, basis, angularFirst);
}

void runJobs(const std::vector<Job>& jobs, int threads, const std::function<void(const Job&)>& run)
{
	std::atomic<size_t> next{0};
	auto worker = [&]() {
		for (size_t i; (i = next++) < jobs.size();) run(jobs[i]);
	};
	std::vector<std::thread> pool;
	for (int t = 0; t < threads; ++t) pool.emplace_back(worker);
	for (std::thread& t : pool) t.join();
}

}  // namespace sweep
}  // namespace quathinge
