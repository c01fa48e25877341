// quathinge-sweep: the row-basis sweep of issue 16 (docs/ROW_BASIS.md). Runs scenes × row basis × row order ×
// solver iterations with the bare quaternion hinge (and stock btHingeConstraint at the same iterations) and writes
// one CSV line per run; with --analysis it writes instead, per scene × basis × order, the conditioning of the rows'
// K = J M⁻¹ Jᵀ at the start pose and the spectral radius of the Gauss–Seidel sweep on it; with --matched, per scene ×
// basis × order × iterations, stock and the quaternion hinge stepped from the same states (MatchedStates.h): once on
// stock's own trajectory, once on the quaternion hinge's.
//
// The basis is set through the in-tree hook quathinge::SolverRowBasisAccess (plugin/src/SolverRowBasis.h), not a
// public setter: it is the library's choice of how to present one constraint to the solver.
#include "JointKinds.h"
#include "MatchedStates.h"
#include "SceneSpec.h"
#include "Simulation.h"
#include "SolverRowBasis.h"

#include "quathinge/btQuaternionHingeConstraint.h"

#include <CLI/CLI.hpp>
#include <Eigen/Dense>
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <mutex>
#include <memory>
#include <thread>

using namespace quathinge;
using namespace quathinge::scenes;

namespace
{
struct Variant
{
	std::string name;  // "stock", or a RowBasis name
	bool stock = false;
	RowBasis basis = RowBasis::Radial;
};

Variant parseVariant(const std::string& name)
{
	if (name == "stock") return {name, true, RowBasis::Radial};
	for (int b = 0; b < int(RowBasis::Count); ++b)
		if (name == rowBasisName(RowBasis(b))) return {name, false, RowBasis(b)};
	throw std::invalid_argument("unknown basis '" + name + "' (stock radial world heavy decoupled jointframe radial-turned turned-at-static radial-turned45 radial-turned90)");
}

void setBasis(btDiscreteDynamicsWorld& world, RowBasis basis, bool angularFirst)
{
	for (int i = 0; i < world.getNumConstraints(); ++i)
		if (btQuaternionHingeConstraint* q = btQuaternionHingeConstraint::upcast(world.getConstraint(i)))
			SolverRowBasisAccess::set(*q, basis, angularFirst);
}

// ---- K analysis -------------------------------------------------------------------------------------------------

struct Analysis
{
	int rows = 0;
	double residual[3] = {0, 0, 0};  // ‖λ_N − λ*‖_K / ‖λ*‖_K after N = 10, 50, 250 Gauss–Seidel sweeps (cold start)
	// after those sweeps, over the joints: the largest error of the swing rate (rad/s: the relative angular velocity
	// across the hinge axis) and of the pivots' relative velocity (m/s) against the exact solve's, basis-independent;
	// [3]: the exact solve's own (the Baumgarte bias it asks for)
	double swingRate[4] = {0, 0, 0, 0};
	double pivotSpeed[4] = {0, 0, 0, 0};
	double intraCoupling = 0;        // largest |K_ij| / √(K_ii K_jj) between two rows of one joint
	double angularPairCoupling = 0;  // the same between a joint's two angular rows (no linear part)
	double pointAngularCoupling = 0; // the same between a joint's point row and angular row
	double angularDiagonalRatio = 0; // largest K_uu / K_vv of a joint's two angular rows (≥ 1)
	double interCoupling = 0;        // the same between rows of two joints
	double blockCondition = 0;       // largest eigenvalue ratio of a joint's own block of K
};
const int kSweeps[3] = {10, 50, 250};

// The K analysis at one state: `states` are the scene's bodies' transforms and velocities (taken from one run of the
// stabilized kind, so every basis is judged at the same poses, on the joints' manifold). The right-hand side is the solver's: b = e − J v_free, v_free the
// velocities after gravity's step.
Analysis analyse(const SceneSpec& scene, const Variant& v, bool angularFirst, const std::vector<btRigidBody*>& states,
				 double dt)
{
	Simulation sim(scene, v.stock ? Kind::Stock : Kind::Quaternion);
	btDiscreteDynamicsWorld& world = sim.world();
	if (!v.stock) setBasis(world, v.basis, angularFirst);
	for (size_t i = 0; i < sim.bodies.size() && i < states.size(); ++i)
	{
		sim.bodies[i]->setCenterOfMassTransform(states[i]->getCenterOfMassTransform());
		sim.bodies[i]->setLinearVelocity(states[i]->getLinearVelocity());
		sim.bodies[i]->setAngularVelocity(states[i]->getAngularVelocity());
		sim.bodies[i]->updateInertiaTensor();
	}
	// every dynamic body an index (6 velocity coordinates each); static bodies none
	std::vector<const btRigidBody*> bodies;
	auto indexOf = [&](const btRigidBody* b) -> int {
		if (b->getInvMass() == 0 && b->getInvInertiaDiagLocal().isZero()) return -1;
		for (size_t i = 0; i < bodies.size(); ++i)
			if (bodies[i] == b) return int(i);
		bodies.push_back(b);
		return int(bodies.size() - 1);
	};
	struct Row
	{
		int joint, a, b;
		double j[12];
		double error;
	};
	std::vector<Row> rows;
	const int kStride = 16, kMax = 8;
	for (int c = 0; c < world.getNumConstraints(); ++c)
	{
		btTypedConstraint* con = world.getConstraint(c);
		btTypedConstraint::btConstraintInfo1 info1;
		con->getInfo1(&info1);
		if (info1.m_numConstraintRows == 0 || info1.m_numConstraintRows > kMax) continue;
		std::vector<btScalar> j1l(kMax * kStride, 0), j1a(kMax * kStride, 0), j2l(kMax * kStride, 0),
			j2a(kMax * kStride, 0), err(kMax * kStride, 0), cfm(kMax * kStride, 0), lo(kMax * kStride, -SIMD_INFINITY),
			hi(kMax * kStride, SIMD_INFINITY);
		btTypedConstraint::btConstraintInfo2 info2;
		info2.fps = btScalar(1 / dt);
		info2.erp = btScalar(0.2);
		info2.m_J1linearAxis = j1l.data();
		info2.m_J1angularAxis = j1a.data();
		info2.m_J2linearAxis = j2l.data();
		info2.m_J2angularAxis = j2a.data();
		info2.rowskip = kStride;
		info2.m_constraintError = err.data();
		info2.cfm = cfm.data();
		info2.m_lowerLimit = lo.data();
		info2.m_upperLimit = hi.data();
		info2.m_numIterations = 10;
		info2.m_damping = 1;
		con->getInfo2(&info2);
		const int ia = indexOf(&con->getRigidBodyA()), ib = indexOf(&con->getRigidBodyB());
		for (int r = 0; r < info1.m_numConstraintRows; ++r)
		{
			// the bilateral rows (unbounded; limits and drives are bounded: left out)
			if (lo[size_t(r * kStride)] > -SIMD_INFINITY || hi[size_t(r * kStride)] < SIMD_INFINITY) continue;
			Row row{c, ia, ib, {}, double(err[size_t(r * kStride)])};
			for (int k = 0; k < 3; ++k)
			{
				row.j[k] = j1l[size_t(r * kStride + k)];
				row.j[3 + k] = j1a[size_t(r * kStride + k)];
				row.j[6 + k] = j2l[size_t(r * kStride + k)];
				row.j[9 + k] = j2a[size_t(r * kStride + k)];
			}
			rows.push_back(row);
		}
	}
	const size_t n = rows.size();
	// M⁻¹ Jᵀ per row, per body side
	auto minvTimes = [&](const Row& row, int side, double out[6]) {
		const btRigidBody* body = bodies[size_t(side == 0 ? row.a : row.b)];
		const double* j = row.j + 6 * side;
		const btMatrix3x3& inv = body->getInvInertiaTensorWorld();
		for (int k = 0; k < 3; ++k) out[k] = double(body->getInvMass()) * j[k];
		for (int k = 0; k < 3; ++k)
			out[3 + k] = double(inv[k][0]) * j[3] + double(inv[k][1]) * j[4] + double(inv[k][2]) * j[5];
	};
	std::vector<std::vector<double>> K(n, std::vector<double>(n, 0));
	for (size_t r = 0; r < n; ++r)
		for (int sr = 0; sr < 2; ++sr)
		{
			const int br = sr == 0 ? rows[r].a : rows[r].b;
			if (br < 0) continue;
			double m[6];
			minvTimes(rows[r], sr, m);
			for (size_t c = 0; c < n; ++c)
				for (int sc = 0; sc < 2; ++sc)
				{
					const int bc = sc == 0 ? rows[c].a : rows[c].b;
					if (bc != br) continue;
					const double* j = rows[c].j + 6 * sc;
					double d = 0;
					for (int k = 0; k < 6; ++k) d += m[k] * j[k];
					K[r][c] += d;
				}
		}
	Analysis out;
	out.rows = int(n);
	for (size_t r = 0; r < n; ++r)
		for (size_t c = 0; c < n; ++c)
		{
			if (r == c || K[r][r] <= 0 || K[c][c] <= 0) continue;
			const double coupling = std::fabs(K[r][c]) / std::sqrt(K[r][r] * K[c][c]);
			auto angularRow = [&](size_t i) {
				return rows[i].j[0] == 0 && rows[i].j[1] == 0 && rows[i].j[2] == 0 && rows[i].j[6] == 0 &&
					   rows[i].j[7] == 0 && rows[i].j[8] == 0;
			};
			if (rows[r].joint == rows[c].joint)
			{
				if (angularRow(r) && angularRow(c))
				{
					out.angularPairCoupling = std::max(out.angularPairCoupling, coupling);
					out.angularDiagonalRatio = std::max(out.angularDiagonalRatio, K[r][r] / K[c][c]);
				}
				else if (angularRow(r) != angularRow(c))
					out.pointAngularCoupling = std::max(out.pointAngularCoupling, coupling);
			}
			if (rows[r].joint == rows[c].joint) out.intraCoupling = std::max(out.intraCoupling, coupling);
			else out.interCoupling = std::max(out.interCoupling, coupling);
		}
	Eigen::MatrixXd dense{Eigen::Index(n), Eigen::Index(n)};  // K for Eigen's eigenvalues and LU
	for (size_t r = 0; r < n; ++r)
		for (size_t c = 0; c < n; ++c) dense(Eigen::Index(r), Eigen::Index(c)) = K[r][c];
	// each joint's own block: its eigenvalue ratio
	for (size_t start = 0; start < n;)
	{
		size_t end = start;
		while (end < n && rows[end].joint == rows[start].joint) ++end;
		const Eigen::Index size = Eigen::Index(end - start);
		const Eigen::VectorXd e =
			Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(dense.block(Eigen::Index(start), Eigen::Index(start), size, size),
														   Eigen::EigenvaluesOnly)
				.eigenvalues();
		const double lo = e.minCoeff(), hi = e.maxCoeff();
		out.blockCondition = std::max(out.blockCondition, lo > 0 ? hi / lo : INFINITY);
		start = end;
	}
	// b = e − J v_free; λ* = K⁻¹ b (Eigen's LU with partial pivoting); then Gauss–Seidel from λ = 0, as the
	// solver's first iteration (joints are not warm-started), in the rows' order
	std::vector<double> b(n), star(n);
	auto velocity = [&](int body, double out[6]) {
		const btRigidBody* rb = bodies[size_t(body)];
		const btVector3 lin = rb->getLinearVelocity() + rb->getGravity() * btScalar(dt);
		const btVector3 ang = rb->getAngularVelocity();
		for (int k = 0; k < 3; ++k)
		{
			out[k] = double(lin[k]);
			out[3 + k] = double(ang[k]);
		}
	};
	for (size_t r = 0; r < n; ++r)
	{
		double jv = 0, vel[6];
		for (int side = 0; side < 2; ++side)
		{
			const int body = side == 0 ? rows[r].a : rows[r].b;
			if (body < 0) continue;
			velocity(body, vel);
			for (int k = 0; k < 6; ++k) jv += rows[r].j[6 * side + k] * vel[k];
		}
		b[r] = rows[r].error - jv;
	}
	{
		const Eigen::VectorXd x = dense.partialPivLu().solve(Eigen::Map<const Eigen::VectorXd>(b.data(), Eigen::Index(n)));
		for (size_t i = 0; i < n; ++i) star[i] = x[Eigen::Index(i)];
	}
	// the joints' velocity errors after impulses λ: v = v_free + M⁻¹ Jᵀ λ per body, then each measured joint's swing
	// rate and pivot speed (from its frames, not from the rows: the same measure for every basis)
	std::vector<btVector3> exactSwing, exactPivot;  // per joint, at λ* (set first)
	auto jointRates = [&](const std::vector<double>& lambda, double& swing, double& pivot) {
		std::vector<btVector3> lin(bodies.size()), ang(bodies.size());
		for (size_t i = 0; i < bodies.size(); ++i)
		{
			double vel[6];
			velocity(int(i), vel);
			lin[i].setValue(btScalar(vel[0]), btScalar(vel[1]), btScalar(vel[2]));
			ang[i].setValue(btScalar(vel[3]), btScalar(vel[4]), btScalar(vel[5]));
		}
		for (size_t r = 0; r < n; ++r)
			for (int side = 0; side < 2; ++side)
			{
				const int body = side == 0 ? rows[r].a : rows[r].b;
				if (body < 0) continue;
				double m[6];
				minvTimes(rows[r], side, m);
				lin[size_t(body)] += btVector3(btScalar(m[0]), btScalar(m[1]), btScalar(m[2])) * btScalar(lambda[r]);
				ang[size_t(body)] += btVector3(btScalar(m[3]), btScalar(m[4]), btScalar(m[5])) * btScalar(lambda[r]);
			}
		swing = pivot = 0;
		const bool exact = exactSwing.empty();
		for (size_t k = 0; k < sim.joints.size(); ++k)
		{
			const MeasuredJoint& j = sim.joints[k];
			const int ia = indexOf(j.a), ib = indexOf(j.b);
			const btVector3 zero(0, 0, 0);
			const btVector3 ra = j.a->getCenterOfMassTransform().getBasis() * j.frameA.getOrigin();
			const btVector3 rb = j.b->getCenterOfMassTransform().getBasis() * j.frameB.getOrigin();
			const btVector3 va = ia < 0 ? zero : lin[size_t(ia)] + ang[size_t(ia)].cross(ra);
			const btVector3 vb = ib < 0 ? zero : lin[size_t(ib)] + ang[size_t(ib)].cross(rb);
			const btVector3 wa = ia < 0 ? zero : ang[size_t(ia)], wb = ib < 0 ? zero : ang[size_t(ib)];
			const btVector3 axis = j.a->getCenterOfMassTransform().getBasis() * j.frameA.getBasis().getColumn(2);
			const btVector3 rel = wb - wa;
			const btVector3 swingRate = rel - axis * rel.dot(axis), pivotRate = vb - va;
			if (exact)
			{
				exactSwing.push_back(swingRate);
				exactPivot.push_back(pivotRate);
				swing = std::max(swing, double(swingRate.length()));
				pivot = std::max(pivot, double(pivotRate.length()));
			}
			else
			{
				swing = std::max(swing, double((swingRate - exactSwing[k]).length()));
				pivot = std::max(pivot, double((pivotRate - exactPivot[k]).length()));
			}
		}
	};
	auto kNorm = [&](const std::vector<double>& x) {
		double sum = 0;
		for (size_t r = 0; r < n; ++r)
			for (size_t c = 0; c < n; ++c) sum += x[r] * K[r][c] * x[c];
		return std::sqrt(std::max(0.0, sum));
	};
	const double starNorm = kNorm(star);
	std::vector<double> lambda(n, 0), diff(n);
	jointRates(star, out.swingRate[3], out.pivotSpeed[3]);  // the exact solve's rates: what the others are judged by
	int done = 0;
	for (int sweep = 1; sweep <= kSweeps[2]; ++sweep)
	{
		for (size_t r = 0; r < n; ++r)
		{
			if (K[r][r] <= 0) continue;
			double kx = 0;
			for (size_t c = 0; c < n; ++c) kx += K[r][c] * lambda[c];
			lambda[r] += (b[r] - kx) / K[r][r];
		}
		if (sweep == kSweeps[done])
		{
			for (size_t r = 0; r < n; ++r) diff[r] = lambda[r] - star[r];
			jointRates(lambda, out.swingRate[done], out.pivotSpeed[done]);
			out.residual[done++] = starNorm > 0 ? kNorm(diff) / starNorm : 0;
		}
	}
	return out;
}

struct Job
{
	std::string sceneName;
	Variant variant;
	bool angularFirst;
	int iterations;
};

// Runs every job on `threads` threads, each taking the next job not yet taken.
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
}  // namespace

