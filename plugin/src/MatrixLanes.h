// 3×3 products row by row in SIMD lanes, with the bits of btMatrix3x3's scalar products: Bullet's Debian build has no
// SSE in its API, so btMatrix3x3::operator* and transposeTimes form every entry as a three-term dot product, which the
// compiler schedules one scalar at a time. Entry (i, c) of m1·m2 is m1[i][0]·m2[0][c] + m1[i][1]·m2[1][c] +
// m1[i][2]·m2[2][c], summed left to right; a row of the product is therefore m1[i][0]·m2[0] + m1[i][1]·m2[1] +
// m1[i][2]·m2[2] lane by lane, the same products added in the same order (x86-64 without -march has no FMA to contract
// them into), so every entry has the same bits as Bullet's. A btVector3 holds four lanes; the fourth is padding (zero
// in every matrix Bullet builds) and is carried along, never read back.
// Lanes is a GCC/Clang vector type where QUATHINGE_HAVE_VECTOR_EXTENSIONS (CompilerExtensions.h), else a standard
// struct of four btScalars whose operators do the same IEEE operations lane by lane: the same bits either way.
#ifndef QUATHINGE_MATRIX_LANES_H
#define QUATHINGE_MATRIX_LANES_H

#include "CompilerExtensions.h"
#include "LinearMath/btMatrix3x3.h"

#include <cstdint>
#include <cstring>
#include <type_traits>

#if QUATHINGE_HAVE_VECTOR_EXTENSIONS
// With double-precision Bullet a Lanes value is 32 bytes, which GCC and Clang warn changes the calling convention
// without AVX (-Wpsabi), at these helpers and at every call that passes one. They are inline and this header is
// internal to the library (plugin/src only), so no call crosses an ABI boundary: the warning is off for the files
// that include it.
#if defined(__clang__)
#if __has_warning("-Wpsabi")
#pragma clang diagnostic ignored "-Wpsabi"
#endif
#else
#pragma GCC diagnostic ignored "-Wpsabi"
#endif
#endif

