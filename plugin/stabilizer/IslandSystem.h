// The island's linear system (docs/MATH.md Q13, Q14): the directions M⁻¹ Jᵀ, K = J M⁻¹ Jᵀ + ε s I assembled in
// blocks, its factorization (BlockLDLT on trees, SparseLDLT with loops) and the solve λ = K⁻¹(−r) with the bodies'
// deltas Δ = M⁻¹ Jᵀ λ.
#ifndef QUATHINGE_STABILIZER_ISLAND_SYSTEM_H
#define QUATHINGE_STABILIZER_ISLAND_SYSTEM_H

#include "CompilerExtensions.h"
#include "IslandBodies.h"
#include "StabilizerIsland.h"

#include <Eigen/Cholesky>

namespace quathinge
{
namespace stabilizer
{
// Smallest pivot BlockLDLT accepts, relative to the island's scale s: far below ε s (1e-9 s by default), far above
// the rounding noise of a singular pivot in double (~1e-16 s).
const double kPivotFloor = 1e-13;

// M⁻¹ Jᵀ per joint side (its angular part h; the linear part is linearSign·m⁻¹), at the current J and inertias.
template <int R>
void computeDirections(BlockIsland<R>& island)
{
	if (island.inverseMassesStale) loadInverseMasses(island);
	for (size_t j = 0; j < island.joints.size(); ++j)
	{
		const JointSlot& js = island.joints[j];
		JointBlock<R>& jb = island.blocks[j];
		for (int s = 0; s < 2; ++s)
			if (js.body[s] >= 0)
				jb.h[s].noalias() = island.bodies[js.body[s]].invInertia *
									jb.jacobian.template block<R, 3>(0, 6 * s + 3).transpose();
	}
}

// dst (+)= A h for one joint side: A = the angular columns [first, first + 3) of a joint's J (R rows), h = M_b⁻¹ Aᵀ's
// angular part (3 × R). lowerOnly: only the entries on or below the diagonal (a diagonal block of K: nothing reads the
// others, see BlockLDLT.cpp), from the SSE2 pair holding the diagonal entry down. Column c is Σ_k A's column k h(k, c).
template <int R, bool lowerOnly, bool accumulate>
inline void addSideProduct(Block<R>& dst, const JointJacobian<R>& jacobian, int first,
						   const Eigen::Matrix<double, 3, R>& h)
{
	constexpr int kStorage = BlockShape<R>::kStorageRows;
	unroll<R>([&](auto ci) {
		constexpr int c = decltype(ci)::value;
		constexpr int top = lowerOnly ? c / 2 * 2 : 0;
		constexpr int rows = kStorage - top;
		auto column = dst.col(c).template segment<rows>(top);
		const auto sum = (jacobian.col(first).template segment<rows>(top) * h(0, c) +
						  jacobian.col(first + 1).template segment<rows>(top) * h(1, c) +
						  jacobian.col(first + 2).template segment<rows>(top) * h(2, c));
		if constexpr (accumulate) column += sum;
		else column = sum;
	});
}

// A contact slot's diagonal block (IslandContacts.h): its angular products as a joint's, and its linear part (n per
// row, not ±I) as L diag(m⁻¹) Lᵀ; its rows in the system into trace and activeRows.
template <int R>
void assembleContactDiagonal(const BlockIsland<R>& island, const JointSlot& js, const JointBlock<R>& jb, Block<R>& d,
							 double& trace, int& activeRows)
{
	d.setZero();
	for (int s = 0; s < 2; ++s)
	{
		if (js.body[s] < 0) continue;
		addSideProduct<R, false, true>(d, jb.jacobian, 6 * s + 3, jb.h[s]);
		const auto linear = jb.jacobian.template block<R, 3>(0, 6 * s);
		d.template topLeftCorner<R, R>().noalias() += linear * island.bodies[js.body[s]].invMass.asDiagonal() * linear.transpose();
	}
	for (int r = 0; r < R; ++r)
		if (js.contactTouched & (1u << r))
		{
			trace += d(r, r);
			++activeRows;
		}
}

// A coupling with a general linear part on one side (a contact slot, a locked 6-dof): J_i,lin diag(m⁻¹) J_j,linᵀ (a
// joint's linear part, ±I or 0, is in its stored J as well).
template <int R>
void addContactLinearProduct(const BlockIsland<R>& island, const Coupling& c, Block<R>& b)
{
	const auto linearI = island.blocks[c.i].jacobian.template block<R, 3>(0, 6 * c.sideI);
	const auto linearJ = island.blocks[c.j].jacobian.template block<R, 3>(0, 6 * c.sideJ);
	b.template topLeftCorner<R, R>().noalias() +=
		linearI * island.bodies[island.joints[c.i].body[c.sideI]].invMass.asDiagonal() * linearJ.transpose();
}

// K = J M⁻¹ Jᵀ + regularization into island.k (the directions must be current). Returns the scale s.
// Per pair of joint sides on body b: J_i M_b⁻¹ J_jᵀ = σ_i σ_j diag(m_b⁻¹) (top-left 3×3) + A_i h_j.
template <int R>
double assemble(BlockIsland<R>& island, double regularization)
{
	double trace = 0;
	int activeRows = 0;
	for (size_t j = 0; j < island.joints.size(); ++j)
	{
		const JointSlot& js = island.joints[j];
		const JointBlock<R>& jb = island.blocks[j];
		Block<R>& d = island.k.diag[j];
		if (QUATHINGE_UNLIKELY(js.contact >= 0))
		{
			assembleContactDiagonal(island, js, jb, d, trace, activeRows);
			continue;
		}
		// the lower triangle only (whole storage columns: their storage rows are zero in J)
		bool first = true;
		for (int s = 0; s < 2; ++s)
		{
			if (js.body[s] < 0) continue;
			if (first) addSideProduct<R, true, false>(d, jb.jacobian, 6 * s + 3, jb.h[s]);
			else addSideProduct<R, true, true>(d, jb.jacobian, 6 * s + 3, jb.h[s]);
			first = false;
			if (js.linearSign[s] != 0) d.template topLeftCorner<3, 3>().diagonal() += island.bodies[js.body[s]].invMass;
			else if (QUATHINGE_UNLIKELY(js.generalLinear()))  // a locked 6-dof: L diag(m⁻¹) Lᵀ
			{
				const auto linear = jb.jacobian.template block<R, 3>(0, 6 * s);
				d.template topLeftCorner<R, R>().noalias() +=
					linear * island.bodies[js.body[s]].invMass.asDiagonal() * linear.transpose();
			}
		}
		if (first) d.setZero();  // no movable side (not in an island; kept total)
		for (int r = 0; r < js.bilateralRows; ++r) trace += d(r, r);
		activeRows += js.bilateralRows;
		if (js.limitSlot && js.limitActive)
		{
			trace += d(js.bilateralRows, js.bilateralRows);
			++activeRows;
		}
	}
	for (Block<R>& b : island.k.lower) b.setZero();
	const bool generalLinear = island.generalLinear;
	for (const Coupling& c : island.couplings)
	{
		const JointSlot& ji = island.joints[c.i];
		const JointSlot& jj = island.joints[c.j];
		Block<R>& b = island.k.lower[c.block];
		addSideProduct<R, false, true>(b, island.blocks[c.i].jacobian, 6 * c.sideI + 3, island.blocks[c.j].h[c.sideJ]);
		if (generalLinear && (ji.generalLinear() || jj.generalLinear()))  // a contact's or locked 6-dof's linear part
		{
			addContactLinearProduct(island, c, b);
			continue;
		}
		const double sign = ji.linearSign[c.sideI] * jj.linearSign[c.sideJ];
		if (sign != 0)
			b.template topLeftCorner<3, 3>().diagonal() += sign * island.bodies[ji.body[c.sideI]].invMass;
	}
	// ε s on active rows; s on padding and inactive limit rows (their J rows are zero).
	const double scale = (activeRows > 0 && trace > 0) ? trace / activeRows : 1.0;
	for (size_t j = 0; j < island.joints.size(); ++j)
	{
		JointSlot& js = island.joints[j];
		Block<R>& d = island.k.diag[j];
		if (QUATHINGE_UNLIKELY(js.contact >= 0))
		{
			for (int r = 0; r < R; ++r)
				d(r, r) = (js.contactTouched & (1u << r)) ? d(r, r) + regularization * scale : scale;
			js.contactActiveInFactor = js.contactTouched;
			continue;
		}
		const int activeEnd = js.bilateralRows + ((js.limitSlot && js.limitActive) ? 1 : 0);
		for (int r = 0; r < R; ++r) d(r, r) = r < activeEnd ? d(r, r) + regularization * scale : scale;
		js.limitActiveInFactor = js.limitActive;
	}
	return scale;
}

// Assembles and factorizes K at the current state. False if the factorization failed.
template <int R>
bool refactorize(BlockIsland<R>& island, double regularization, ProjectionResult& result)
{
	computeDirections(island);
	const double scale = assemble(island, regularization);
	++result.factorizations;
	if (island.useSparse)
	{
		if (island.sparse->factorize(island.k)) return true;
		++result.numericalIssues;
		return false;
	}
	result.numericalIssues += island.block.factorize(island.k, kPivotFloor * scale);
	return true;
}

// λ := −r, r = C (the position stage) or J v (the velocity stage): the right-hand side of K λ = −r.
template <int R>
void loadRightHandSide(BlockIsland<R>& island, BlockVector<R> JointBlock<R>::*rhs)
{
	for (size_t j = 0; j < island.joints.size(); ++j) island.lambda[j] = -(island.blocks[j].*rhs);
}

// λ := K⁻¹ λ in place with the current factors.
template <int R>
void solveInPlace(BlockIsland<R>& island, ProjectionResult& result)
{
	if (island.useSparse) island.sparse->template solve<R>(island.lambda.data());
	else island.block.solve(island.k, island.lambda.data());
	++result.solves;
}

// Δ_b = Σ M_b⁻¹ J_bᵀ λ per body (into IslandBody::delta), from island.lambda.
template <int R>
void accumulateDeltas(BlockIsland<R>& island)
{
	for (IslandBody& b : island.bodies) b.delta.setZero();
	for (size_t j = 0; j < island.joints.size(); ++j)
	{
		const JointSlot& js = island.joints[j];
		const JointBlock<R>& jb = island.blocks[j];
		const BlockVector<R>& lambda = island.lambda[j];
		for (int s = 0; s < 2; ++s)
		{
			if (js.body[s] < 0) continue;
			IslandBody& b = island.bodies[js.body[s]];
			if (js.linearSign[s] != 0) b.delta.head<3>() += js.linearSign[s] * b.invMass.cwiseProduct(lambda.template head<3>());
			else if (js.generalLinear())  // a contact slot's linear part is n per row, a locked 6-dof's frame A's axes
				b.delta.head<3>() += b.invMass.cwiseProduct(
					jb.jacobian.template block<R, 3>(0, 6 * s).transpose() * lambda.template head<R>());
			b.delta.tail<3>().noalias() += jb.h[s] * lambda.template head<R>();
		}
	}
}

// λ = K⁻¹(−r) with the current factors, r = C (the position stage) or J v (the velocity stage), then
// Δ_b = Σ M_b⁻¹ J_bᵀ λ per body (into IslandBody::delta).
template <int R>
void solveDeltas(BlockIsland<R>& island, BlockVector<R> JointBlock<R>::*rhs, ProjectionResult& result)
{
	loadRightHandSide(island, rhs);
	solveInPlace(island, result);
	accumulateDeltas(island);
}

// Limit rows that K was factorized with and that are out of the system now, at most this many: a solve without them
// costs 2 + (their number) solves with the factors, against a new assembly and factorization (about 6 solves' worth).
const int kMaxDroppedRows = 4;

// solveDeltas for the velocity stage when limit rows of the factorized K are out of it now (α̇ = 0 applies only to a
// joint still moving past its stop: IslandRows.h), without a new factorization. With E the unit columns of the dropped
// rows d, the system without them is K λ = b − E μ with λ_d = 0 (the other rows' equations unchanged):
// y = K⁻¹ b, C = Eᵀ K⁻¹ E (a principal block of K⁻¹: positive definite), μ = C⁻¹ y_d, then λ = K⁻¹(b − E μ)
// (the capacitance form of removing rows, Woodbury). False, having changed nothing, when more than kMaxDroppedRows rows
// are out or a limit row is in that K does not have: the caller factorizes.
template <int R>
bool solveDeltasWithoutDroppedRows(BlockIsland<R>& island, BlockVector<R> JointBlock<R>::*rhs, ProjectionResult& result)
{
	int joint[kMaxDroppedRows], row[kMaxDroppedRows];
	int dropped = 0;
	for (size_t j = 0; j < island.joints.size(); ++j)
	{
		const JointSlot& js = island.joints[j];
		if (js.contact >= 0 && js.contactTouched != js.contactActiveInFactor) return false;  // a contact row K lacks
		if (!js.limitSlot || js.limitActive == js.limitActiveInFactor) continue;
		if (js.limitActive || dropped == kMaxDroppedRows) return false;  // a row K lacks, or too many out
		joint[dropped] = int(j);
		row[dropped] = js.bilateralRows;
		++dropped;
	}
	// C on the dropped rows, the identity on the unused ones (fixed size: no allocation)
	Eigen::Matrix<double, kMaxDroppedRows, kMaxDroppedRows> c =
		Eigen::Matrix<double, kMaxDroppedRows, kMaxDroppedRows>::Identity();
	for (int b = 0; b < dropped; ++b)
	{
		for (BlockVector<R>& l : island.lambda) l.setZero();
		island.lambda[size_t(joint[b])][row[b]] = 1;
		solveInPlace(island, result);
		for (int a = 0; a < dropped; ++a) c(a, b) = island.lambda[size_t(joint[a])][row[a]];
	}
	Eigen::Matrix<double, kMaxDroppedRows, 1> y = Eigen::Matrix<double, kMaxDroppedRows, 1>::Zero();
	loadRightHandSide(island, rhs);
	solveInPlace(island, result);
	for (int a = 0; a < dropped; ++a) y[a] = island.lambda[size_t(joint[a])][row[a]];
	const Eigen::Matrix<double, kMaxDroppedRows, 1> mu = c.ldlt().solve(y);
	loadRightHandSide(island, rhs);
	for (int a = 0; a < dropped; ++a) island.lambda[size_t(joint[a])][row[a]] -= mu[a];
	solveInPlace(island, result);
	for (int a = 0; a < dropped; ++a) island.lambda[size_t(joint[a])][row[a]] = 0;  // out exactly, not to rounding
	accumulateDeltas(island);
	return true;
}

// The velocity stage's solve with the current factors: solveDeltas when K has exactly the rows in play, else without
// the limit rows that are out (solveDeltasWithoutDroppedRows). False when neither applies (the caller factorizes).
template <int R>
bool solveVelocityDeltas(BlockIsland<R>& island, bool limitsChanged, ProjectionResult& result)
{
	if (limitsChanged) return solveDeltasWithoutDroppedRows(island, &JointBlock<R>::jv, result);
	solveDeltas(island, &JointBlock<R>::jv, result);
	return true;
}

}  // namespace stabilizer
}  // namespace quathinge

#endif
