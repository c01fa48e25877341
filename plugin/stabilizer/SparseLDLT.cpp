// The general sparse LDLᵀ (see SparseLDLT.h).
#include "BulletAllocator.h"
#include "SparseLDLT.h"

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>

namespace quathinge
{
namespace stabilizer
{
struct SparseLDLT::Eigen3
{
	Eigen::SparseMatrix<double> lower;  // lower triangle of K, compressed by columns
	Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt;
	Eigen::VectorXd rhs, solution;
};

SparseLDLT::SparseLDLT() : m_eigen(new Eigen3) {}
SparseLDLT::~SparseLDLT() = default;

void SparseLDLT::analyze(const BlockPattern& pattern)
{
	m_pattern = &pattern;
	const int n = pattern.blockRows();
	// Column c of block column k holds the diagonal block's rows c..size−1, then every lower block's rows, in block
	// row order: the rows of one block are consecutive, so each block column starts at one value index.
	Array<int> columnCount(pattern.rows, 0);
	for (int k = 0; k < n; ++k)
		for (int c = 0; c < pattern.size[k]; ++c)
		{
			int count = pattern.size[k] - c;
			for (int s = pattern.colStart[k]; s < pattern.colStart[k + 1]; ++s) count += pattern.size[pattern.rowOf[s]];
			columnCount[pattern.offset[k] + c] = count;
		}
	Eigen::SparseMatrix<double>& m = m_eigen->lower;
	m.resize(pattern.rows, pattern.rows);
	m.resizeNonZeros(0);
	m.reserve(columnCount);
	m_diagStart.assign(pattern.rows, 0);
	m_lowerStart.assign(size_t(pattern.lowerBlocks()) * kMaxBlockRows, 0);
	for (int k = 0; k < n; ++k)
		for (int c = 0; c < pattern.size[k]; ++c)
		{
			const int col = pattern.offset[k] + c;
			for (int r = c; r < pattern.size[k]; ++r) m.insert(pattern.offset[k] + r, col) = 0;
			for (int s = pattern.colStart[k]; s < pattern.colStart[k + 1]; ++s)
			{
				const int i = pattern.rowOf[s];
				for (int r = 0; r < pattern.size[i]; ++r) m.insert(pattern.offset[i] + r, col) = 0;
			}
		}
	m.makeCompressed();
	// Value indices, read back from the compressed matrix.
	const int* outer = m.outerIndexPtr();
	for (int k = 0; k < n; ++k)
		for (int c = 0; c < pattern.size[k]; ++c)
		{
			const int col = pattern.offset[k] + c;
			int at = outer[col];
			m_diagStart[col] = at;
			at += pattern.size[k] - c;
			for (int s = pattern.colStart[k]; s < pattern.colStart[k + 1]; ++s)
			{
				m_lowerStart[size_t(s) * kMaxBlockRows + c] = at;
				at += pattern.size[pattern.rowOf[s]];
			}
		}
	m_eigen->ldlt.analyzePattern(m);
	m_eigen->rhs.resize(pattern.rows);
	m_eigen->solution.resize(pattern.rows);
}

Array<int> fillReducingOrder(const BlockPattern& pattern)
{
	const int n = pattern.blockRows();
	// the lower triangle, compressed by columns, written directly (rows ascending: the diagonal, then the pattern's)
	Eigen::SparseMatrix<double> graph(n, n);
	graph.resizeNonZeros(n + pattern.lowerBlocks());
	int* outer = graph.outerIndexPtr();
	int* inner = graph.innerIndexPtr();
	int at = 0;
	for (int k = 0; k < n; ++k)
	{
		outer[k] = at;
		inner[at++] = k;
		for (int s = pattern.colStart[k]; s < pattern.colStart[k + 1]; ++s) inner[at++] = pattern.rowOf[s];
	}
	outer[n] = at;
	std::fill(graph.valuePtr(), graph.valuePtr() + at, 1.0);
	// AMDOrdering orders the pattern of A + Aᵀ; its permutation's indices()[new] is the old index (SimplicialLDLT
	// keeps it as the inverse of the permutation it applies)
	Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> perm;
	Eigen::AMDOrdering<int>()(graph, perm);
	Array<int> order(n);
	for (int k = 0; k < n; ++k) order[k] = perm.indices()[k];
	return order;
}

template <int R>
bool SparseLDLT::factorize(const BlockMatrix<R>& k)
{
	const BlockPattern& pattern = *m_pattern;
	double* values = m_eigen->lower.valuePtr();
	for (int b = 0; b < pattern.blockRows(); ++b)
	{
		const int mk = pattern.size[b];
		for (int c = 0; c < mk; ++c)
		{
			double* v = values + m_diagStart[pattern.offset[b] + c];
			for (int r = c; r < mk; ++r) *v++ = k.diag[b](r, c);
		}
		for (int s = pattern.colStart[b]; s < pattern.colStart[b + 1]; ++s)
		{
			const int mi = pattern.size[pattern.rowOf[s]];
			for (int c = 0; c < mk; ++c)
			{
				double* v = values + m_lowerStart[size_t(s) * kMaxBlockRows + c];
				for (int r = 0; r < mi; ++r) v[r] = k.lower[s](r, c);
			}
		}
	}
	m_eigen->ldlt.factorize(m_eigen->lower);
	return m_eigen->ldlt.info() == Eigen::Success;
}

template <int R>
void SparseLDLT::solve(BlockVector<R>* b)
{
	const BlockPattern& pattern = *m_pattern;
	for (int k = 0; k < pattern.blockRows(); ++k)
		m_eigen->rhs.segment(pattern.offset[k], pattern.size[k]) = b[k].head(pattern.size[k]);
	m_eigen->solution = m_eigen->ldlt.solve(m_eigen->rhs);
	for (int k = 0; k < pattern.blockRows(); ++k)
		b[k].head(pattern.size[k]) = m_eigen->solution.segment(pattern.offset[k], pattern.size[k]);
}

template bool SparseLDLT::factorize<5>(const BlockMatrix<5>&);
template bool SparseLDLT::factorize<6>(const BlockMatrix<6>&);
template void SparseLDLT::solve<5>(BlockVector<5>*);
template void SparseLDLT::solve<6>(BlockVector<6>*);

}  // namespace stabilizer
}  // namespace quathinge
