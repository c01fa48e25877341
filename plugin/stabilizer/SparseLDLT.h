// The general sparse LDLᵀ of K (docs/MATH.md Q13, Q14): Eigen's SimplicialLDLT with AMD ordering, the reference for
// the block LDLᵀ (BlockLDLT.h) and the path solver = BT_QHSTAB_SOLVER_SPARSE_LDLT forces; and the fill-reducing order
// of the blocks by which the block LDLᵀ factorizes islands with closed loops (fillReducingOrder, below).
//
// The scalar pattern is every entry of each joint's own rows in every block of the BlockPattern (structural zeros
// included; no padding), lower triangle, compressed by columns. It is analysed once (analyzePattern) and only
// factorize() runs per step: reusing a symbolic analysis on a matrix whose pattern changed corrupted memory in the
// prototype (MATH.md, "Pitfall"), so the pattern here is fixed by construction and rebuilt only with the island.
// Eigen's sparse types stay in SparseLDLT.cpp; this header declares an opaque holder.
#ifndef QUATHINGE_STABILIZER_SPARSE_LDLT_H
#define QUATHINGE_STABILIZER_SPARSE_LDLT_H

#include "BulletAllocator.h"
#include "BlockMatrix.h"

#include <memory>

namespace quathinge
{
namespace stabilizer
{
class SparseLDLT
{
public:
	BT_DECLARE_ALIGNED_ALLOCATOR();
	SparseLDLT();
	~SparseLDLT();
	SparseLDLT(const SparseLDLT&) = delete;
	SparseLDLT& operator=(const SparseLDLT&) = delete;

	/// Builds the scalar pattern of `pattern` and its symbolic analysis.
	void analyze(const BlockPattern& pattern);
	/// Copies the values of k (lower triangle) into the fixed pattern and factorizes. False on a numerical failure
	/// (a zero pivot: the caller then skips the island's correction for this step).
	template <int R>
	bool factorize(const BlockMatrix<R>& k);
	/// Solves K x = b in place; b holds one BlockVector<R> per block row (padding rows are left alone).
	template <int R>
	void solve(BlockVector<R>* b);

private:
	struct Eigen3;
	std::unique_ptr<Eigen3> m_eigen;
	const BlockPattern* m_pattern = nullptr;
	Array<int> m_diagStart;   // value index of entry (offset_k + c, offset_k + c), per block row k and column c
	Array<int> m_lowerStart;  // value index of the first row of lower block s in each of its columns (stride
							  // kMaxBlockRows)
};

/// A fill-reducing order of the blocks of `pattern` (Eigen's approximate minimum degree on the graph whose nodes are the
/// blocks and whose edges are its lower blocks): order[k] is the block to number k. For islands with closed loops,
/// whose numbering along a tree of bodies fills: in this order, with the fill's blocks added to the pattern, the block
/// LDLᵀ (BlockLDLT.h) factorizes them with dense R×R kernels instead of this class's scalar ones.
Array<int> fillReducingOrder(const BlockPattern& pattern);

extern template bool SparseLDLT::factorize<5>(const BlockMatrix<5>&);
extern template bool SparseLDLT::factorize<6>(const BlockMatrix<6>&);
extern template void SparseLDLT::solve<5>(BlockVector<5>*);
extern template void SparseLDLT::solve<6>(BlockVector<6>*);

}  // namespace stabilizer
}  // namespace quathinge

#endif
