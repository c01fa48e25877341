// Scratch rows for calling a constraint's getInfo1/getInfo2 by hand, laid out as the sequential-impulse solver hands
// them over; the tests (through World.h) and the benchmark (demos/bench) use the same ones.
#ifndef QUATHINGE_TESTS_SCRATCH_ROWS_H
#define QUATHINGE_TESTS_SCRATCH_ROWS_H

#include <btBulletDynamicsCommon.h>

namespace qh_test
{
/// Scratch rows for calling getInfo1/getInfo2 by hand (rowskip kStride, zeroed, bounds ±∞ as the solver sets them).
struct ScratchRows
{
	static constexpr int kRows = 8;
	static constexpr int kStride = 16;
	btScalar j1lin[kRows * kStride], j1ang[kRows * kStride], j2lin[kRows * kStride], j2ang[kRows * kStride];
	btScalar error[kRows * kStride], cfm[kRows * kStride], lower[kRows * kStride], upper[kRows * kStride];
	btTypedConstraint::btConstraintInfo2 info;
	explicit ScratchRows(btScalar fps = 60, btScalar erp = btScalar(0.2));
	btVector3 linA(int r) const { return btVector3(j1lin[r * kStride], j1lin[r * kStride + 1], j1lin[r * kStride + 2]); }
	btVector3 angA(int r) const { return btVector3(j1ang[r * kStride], j1ang[r * kStride + 1], j1ang[r * kStride + 2]); }
	btVector3 linB(int r) const { return btVector3(j2lin[r * kStride], j2lin[r * kStride + 1], j2lin[r * kStride + 2]); }
	btVector3 angB(int r) const { return btVector3(j2ang[r * kStride], j2ang[r * kStride + 1], j2ang[r * kStride + 2]); }
	btScalar err(int r) const { return error[r * kStride]; }
	btScalar lo(int r) const { return lower[r * kStride]; }
	btScalar hi(int r) const { return upper[r * kStride]; }
};

}  // namespace qh_test

#endif
