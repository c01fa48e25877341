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

template <int R>
bool BlockLDLT<R>::analyze(const BlockPattern& pattern)
{
	m_pattern = &pattern;
	m_updates.clear();
	m_updateStart.assign(pattern.blockRows() + 1, 0);
	int widest = 0;
	for (int k = 0; k < pattern.blockRows(); ++k)
	{
		m_updateStart[k] = int(m_updates.size());
		const int first = pattern.colStart[k], last = pattern.colStart[k + 1];
		widest = (std::max)(widest, last - first);
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
	m_invPivot.assign(pattern.blockRows(), BlockVector<R>::Zero());
	return true;
}

namespace
{
// Unrolls the loop that follows (fixed, small bounds): GCC leaves these nested loops rolled at -O3 otherwise.
#if defined(__clang__)
#define QUATHINGE_UNROLL _Pragma("unroll")
#elif defined(__GNUC__)
#define QUATHINGE_UNROLL _Pragma("GCC unroll 8")
#else
#define QUATHINGE_UNROLL
#endif

// factorBlock for a block whose rows ≥ N are decoupled (zero off the diagonal): a joint without a limit row in play,
// whose sixth row is padding.
template <int R, int N>
int factorBlockCoupled(const Block<R>& d, int ownRows, double pivotFloor, Block<R>& x, BlockVector<R>& invPivot)
{
	// a[i][j] (i > j) holds L_ij p_j while the factorization runs.
	double a[N][N];
	double l[N][N];
	QUATHINGE_UNROLL
	for (int c = 0; c < N; ++c)
	{
		QUATHINGE_UNROLL
		for (int r = c; r < N; ++r) a[r][c] = d(r, c);
	}
	int dropped = 0;
	QUATHINGE_UNROLL
	for (int j = 0; j < N; ++j)
	{
		double pivot = a[j][j];
		QUATHINGE_UNROLL
		for (int q = 0; q < j; ++q) pivot -= l[j][q] * a[j][q];
		const bool keep = pivot > pivotFloor;
		dropped += (!keep && j < ownRows) ? 1 : 0;
		invPivot[j] = keep ? 1 / pivot : 0;
		QUATHINGE_UNROLL
		for (int i = j + 1; i < N; ++i)
		{
			double s = a[i][j];
			QUATHINGE_UNROLL
			for (int q = 0; q < j; ++q) s -= l[i][q] * a[j][q];
			a[i][j] = s;
			l[i][j] = s * invPivot[j];
		}
	}
	// X = L⁻¹ (unit lower), column by column; the identity on the decoupled rows.
	x.setIdentity();
	QUATHINGE_UNROLL
	for (int c = 0; c < N; ++c)
	{
		QUATHINGE_UNROLL
		for (int i = c + 1; i < N; ++i)
		{
			double s = -l[i][c];
			QUATHINGE_UNROLL
			for (int q = c + 1; q < i; ++q) s -= l[i][q] * x(q, c);
			x(i, c) = s;
		}
	}
	for (int j = N; j < R; ++j)
	{
		const bool keep = d(j, j) > pivotFloor;
		dropped += (!keep && j < ownRows) ? 1 : 0;
		invPivot[j] = keep ? 1 / d(j, j) : 0;
	}
	return dropped;
}
}  // namespace

template <int R>
int factorBlock(const Block<R>& d, int ownRows, double pivotFloor, Block<R>& x, BlockVector<R>& invPivot)
{
	// A 6-block whose limit slot is out of play (padding or an inactive limit row): its last row is decoupled.
	// A 5-block has no limit slot.
	if constexpr (R == 6)
	{
		const int last = R - 1;
		if (d.row(last).template head<last>().isZero(0))
			return factorBlockCoupled<R, R - 1>(d, ownRows, pivotFloor, x, invPivot);
	}
	return factorBlockCoupled<R, R>(d, ownRows, pivotFloor, x, invPivot);
}

namespace
{
// V = W Xᵀ in place (w holds W on entry, V on return). X = L_k⁻¹ is unit lower triangular, so column c of V is
// W's column c plus Σ_{q<c} X(c, q) W's column q: 10 column updates instead of the dense product's 25 (R = 5).
// Columns are written from the last down, each reading only columns at or before it.
template <int R>
inline void multiplyByUnitLowerTranspose(Block<R>& w, const Block<R>& x)
{
	unroll<R>([&](auto ci) {
		constexpr int c = R - 1 - decltype(ci)::value;
		BlockVector<R> column = w.col(c);
		unroll<c>([&](auto qi) {
			constexpr int q = decltype(qi)::value;
			column += x(c, q) * w.col(q);
		});
		w.col(c) = column;
	});
}

// A diagonal block's K_ii −= A Vᵀ (A = V_ik P⁻¹, V = V_ik): only the entries on or below the diagonal, all that
// factorBlock and the later updates read, computed in whole SSE2 pairs from the pair holding the diagonal entry down.
// (A lower block's update is Eigen's dense product: this column loop measured slower there.)
template <int R>
inline void subtractProductLower(Block<R>& target, const Block<R>& a, const Block<R>& v)
{
	constexpr int kStorage = BlockShape<R>::kStorageRows;
	unroll<R>([&](auto ci) {
		constexpr int c = decltype(ci)::value;
		constexpr int first = c / 2 * 2;
		constexpr int rows = kStorage - first;
		// accumulated in registers, stored once (the compiler cannot know that target aliases neither operand)
		Eigen::Matrix<double, rows, 1> column = target.col(c).template segment<rows>(first);
		unroll<R>([&](auto qi) {
			constexpr int q = decltype(qi)::value;
			column -= v(c, q) * a.col(q).template segment<rows>(first);
		});
		target.col(c).template segment<rows>(first) = column;
	});
}
}  // namespace

template <int R>
int BlockLDLT<R>::factorize(BlockMatrix<R>& k, double pivotFloor)
{
	const BlockPattern& pattern = *m_pattern;
	int dropped = 0;
	for (int col = 0; col < pattern.blockRows(); ++col)
	{
		Block<R> x;
		BlockVector<R>& invPivot = m_invPivot[col];
		dropped += factorBlock<R>(k.diag[col], pattern.size[col], pivotFloor, x, invPivot);
		k.diag[col] = x;

		const int first = pattern.colStart[col], last = pattern.colStart[col + 1];
		for (int s = first; s < last; ++s)
		{
			multiplyByUnitLowerTranspose<R>(k.lower[s], x);  // V_ik = W_ik X_kᵀ
			m_w[s - first].noalias() = k.lower[s] * invPivot.template head<R>().asDiagonal();
		}
		for (int u = m_updateStart[col]; u < m_updateStart[col + 1]; ++u)
		{
			const Update& up = m_updates[u];
			// K_ij −= V_i P⁻¹ V_jᵀ
			const Block<R>& left = m_w[up.left - first];
			const Block<R>& right = k.lower[first + up.right];
			if (up.target < 0) subtractProductLower<R>(k.diag[-1 - up.target], left, right);
			else k.lower[up.target].noalias() -= left * logicalRows<R>(right).transpose();
		}
	}
	return dropped;
}

template <int R>
void BlockLDLT<R>::solve(const BlockMatrix<R>& factors, BlockVector<R>* b) const
{
	const BlockPattern& pattern = *m_pattern;
	const int n = pattern.blockRows();
	for (int col = 0; col < n; ++col)  // forward: u_k = P⁻¹ X_k b_k (kept in b_k), b_i −= V_ik u_k
	{
		// whole storage columns (zero on the storage rows): vectorized
		const BlockVector<R> u = m_invPivot[col].cwiseProduct(factors.diag[col] * b[col].template head<R>());
		b[col] = u;
		for (int s = pattern.colStart[col]; s < pattern.colStart[col + 1]; ++s)
			b[pattern.rowOf[s]].noalias() -= factors.lower[s] * u.template head<R>();
	}
	for (int col = n - 1; col >= 0; --col)  // backward: x_k = X_kᵀ (u_k − P⁻¹ Σ V_ikᵀ x_i)
	{
		PivotVector<R> t = PivotVector<R>::Zero();
		for (int s = pattern.colStart[col]; s < pattern.colStart[col + 1]; ++s)
			t.noalias() += factors.lower[s].transpose() * b[pattern.rowOf[s]];  // storage rows: zero in both
		BlockVector<R> w = b[col];
		w.template head<R>() -= m_invPivot[col].template head<R>().cwiseProduct(t);
		b[col].template head<R>() = factors.diag[col].transpose() * w;  // storage rows: zero in both
	}
}

template class BlockLDLT<5>;
template class BlockLDLT<6>;
template int factorBlock<5>(const Block<5>&, int, double, Block<5>&, BlockVector<5>&);
template int factorBlock<6>(const Block<6>&, int, double, Block<6>&, BlockVector<6>&);

}  // namespace stabilizer
}  // namespace quathinge