int main(int argc, char** argv)
{
	CLI::App app("quathinge-sweep: row basis × order × iterations over scenes, CSV out (docs/ROW_BASIS.md)");
	std::vector<std::string> sceneList = {"inertia_ratio"};
	std::vector<std::string> basisList = {"stock",      "radial",        "world",           "heavy",
										  "decoupled", "jointframe",    "radial-turned",   "turned-at-static"};
	std::vector<std::string> orderList = {"point-first", "angular-first"};
	std::vector<int> iterationList = {10, 20, 50, 100, 250};
	double dt = -1, duration = -1;
	int jobs = 1;
	std::string out = "sweep.csv", models;
	bool analysis = false, matched = false;
	app.add_option("-s,--scenes", sceneList, "scene names (quathinge-compare --list), inertia_ratio_<N> for the family")
		->capture_default_str();
	app.add_option("-b,--bases", basisList, "stock radial world heavy decoupled jointframe radial-turned turned-at-static radial-turned45 radial-turned90")->capture_default_str();
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
	CLI11_PARSE(app, argc, argv);
	if (models.empty()) models = defaultModelsDir();

	std::vector<Variant> variants;
	for (const std::string& b : basisList) variants.push_back(parseVariant(b));
	std::vector<bool> orders;
	for (const std::string& o : orderList)
	{
		if (o != "point-first" && o != "angular-first") throw std::invalid_argument("unknown order '" + o + "'");
		orders.push_back(o == "angular-first");
	}

	std::ofstream csv(out);
	if (analysis)
	{
		csv << "scene,basis,order,sample_time_s,rows,gs_residual_10,gs_residual_50,gs_residual_250,"
			   "swing_rate_10,swing_rate_50,swing_rate_250,swing_rate_exact,pivot_speed_10,pivot_speed_50,"
			   "pivot_speed_250,pivot_speed_exact,"
			   "max_intra_joint_coupling,max_inter_joint_coupling,max_joint_block_condition,"
			   "max_angular_pair_coupling,max_point_angular_coupling,max_angular_diagonal_ratio\n";
		for (const std::string& name : sceneList)
		{
			const SceneSpec scene = makeScene(name, 1, models);
			if (!scene.unavailable.empty()) continue;
			const double step = dt > 0 ? dt : sceneStep(scene);
			// the states: a run of the stabilized quaternion hinge (on the joints' manifold to 1e-4 m) at 250
			// iterations, sampled at 0, 1/3 and 2/3 of the scene's duration
			std::unique_ptr<Simulation> stockRun;
			try
			{
				stockRun.reset(new Simulation(scene, Kind::QuaternionStabilized));
			}
			catch (const std::exception& e)
			{
				std::cerr << name << ": " << e.what() << '\n';
				continue;
			}
			const double length = duration > 0 ? duration : scene.duration;
			int stepsDone = 0;
			for (int sample = 0; sample < 3; ++sample)
			{
				const int target = int(std::lround(length * sample / 3 / step));
				for (; stepsDone < target; ++stepsDone) stockRun->step(step, 250);
				for (const Variant& v : variants)
					for (bool angularFirst : orders)
					{
						if (v.stock && angularFirst) continue;
						Analysis a;
						try
						{
							a = analyse(scene, v, angularFirst, stockRun->bodies, step);
						}
						catch (const std::exception& e)
						{
							std::cerr << name << ": " << e.what() << '\n';
							continue;
						}
						csv << name << ',' << v.name << ',' << (angularFirst ? "angular-first" : "point-first") << ','
							<< stepsDone * step << ',' << a.rows << ',' << fmt::format("{:.3e}", a.residual[0]) << ','
							<< fmt::format("{:.3e}", a.residual[1]) << ',' << fmt::format("{:.3e}", a.residual[2]) << ',';
						for (int k = 0; k < 4; ++k) csv << fmt::format("{:.3e}", a.swingRate[k]) << ',';
						for (int k = 0; k < 4; ++k) csv << fmt::format("{:.3e}", a.pivotSpeed[k]) << ',';
						csv
							<< fmt::format("{:.4f}", a.intraCoupling) << ',' << fmt::format("{:.4f}", a.interCoupling)
							<< ',' << fmt::format("{:.4g}", a.blockCondition) << ','
							<< fmt::format("{:.4f}", a.angularPairCoupling) << ','
							<< fmt::format("{:.4f}", a.pointAngularCoupling) << ','
							<< fmt::format("{:.4g}", a.angularDiagonalRatio) << '\n';
					}
			}
		}
		return 0;
	}

	// every run of scene × iterations × basis × order (stock has one order)
	std::vector<Job> queue;
	for (const std::string& name : sceneList)
		for (int iterations : iterationList)
			for (const Variant& v : variants)
				for (bool angularFirst : orders)
				{
					if (v.stock && angularFirst) continue;
					queue.push_back({name, v, angularFirst, iterations});
				}

	if (matched)
	{
		// one line per scene × basis × order × iterations × leader: both kinds' errors, the follower's from the
		// leader's state before every step
		csv << "scene,basis,order,dt,iterations,leader,skipped,blew_up,steps,stock_max_separation_m,"
			   "stock_rms_separation_m,stock_max_misalignment_deg,stock_rms_misalignment_deg,"
			   "quaternion_max_separation_m,quaternion_rms_separation_m,quaternion_max_misalignment_deg,"
			   "quaternion_rms_misalignment_deg\n";
		std::vector<Job> matchedJobs;  // the quaternion hinge's runs (each is compared with stock's here)
		std::copy_if(queue.begin(), queue.end(), std::back_inserter(matchedJobs),
					 [](const Job& job) { return !job.variant.stock; });
		std::mutex lock;
		runJobs(matchedJobs, jobs, [&](const Job& job) {
			const SceneSpec scene = makeScene(job.sceneName, 1, models);
			const double step = dt > 0 ? dt : sceneStep(scene);
			auto prepare = [&job](btDiscreteDynamicsWorld& world) {
				setBasis(world, job.variant.basis, job.angularFirst);  // touches only quaternion hinges
			};
			for (bool stockLeads : {true, false})
			{
				const Kind leader = stockLeads ? Kind::Stock : Kind::Quaternion;
				const Kind follower = stockLeads ? Kind::Quaternion : Kind::Stock;
				const MatchedRun run = runMatched(scene, leader, follower, step, job.iterations, duration, prepare);
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
				std::cout << fmt::format("{:<22} {:<11} {:>4} it  on {}'s states: max sep stock {:.3e} "
										 "quaternion {:.3e} m\n",
										 job.sceneName, job.variant.name, job.iterations,
										 stockLeads ? "stock" : "quaternion", stock.maxSeparation,
										 quaternion.maxSeparation)
						  << std::flush;
			}
		});
		return 0;
	}

	csv << "scene,basis,order,dt,iterations,skipped,max_separation_m,rms_separation_m,max_misalignment_deg,"
		   "rms_misalignment_deg,energy_drift,max_out_of_plane_rad,blew_up,cpu_per_sim_s,max_joint_rms_swing_rate,"
		   "swing_mean_over_rms\n";
	std::mutex lock;
	runJobs(queue, jobs, [&](const Job& job) {
		const SceneSpec scene = makeScene(job.sceneName, 1, models);
		RunSettings settings;
		settings.dt = dt > 0 ? dt : sceneStep(scene);
		settings.iterations = job.iterations;
		settings.duration = duration;
		settings.reference = false;
		if (!job.variant.stock)
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
		const Metrics m = runScene(scene, job.variant.stock ? Kind::Stock : Kind::Quaternion, settings);
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
			<< swingBias << '\n';
		csv.flush();
		std::cout << fmt::format("{:<22} {:<11} {:<13} {:>4} it  max sep {:.3e} m  max mis {:.3e} deg  oop {:.4f} rad{}\n",
								 m.scene, job.variant.name, job.angularFirst ? "angular-first" : "point-first",
								 m.iterations, m.maxSeparation, m.maxMisalignmentDeg, m.maxOutOfPlaneRad,
								 m.blewUp ? "  BLEW UP" : "")
				  << std::flush;
	});
	return 0;
}
