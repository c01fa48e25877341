// The stabilizer's K = J M⁻¹ Jᵀ in block form (shared/MATH.md Q13, Q14, "K has the joint graph's sparsity").
//
// One block row per joint: its bilateral rows (3 linear + 2 quaternion, or 2 when angular-only) and, for a joint with
// a limit, one slot for the limit row. K_ij = Σ_b J_ib M_b⁻¹ J_jbᵀ over the movable bodies b that joints i and j share,
// so K_ij ≠ 0 only for i = j and for pairs of joints on a common body. The pattern holds exactly those blocks, every
// entry of each (structural zeros included), and never changes while an island's structure is the same.
// Every block is a fixed 6×6 matrix (kBlockRows): a joint's rows beyond its own are padding, zero off the diagonal,
// which keeps every block product fixed-size (vectorized, no index arithmetic). The general sparse path copies only
// each joint's own rows (BlockPattern::size).
//
// Glossary: lower block — a block K_ij with i > j (K is symmetric: only the diagonal and lower blocks are stored);
// padding row — a row of a block beyond the joint's own rows, or a limit slot whose limit is not violated: its J is
// zero, its diagonal entry is the island's scale s, so its λ is 0.
#ifndef QUATHINGE_STABILIZER_BLOCK_MATRIX_H
#define QUATHINGE_STABILIZER_BLOCK_MATRIX_H

#include <Eigen/Core>

#include <vector>

namespace quathinge
{
namespace stabilizer
{
/// Rows of every block: 3 linear + 2 quaternion + 1 limit.
const int kBlockRows = 6;

typedef Eigen::Matrix<double, kBlockRows, kBlockRows> Block;
typedef Eigen::Matrix<double, kBlockRows, 1> BlockVector;

/// The block structure of a symmetric matrix: diagonal blocks and the lower blocks present, column by column.
struct BlockPattern
{
	std::vector<int> size;      ///< a joint's own rows (the general sparse path's block sizes)
	std::vector<int> offset;    ///< first scalar row of block row i in the compact (unpadded) numbering
	int rows = 0;               ///< compact scalar rows in all
	std::vector<int> colStart;  ///< lower blocks of column k: [colStart[k], colStart[k + 1]), block rows ascending
	std::vector<int> rowOf;     ///< block row of each lower block

	int blockRows() const { return int(size.size()); }
	int lowerBlocks() const { return int(rowOf.size()); }
	/// Index of lower block (i, k), i > k, or −1 when it is not in the pattern.
	int find(int i, int k) const;
};

/// Values on a BlockPattern.
struct BlockMatrix
{
	std::vector<Block> diag;   ///< diagonal blocks (symmetric, stored in full)
	std::vector<Block> lower;  ///< lower blocks, in pattern order
	void resize(const BlockPattern& pattern)
	{
		diag.resize(pattern.blockRows());
		lower.resize(pattern.lowerBlocks());
	}
};

}  // namespace stabilizer
}  // namespace quathinge

#endif
