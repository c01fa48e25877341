// The stabilizer's K = J M⁻¹ Jᵀ in block form (docs/MATH.md Q13, Q14, "K has the joint graph's sparsity").
//
// One block row per joint: its bilateral rows (3 linear + 2 quaternion, or 2 when angular-only) and, for a joint with
// a limit, one slot for the limit row. K_ij = Σ_b J_ib M_b⁻¹ J_jbᵀ over the movable bodies b that joints i and j share,
// so K_ij ≠ 0 only for i = j and for pairs of joints on a common body. The pattern holds exactly those blocks, every
// entry of each (structural zeros included), and never changes while an island's structure is the same.
// Every block of an island is a fixed R×R matrix, R = 6 when some joint of the island has a limit slot and 5 when
// none has (BlockShape): a joint's rows beyond its own are padding, zero off the diagonal, which keeps every block
// product fixed-size (vectorized, no index arithmetic). The general sparse path copies only each joint's own rows
// (BlockPattern::size).
//
// Glossary: lower block — a block K_ij with i > j (K is symmetric: only the diagonal and lower blocks are stored);
// padding row — a row of a block beyond the joint's own rows, or a limit slot whose limit is not violated: its J is
// zero, its diagonal entry is the island's scale s, so its λ is 0.
#ifndef QUATHINGE_STABILIZER_BLOCK_MATRIX_H
#define QUATHINGE_STABILIZER_BLOCK_MATRIX_H

#include "BulletAllocator.h"
#include <Eigen/Core>

#include <type_traits>
#include <utility>


namespace quathinge
{
namespace stabilizer
{
/// Rows of the largest block: 3 linear + 2 quaternion + 1 limit.
const int kMaxBlockRows = 6;

/// An island's block size R: 6 when some joint of the island has a limit slot, else 5 (StabilizerIsland.h).
/// Every block is stored with an even number of rows (kStorageRows: 6 for both sizes) and R columns: Eigen runs the
/// fixed-size products of 6-row columns in SSE2 pairs of doubles, and those of 5-row columns as scalar code that costs
/// more than the whole 6-row column (README, the 5×5-corner experiment). So a 5-block is 6×5: its sixth row is a zero
/// storage row, never read as a column of the other operand; a product costs 5 columns of 3 pairs instead of 6.
template <int R>
struct BlockShape
{
	static_assert(R == 5 || R == 6, "blocks are 5 or 6 rows");
	static constexpr int kRows = R;
	static constexpr int kStorageRows = (R + 1) / 2 * 2;
};

/// A block of K: R logical rows (stored in BlockShape<R>::kStorageRows, the rest zero) × R columns.
template <int R>
using Block = Eigen::Matrix<double, BlockShape<R>::kStorageRows, R>;
/// A block row's entries of a vector (right-hand side, λ, C, J v): R logical entries, the storage rows zero.
template <int R>
using BlockVector = Eigen::Matrix<double, BlockShape<R>::kStorageRows, 1>;

/// A block row's R logical entries, without storage rows.
template <int R>
using PivotVector = Eigen::Matrix<double, R, 1>;

/// The R × R logical part of a block (the block itself when it has no storage rows).
template <int R, class M>
decltype(auto) logicalRows(const M& m)
{
	if constexpr (int(M::RowsAtCompileTime) == R) return (m);
	else return m.template topRows<R>();
}

/// Calls f(std::integral_constant<int, I>{}) for I = 0 … N − 1, unrolled at compile time, so that a loop over a
/// block's columns works on fixed-size segments (whole SSE2 pairs of doubles, no index arithmetic): the block kernels
/// of the assembly (IslandSystem.h) and the factorization (BlockLDLT.cpp).
template <class F, int... I>
inline void unrollEach(F&& f, std::integer_sequence<int, I...>)
{
	(f(std::integral_constant<int, I>{}), ...);
}
template <int N, class F>
inline void unroll(F&& f)
{
	unrollEach(f, std::make_integer_sequence<int, N>{});
}

/// The block structure of a symmetric matrix: diagonal blocks and the lower blocks present, column by column.
struct BlockPattern
{
	Array<int> size;      ///< a joint's own rows (the general sparse path's block sizes)
	Array<int> offset;    ///< first scalar row of block row i in the compact (unpadded) numbering
	int rows = 0;         ///< compact scalar rows in all
	Array<int> colStart;  ///< lower blocks of column k: [colStart[k], colStart[k + 1]), block rows ascending
	Array<int> rowOf;     ///< block row of each lower block

	int blockRows() const { return int(size.size()); }
	int lowerBlocks() const { return int(rowOf.size()); }
	/// Index of lower block (i, k), i > k, or −1 when it is not in the pattern.
	int find(int i, int k) const;
};

/// Values on a BlockPattern, in blocks of R rows.
template <int R>
struct BlockMatrix
{
	Array<Block<R>> diag;   ///< diagonal blocks (symmetric, stored in full)
	Array<Block<R>> lower;  ///< lower blocks, in pattern order
	void resize(const BlockPattern& pattern)
	{
		diag.resize(pattern.blockRows());
		lower.resize(pattern.lowerBlocks());
	}
};

}  // namespace stabilizer
}  // namespace quathinge

#endif
