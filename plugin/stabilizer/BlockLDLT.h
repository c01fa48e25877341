// Tree-ordered block LDLᵀ of K = J M⁻¹ Jᵀ: linear in the number of joints, without fill, for islands whose joint
// numbering is a perfect elimination order (Baraff, "Linear-time dynamics using Lagrange multipliers", SIGGRAPH 1996;
// docs/MATH.md, "for a tree it factorizes in O(n)").
//
//   K = L D Lᵀ with L unit block-lower and dense R×R diagonal blocks D_k (R = 5 or 6, BlockMatrix.h); each D_k = L_k P_k L_kᵀ densely (unit lower
//   L_k, pivots P_k), X_k = L_k⁻¹, so D_k⁻¹ = X_kᵀ P_k⁻¹ X_k. Column k, right-looking, with W_ik = K_ik (updated):
//     V_ik = W_ik X_kᵀ                      (so L_ik = W_ik D_k⁻¹ = V_ik P_k⁻¹ X_k)
//     K_ij −= V_ik P_k⁻¹ V_jkᵀ             (= L_ik D_k L_jkᵀ) for every pair i ≥ j of lower blocks in column k
//   Solve K x = b:  forward  u_k = P_k⁻¹ X_k b_k,  b_i −= V_ik u_k;   backward  x_k = X_kᵀ (u_k − P_k⁻¹ Σ_i V_ikᵀ x_i).
// The Schur updates are sums of outer products weighted by positive 1/p, never a product through an explicit D_k⁻¹:
// with redundant rows (a closed loop) a pivot is as small as the regularization, and an explicit inverse would turn
// its rounding into large negative pivots further on.
// The numbering is fill-free when the later neighbours of every joint are pairwise neighbours (true for joints
// numbered leaves first along a tree of bodies: they all share the one body towards the root). analyze() checks it
// and refuses a pattern that would fill; for an island with closed loops the caller then numbers the joints in a
// fill-reducing order and adds the fill's blocks to the pattern (IslandBuilder.cpp, fillReducingOrder in
// SparseLDLT.h), which this class then accepts; the general sparse LDLᵀ is the reference and the forced path.
// A pivot at or below the pivot floor makes that row inactive (its 1/p is 0, so its λ is 0) instead of dividing by ~0.
// The diagonal blocks are overwritten by X_k, the lower blocks by V_ik. Only a diagonal block's lower triangle is read
// (the assembly and the Schur updates write no other; BlockLDLT.cpp), and X_k's unit lower shape is used in V = W Xᵀ.
#ifndef QUATHINGE_STABILIZER_BLOCK_LDLT_H
#define QUATHINGE_STABILIZER_BLOCK_LDLT_H

#include "BulletAllocator.h"
#include "BlockMatrix.h"


namespace quathinge
{
namespace stabilizer
{
template <int R>
class BlockLDLT
{
public:
	/// Prepares the update schedule for `pattern`; false if its numbering would create fill.
	bool analyze(const BlockPattern& pattern);
	/// Factorizes k in place. pivotFloor: the smallest acceptable pivot. Returns the number of pivots at or below the
	/// floor that belong to the joints' own rows (padding rows are not counted).
	int factorize(BlockMatrix<R>& k, double pivotFloor);
	/// Solves K x = b in place; b holds one BlockVector<R> per block row.
	void solve(const BlockMatrix<R>& factors, BlockVector<R>* b) const;
	/// 1/p of block row k (0 for a dropped pivot), from the last factorize.
	const BlockVector<R>& inversePivots(int k) const { return m_invPivot[k]; }

private:
	struct Update
	{
		int left;    // lower block (i, k): its V_ik P_k⁻¹ multiplies
		int right;   // position in column k of lower block (j, k): its V_jk is transposed
		int target;  // lower block (i, j), or −1 − i for the diagonal block i (i == j)
	};
	const BlockPattern* m_pattern = nullptr;
	Array<int> m_updateStart;  // updates of column k: [m_updateStart[k], m_updateStart[k + 1])
	Array<Update> m_updates;
	Array<Block<R>> m_w;               // V_ik P_k⁻¹ of the column being eliminated (by position in the column)
	Array<BlockVector<R>> m_invPivot;  // P_k⁻¹ per block row (0 on the block's storage rows)
};

extern template class BlockLDLT<5>;
extern template class BlockLDLT<6>;

/// Dense LDLᵀ of a symmetric R×R block d = L P Lᵀ: returns X = L⁻¹ and 1/p per row (0 for a pivot ≤ pivotFloor,
/// a dropped row; invPivot's storage rows are left alone). Returns how many of the first `ownRows` rows were dropped.
template <int R>
int factorBlock(const Block<R>& d, int ownRows, double pivotFloor, Block<R>& x, BlockVector<R>& invPivot);

}  // namespace stabilizer
}  // namespace quathinge

#endif