namespace quathinge
{
/// Integer lanes of the same width, for bit masks.
typedef std::conditional<sizeof(btScalar) == 4, std::int32_t, std::int64_t>::type LaneInt;

#if QUATHINGE_HAVE_VECTOR_EXTENSIONS
typedef btScalar Lanes __attribute__((vector_size(4 * sizeof(btScalar))));
typedef LaneInt LaneBits __attribute__((vector_size(4 * sizeof(btScalar))));
#else
/// Four btScalars; + − × lane by lane, × by a scalar on every lane (the vector type's operators, the same operations).
struct Lanes
{
	btScalar lane[4];
	btScalar& operator[](int i) { return lane[i]; }
	const btScalar& operator[](int i) const { return lane[i]; }
	Lanes& operator+=(const Lanes& b)
	{
		for (int i = 0; i < 4; ++i) lane[i] += b.lane[i];
		return *this;
	}
	Lanes& operator-=(const Lanes& b)
	{
		for (int i = 0; i < 4; ++i) lane[i] -= b.lane[i];
		return *this;
	}
	Lanes& operator*=(btScalar s)
	{
		for (int i = 0; i < 4; ++i) lane[i] *= s;
		return *this;
	}
};
inline Lanes operator+(Lanes a, const Lanes& b) { return a += b; }
inline Lanes operator-(Lanes a, const Lanes& b) { return a -= b; }
inline Lanes operator-(const Lanes& a) { return {{-a.lane[0], -a.lane[1], -a.lane[2], -a.lane[3]}}; }
inline Lanes operator*(const Lanes& a, const Lanes& b)
{
	return {{a.lane[0] * b.lane[0], a.lane[1] * b.lane[1], a.lane[2] * b.lane[2], a.lane[3] * b.lane[3]}};
}
inline Lanes operator*(const Lanes& a, btScalar s)
{
	return {{a.lane[0] * s, a.lane[1] * s, a.lane[2] * s, a.lane[3] * s}};
}
inline Lanes operator*(btScalar s, const Lanes& a)
{
	return {{s * a.lane[0], s * a.lane[1], s * a.lane[2], s * a.lane[3]}};
}

/// The bits of lane i (memcpy: no aliasing through another type).
inline LaneInt laneBits(const Lanes& l, int i)
{
	LaneInt bits;
	std::memcpy(&bits, &l.lane[i], sizeof bits);
	return bits;
}
inline btScalar scalarOfBits(LaneInt bits)
{
	btScalar value;
	std::memcpy(&value, &bits, sizeof value);
	return value;
}
#endif

inline Lanes lanesOf(const btVector3& v)
{
	Lanes l;
	std::memcpy(&l, v.m_floats, sizeof l);
	return l;
}

inline void storeLanes(btVector3& v, const Lanes& l) { std::memcpy(v.m_floats, &l, sizeof l); }

/// (|x|, |y|, |z|, 0): the sign bits and the padding lane cleared (whatever the padding holds, even NaN).
inline Lanes absXyz(const btVector3& v)
{
	const LaneInt magnitude = ~(LaneInt(1) << (8 * sizeof(btScalar) - 1));
#if QUATHINGE_HAVE_VECTOR_EXTENSIONS
	const LaneBits mask = {magnitude, magnitude, magnitude, 0};
	return (Lanes)((LaneBits)lanesOf(v) & mask);
#else
	const Lanes l = lanesOf(v);
	return {{scalarOfBits(laneBits(l, 0) & magnitude), scalarOfBits(laneBits(l, 1) & magnitude),
			 scalarOfBits(laneBits(l, 2) & magnitude), btScalar(0)}};
#endif
}

/// The smallest magnitude a Jacobian entry keeps with float Bullet: 2^-40 = 9.1e-13 (metres for a lever arm, a plain
/// number for a unit direction's component). Anything smaller is round-off of the frames — a component of 8.9e-18 in
/// a unit axis — and, handed to Bullet's solver, it underflows into subnormal numbers there (its products with inverse
/// inertias and impulses, or itself: 8.9e-18 × 2.8e-22), which cost a microcode assist per operation on x86 cores
/// (Intel: of the order of a hundred cycles) in every solver iteration through every body the row moves. Measured on
/// an Intel Xeon, r2d2.urdf's bare quaternion world stepped 1.23 × stock's; flushing only the subnormal entries,
/// 1.12 ×; flushing below this bound, 1.04 × (1.07 × with the thread's flush-to-zero set, where neither stalls;
/// README, "Cost"). Double's subnormals start at 2^-1022, far below any product of round-off, so double Bullet flushes
/// only below 2^-300: its rows keep their bits (double's round-off, 1e-17 in a unit axis, is no stall there).
constexpr double kSmallestRowEntry = sizeof(btScalar) == 4 ? 9.094947017729282e-13 : 4.9090934652977266e-91;

/// l with every lane below kSmallestRowEntry in magnitude (zero, subnormal, or round-off) replaced by a zero of its
/// sign; every other value (infinite and NaN included) keeps its bits. Integer compares of the magnitude bits: exact,
/// and the same whatever the floating-point environment (a float compare would itself meet the subnormals).
inline Lanes flushRoundOff(const Lanes& l)
{
	const LaneInt sign = LaneInt(1) << (8 * sizeof(btScalar) - 1);
	// the bits of kSmallestRowEntry (a power of two, exact in either precision); the copy folds to a constant
	const btScalar smallestValue = btScalar(kSmallestRowEntry);
	LaneInt smallest;
	std::memcpy(&smallest, &smallestValue, sizeof smallest);
#if QUATHINGE_HAVE_VECTOR_EXTENSIONS
	const LaneBits bits = (LaneBits)l;
	const LaneBits keep = (bits & ~sign) >= smallest;  // −1 where kept, 0 where flushed
	return (Lanes)(bits & (keep | sign));
#else
	Lanes out;
	for (int i = 0; i < 4; ++i)
	{
		const LaneInt bits = laneBits(l, i);
		out.lane[i] = scalarOfBits((bits & ~sign) >= smallest ? bits : bits & sign);
	}
	return out;
#endif
}

/// The first three lanes into d[0..2] (a row of the solver's arrays: its fourth entry is not the joint's to write),
/// round-off flushed (flushRoundOff): the rows never hand Bullet's solver a non-zero entry below kSmallestRowEntry.
inline void storeXyz(btScalar* d, const Lanes& l)
{
	const Lanes f = flushRoundOff(l);
	d[0] = f[0];
	d[1] = f[1];
	d[2] = f[2];
}

/// −l into first[0..2] and l into second[0..2] (a row's two bodies' halves), as storeXyz with one flush for both.
inline void storeXyzNegatedAndAsIs(btScalar* first, btScalar* second, const Lanes& l)
{
	const Lanes f = flushRoundOff(l), n = -f;
	first[0] = n[0];
	first[1] = n[1];
	first[2] = n[2];
	second[0] = f[0];
	second[1] = f[1];
	second[2] = f[2];
}

/// a × b (btVector3::cross's bits: lane i is the same two products subtracted).
inline Lanes crossLanes(const Lanes& a, const Lanes& b)
{
#if QUATHINGE_HAVE_VECTOR_EXTENSIONS
	return __builtin_shufflevector(a, a, 1, 2, 0, 3) * __builtin_shufflevector(b, b, 2, 0, 1, 3) -
		   __builtin_shufflevector(a, a, 2, 0, 1, 3) * __builtin_shufflevector(b, b, 1, 2, 0, 3);
#else
	return {{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0], a[3] * b[3] - a[3] * b[3]}};
#endif
}

