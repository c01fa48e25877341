// Tree-ordered block LDLᵀ (derivation in BlockLDLT.h).
#include "BlockLDLT.h"

#include <algorithm>

namespace quathinge
{
namespace stabilizer
{
int BlockPattern::find(int i, int k) const
{
	const int* first = rowOf.data() + colStart[k];
	const int* last = rowOf.data() + colStart[k + 1];
	const int* at = std::lower_bound(first, last, i);
	return (at != last && *at == i) ? int(at - rowOf.data()) : -1;
}

bool BlockLDLT::analyze(const BlockPattern& pattern)
{
	m_pattern = &pattern;
	m_updates.clear();
	m_updateStart.assign(pattern.blockRows() + 1, 0);
	int widest = 0;
	for (int k = 0; k < pattern.blockRows(); ++k)
	{
		m_updateStart[k] = int(m_updates.size());
		const int first = pattern.colStart[k], last = pattern.colStart[k + 1];
		widest = std::max(widest, last - first);
		for (int a = first; a < last; ++a)
			for (int b = first; b <= a; ++b)
			{
				Update u;
				u.left = a;
				u.right = b - first;
				if (a == b) u.target = -1 - pattern.rowOf[a];
				else
				{
					u.target = pattern.find(pattern.rowOf[a], pattern.rowOf[b]);
					if (u.target < 0) return false;  // (rowOf[a], rowOf[b]) is not in the pattern: fill
				}
				m_updates.push_back(u);
			}
	}
	m_updateStart[pattern.blockRows()] = int(m_updates.size());
	m_w.resize(widest);
	m_invPivot.resize(pattern.blockRows());
	return true;
}

namespace
{
// factorBlock for a block whose rows ≥ N are decoupled (zero off the diagonal): a joint without a limit row in play,
// whose sixth row is padding. The loops have fixed bounds, so the compiler unrolls each size.
template <int N>
int factorBlockCoupled(const Block& d, int ownRows, double pivotFloor, Block& x, BlockVector& invPivot)
{
	// a[i][j] (i > j) holds L_ij p_j while the factorization runs.
	double a[N][N];
	double l[N][N];
	for (int c = 0; c < N; ++c)
		for (int r = c; r < N; ++r) a[r][c] = d(r, c);
	int dropped = 0;
	for (int j = 0; j < N; ++j)
	{
		double pivot = a[j][j];
		for (int q = 0; q < j; ++q) pivot -= l[j][q] * a[j][q];
		const bool keep = pivot > pivotFloor;
		dropped += (!keep && j < ownRows) ? 1 : 0;
		invPivot[j] = keep ? 1 / pivot : 0;
		for (int i = j + 1; i < N; ++i)
		{
			double s = a[i][j];
			for (int q = 0; q < j; ++q) s -= l[i][q] * a[j][q];
			a[i][j] = s;
			l[i][j] = s * invPivot[j];
		}
	}
	// X = L⁻¹ (unit lower), column by column; the identity on the decoupled rows.
	x.setIdentity();
	for (int c = 0; c < N; ++c)
		for (int i = c + 1; i < N; ++i)
		{
			double s = -l[i][c];
			for (int q = c + 1; q < i; ++q) s -= l[i][q] * x(q, c);
			x(i, c) = s;
		}
	for (int j = N; j < kBlockRows; ++j)
	{
		const bool keep = d(j, j) > pivotFloor;
		dropped += (!keep && j < ownRows) ? 1 : 0;
		invPivot[j] = keep ? 1 / d(j, j) : 0;
	}
	return dropped;
}
}  // namespace

int factorBlock(const Block& d, int ownRows, double pivotFloor, Block& x, BlockVector& invPivot)
{
	const int last = kBlockRows - 1;
	if (d.row(last).head<last>().isZero(0))
		return factorBlockCoupled<kBlockRows - 1>(d, ownRows, pivotFloor, x, invPivot);
	return factorBlockCoupled<kBlockRows>(d, ownRows, pivotFloor, x, invPivot);
}

int BlockLDLT::factorize(BlockMatrix& k, double pivotFloor)
{
	const BlockPattern& pattern = *m_pattern;
	int dropped = 0;
	for (int col = 0; col < pattern.blockRows(); ++col)
	{
		Block x;
		BlockVector& invPivot = m_invPivot[col];
		dropped += factorBlock(k.diag[col], pattern.size[col], pivotFloor, x, invPivot);
		k.diag[col] = x;

		const int first = pattern.colStart[col], last = pattern.colStart[col + 1];
		for (int s = first; s < last; ++s)
		{
			const Block v = k.lower[s] * x.transpose();  // V_ik = W_ik X_kᵀ
			k.lower[s] = v;
			m_w[s - first].noalias() = v * invPivot.asDiagonal();
		}
		for (int u = m_updateStart[col]; u < m_updateStart[col + 1]; ++u)
		{
			const Update& up = m_updates[u];
			Block& target = up.target < 0 ? k.diag[-1 - up.target] : k.lower[up.target];
			target.noalias() -= m_w[up.left - first] * k.lower[first + up.right].transpose();  // K_ij −= V_i P⁻¹ V_jᵀ
		}
	}
	return dropped;
}

void BlockLDLT::solve(const BlockMatrix& factors, BlockVector* b) const
{
	const BlockPattern& pattern = *m_pattern;
	const int n = pattern.blockRows();
	for (int col = 0; col < n; ++col)  // forward: u_k = P⁻¹ X_k b_k (kept in b_k), b_i −= V_ik u_k
	{
		const BlockVector u = m_invPivot[col].cwiseProduct(factors.diag[col] * b[col]);
		b[col] = u;
		for (int s = pattern.colStart[col]; s < pattern.colStart[col + 1]; ++s)
			b[pattern.rowOf[s]].noalias() -= factors.lower[s] * u;
	}
	for (int col = n - 1; col >= 0; --col)  // backward: x_k = X_kᵀ (u_k − P⁻¹ Σ V_ikᵀ x_i)
	{
		BlockVector t = BlockVector::Zero();
		for (int s = pattern.colStart[col]; s < pattern.colStart[col + 1]; ++s)
			t.noalias() += factors.lower[s].transpose() * b[pattern.rowOf[s]];
		const BlockVector w = b[col] - m_invPivot[col].cwiseProduct(t);
		b[col] = factors.diag[col].transpose() * w;
	}
}

}  // namespace stabilizer
}  // namespace quathinge
