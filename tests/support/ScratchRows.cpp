// Scratch rows (ScratchRows.h): zeroed Jacobians and errors, bounds ±∞, the solver's info fields.
#include "support/ScratchRows.h"

#include <cstring>

namespace qh_test
{
ScratchRows::ScratchRows(btScalar fps, btScalar erp)
{
	std::memset(j1lin, 0, sizeof(j1lin));
	std::memset(j1ang, 0, sizeof(j1ang));
	std::memset(j2lin, 0, sizeof(j2lin));
	std::memset(j2ang, 0, sizeof(j2ang));
	std::memset(error, 0, sizeof(error));
	std::memset(cfm, 0, sizeof(cfm));
	for (int i = 0; i < kRows * kStride; ++i)
	{
		lower[i] = -SIMD_INFINITY;
		upper[i] = SIMD_INFINITY;
	}
	info.fps = fps;
	info.erp = erp;
	info.m_J1linearAxis = j1lin;
	info.m_J1angularAxis = j1ang;
	info.m_J2linearAxis = j2lin;
	info.m_J2angularAxis = j2ang;
	info.rowskip = kStride;
	info.m_constraintError = error;
	info.cfm = cfm;
	info.m_lowerLimit = lower;
	info.m_upperLimit = upper;
	info.m_numIterations = 10;
	info.m_damping = 1;
}

}  // namespace qh_test