/// a · b over the first three lanes (btVector3::dot's bits: x + y, then + z).
inline btScalar dotXyz(const Lanes& a, const Lanes& b)
{
	const Lanes p = a * b;
	return p[0] + p[1] + p[2];
}

/// (x, y, z, w) in four lanes.
inline Lanes makeLanes(btScalar x, btScalar y, btScalar z, btScalar w)
{
#if QUATHINGE_HAVE_VECTOR_EXTENSIONS
	const Lanes l = {x, y, z, w};
	return l;
#else
	return {{x, y, z, w}};
#endif
}

/// Column `c` of m as (m[0][c], m[1][c], m[2][c], 0).
inline Lanes columnLanes(const btMatrix3x3& m, int c) { return makeLanes(m[0][c], m[1][c], m[2][c], btScalar(0)); }

/// out = m1 · m2 (btMatrix3x3::operator*'s bits). out may not be m1 or m2.
inline void multiplyRows(const btMatrix3x3& m1, const btMatrix3x3& m2, btMatrix3x3& out)
{
	const Lanes r0 = lanesOf(m2[0]), r1 = lanesOf(m2[1]), r2 = lanesOf(m2[2]);
	for (int i = 0; i < 3; ++i)
		storeLanes(out[i], r0 * m1[i].x() + r1 * m1[i].y() + r2 * m1[i].z());
}

/// out = (m1 · m2)ᵀ for m1 given by its columns c0, c1, c2: row c of out is column c of m1 · m2,
/// Σ_k m1[·][k] m2[k][c] lane by lane (operator*'s bits, transposed). out may not be m2.
inline void productTransposedRows(const Lanes& c0, const Lanes& c1, const Lanes& c2, const btMatrix3x3& m2,
								  btMatrix3x3& out)
{
	for (int c = 0; c < 3; ++c)
		storeLanes(out[c], c0 * m2[0][c] + c1 * m2[1][c] + c2 * m2[2][c]);
}

/// t(x) for the transform with basis columns c0, c1, c2 and origin `origin`: btTransform::operator()'s bits (each
/// row's dot product with x, then the origin added).
inline Lanes transformedLanes(const Lanes& c0, const Lanes& c1, const Lanes& c2, const btVector3& origin,
							  const btVector3& x)
{
	return c0 * x.x() + c1 * x.y() + c2 * x.z() + lanesOf(origin);
}

/// R·v for R given by its transpose `transposed` (rows: R's columns): (R v)_i = R[i][0] v_x + R[i][1] v_y + R[i][2] v_z
/// in that order, btMatrix3x3 * btVector3's bits.
inline Lanes timesTransposed(const btMatrix3x3& transposed, const btVector3& v)
{
	return lanesOf(transposed[0]) * v.x() + lanesOf(transposed[1]) * v.y() + lanesOf(transposed[2]) * v.z();
}

}  // namespace quathinge

#endif
