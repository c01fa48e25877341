// quathinge-sweep --analysis (Sweep.h): per scene × basis × order, the conditioning of the rows' K = J M⁻¹ Jᵀ at
// states of a stabilized run and how Gauss–Seidel sweeps on it converge (docs/ROW_BASIS.md).
#include "Simulation.h"
#include "Sweep.h"

#include <Eigen/Dense>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>

namespace quathinge
{
namespace sweep
{
using namespace quathinge::scenes;

namespace
{
struct Analysis
{
	int rows = 0;
	double residual[3] = {0, 0, 0};  // ‖λ_N − λ*‖_K / ‖λ*‖_K after N = 10, 50, 250 Gauss–Seidel sweeps (cold start)
	// after those sweeps, over the joints: the largest error of the swing rate (rad/s: the relative angular velocity
	// across the hinge axis) and of the pivots' relative velocity (m/s) against the exact solve's, basis-independent;
	// [3]: the exact solve's own (the Baumgarte bias it asks for)
	double swingRate[4] = {0, 0, 0, 0};
	double pivotSpeed[4] = {0, 0, 0, 0};
	double intraCoupling = 0;         // largest |K_ij| / √(K_ii K_jj) between two rows of one joint
	double angularPairCoupling = 0;   // the same between a joint's two angular rows (no linear part)
	double pointAngularCoupling = 0;  // the same between a joint's point row and angular row
	double angularDiagonalRatio = 0;  // largest K_uu / K_vv of a joint's two angular rows (≥ 1)
	double interCoupling = 0;         // the same between rows of two joints
	double blockCondition = 0;        // largest eigenvalue ratio of a joint's own block of K
};
const int kSweeps[3] = {10, 50, 250};

// The K analysis at one state: `states` are the scene's bodies' transforms and velocities (taken from one run of the
// stabilized kind, so every basis is judged at the same poses, on the joints' manifold). The right-hand side is the solver's: b = e − J v_free, v_free the
// velocities after gravity's step.
Analysis analyse(const SceneSpec& scene, const Variant& v, bool angularFirst, const std::vector<btRigidBody*>& states,
				 double dt)
{
	Simulation sim(scene, v.hasBasis ? Kind::Quaternion : v.kind);
	btDiscreteDynamicsWorld& world = sim.world();
	if (v.hasBasis) setBasis(world, v.basis, angularFirst);
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
}  // namespace

void writeAnalysis(std::ostream& csv, const std::vector<std::string>& scenes, const std::vector<Variant>& variants,
				   const std::vector<bool>& orders, const SweepSettings& settings)
{
	csv << "scene,basis,order,sample_time_s,rows,gs_residual_10,gs_residual_50,gs_residual_250,"
		   "swing_rate_10,swing_rate_50,swing_rate_250,swing_rate_exact,pivot_speed_10,pivot_speed_50,"
		   "pivot_speed_250,pivot_speed_exact,"
		   "max_intra_joint_coupling,max_inter_joint_coupling,max_joint_block_condition,"
		   "max_angular_pair_coupling,max_point_angular_coupling,max_angular_diagonal_ratio\n";
	for (const std::string& name : scenes)
	{
		const SceneSpec scene = makeScene(name, 1, settings.models);
		if (!scene.unavailable.empty()) continue;
		const double step = settings.dt > 0 ? settings.dt : sceneStep(scene);
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
		const double length = settings.duration > 0 ? settings.duration : scene.duration;
		int stepsDone = 0;
		for (int sample = 0; sample < 3; ++sample)
		{
			const int target = int(std::lround(length * sample / 3 / step));
			for (; stepsDone < target; ++stepsDone) stockRun->step(step, 250);
			for (const Variant& v : variants)
				for (bool angularFirst : orders)
				{
					if (!v.hasBasis && (angularFirst || v.kind != Kind::Stock)) continue;  // stock: one order; no peer
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
}

}  // namespace sweep
}  // namespace quathinge
