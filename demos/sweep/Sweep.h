// quathinge-sweep's shared pieces (main.cpp): what one run varies (a row basis of the bare quaternion hinge, or a
// whole joint kind: stock and the peers of docs/PEERS.md), the job queue, and the three outputs — the K analysis
// (Analysis.cpp), the matched-state runs and the free runs (Runs.cpp).
#ifndef QUATHINGE_SWEEP_H
#define QUATHINGE_SWEEP_H

#include "JointKinds.h"
#include "SolverRowBasis.h"

#include <btBulletDynamicsCommon.h>

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace quathinge
{
namespace sweep
{
/// A variant: a joint kind by its name (stock, stock+mlcp, multibody-damped, ...: JointKinds.h), or a row basis of
/// the bare quaternion hinge (its RowBasis name).
struct Variant
{
	std::string name;
	scenes::Kind kind = scenes::Kind::Stock;
	bool hasBasis = false;  ///< a row basis of Kind::Quaternion (set through SolverRowBasisAccess)
	RowBasis basis = RowBasis::Radial;
};
/// Throws std::invalid_argument naming the unknown variant.
Variant parseVariant(const std::string& name);
/// Sets every quaternion hinge of `world` to `basis` and the row order.
void setBasis(btDiscreteDynamicsWorld& world, RowBasis basis, bool angularFirst);

struct Job
{
	std::string sceneName;
	Variant variant;
	bool angularFirst;
	int iterations;
};
/// Runs every job on `threads` threads, each taking the next job not yet taken.
void runJobs(const std::vector<Job>& jobs, int threads, const std::function<void(const Job&)>& run);

/// What every output shares: the step (≤ 0: each scene's own), duration (≤ 0: the scene's), models directory.
struct SweepSettings
{
	double dt = -1, duration = -1;
	int jobs = 1;
	std::string models;
};
/// The K analysis per scene × variant × order (Analysis.cpp).
void writeAnalysis(std::ostream& csv, const std::vector<std::string>& scenes, const std::vector<Variant>& variants,
				   const std::vector<bool>& orders, const SweepSettings& settings);
/// Per job with a row basis: stock and the quaternion hinge stepped from the same states (Runs.cpp).
void writeMatched(std::ostream& csv, const std::vector<Job>& queue, const SweepSettings& settings);
/// Per job: one free run (Runs.cpp).
void writeRuns(std::ostream& csv, const std::vector<Job>& queue, const SweepSettings& settings);

}  // namespace sweep
}  // namespace quathinge

#endif
