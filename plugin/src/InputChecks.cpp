#include "InputChecks.h"

#include "quathinge/btQuaternionHingeErrors.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#ifndef QUATHINGE_NO_EXCEPTIONS
#include <stdexcept>
#endif

namespace
{
thread_local unsigned t_refusals = 0;
}  // namespace

namespace quathinge
{
namespace check
{
namespace
{
bool refuse(const std::string& message)
{
	++t_refusals;
#ifdef QUATHINGE_NO_EXCEPTIONS
	btQuaternionHingeReportError(message.c_str());
	return false;
#else
	throw std::invalid_argument(message);
#endif
}
}  // namespace

unsigned refusals() { return t_refusals; }

bool fail(const char* fn, const char* param, const char* what, btScalar value)
{
	std::ostringstream message;
	message << fn << ": " << param << " (" << value << ") " << what;
	return refuse(message.str());
}

bool fail(const char* fn, const char* message) { return refuse(std::string(fn) + ": " + message); }

bool finite(const char* fn, const char* param, btScalar value)
{
	return std::isfinite(value) || fail(fn, param, "must be finite", value);
}

bool finite(const char* fn, const char* param, const btVector3& value)
{
	for (int i = 0; i < 3; ++i)
		if (!std::isfinite(value[i]))
		{
			std::ostringstream message;
			message << param << " must be finite (component " << i << " is " << value[i] << ")";
			return fail(fn, message.str().c_str());
		}
	return true;
}

bool pivot(const char* fn, const char* param, const btVector3& value)
{
	if (!finite(fn, param, value)) return false;
	return value.length() <= kMaxPivotDistance ||
		   fail(fn, (std::string(param) + " distance from the centre of mass (m)").c_str(), "must be at most 1e6",
				value.length());
}

bool direction(const char* fn, const char* param, const btVector3& axis, btVector3& normalized)
{
	if (!finite(fn, param, axis)) return false;
	const btScalar length = axis.length();
	if (length >= SIMD_EPSILON && length <= btScalar(1) / SIMD_EPSILON)
	{
		normalized = axis / length;
		return true;
	}
	// scaled by its largest component first, so a tiny axis (1e-30, whose squared length underflows) or a huge one
	// still normalizes
	const btScalar largest = btMax(btFabs(axis.x()), btMax(btFabs(axis.y()), btFabs(axis.z())));
	if (largest == 0) return fail(fn, (std::string(param) + " must not be the zero vector").c_str());
	// component by component: btVector3's division multiplies by 1/largest, which is +inf for a denormal largest
	// (the fuzzer's axis of 1e-45 became NaN and a NaN frame B)
	const btVector3 scaled(axis.x() / largest, axis.y() / largest, axis.z() / largest);
	normalized = scaled / scaled.length();
	return true;
}

bool isRigidFrame(const btTransform& frame)
{
	const btMatrix3x3& basis = frame.getBasis();
	for (int i = 0; i < 3; ++i)
		if (!std::isfinite(frame.getOrigin()[i])) return false;
	if (frame.getOrigin().length() > kMaxPivotDistance) return false;
	for (int i = 0; i < 3; ++i)
		for (int j = 0; j < 3; ++j)
		{
			if (!std::isfinite(basis[i][j])) return false;
			const btScalar dot = basis.getColumn(i).dot(basis.getColumn(j));
			if (btFabs(dot - (i == j ? btScalar(1) : btScalar(0))) > kUnitTolerance) return false;
		}
	return basis.determinant() > 0;
}

bool rigidFrame(const char* fn, const char* param, const btTransform& frame)
{
	if (!pivot(fn, (std::string(param) + " origin").c_str(), frame.getOrigin())) return false;
	return isRigidFrame(frame) ||
		   fail(fn, (std::string(param) + " basis must be orthonormal and right-handed (a rotation)").c_str());
}

bool inRange(const char* fn, const char* param, btScalar value, btScalar lo, bool loIncluded, btScalar hi,
			 bool hiIncluded)
{
	const bool aboveLo = loIncluded ? value >= lo : value > lo;
	const bool belowHi = hiIncluded ? value <= hi : value < hi;
	if (!(aboveLo && belowHi))  // also catches NaN
	{
		std::ostringstream what;
		what << "must be in " << (loIncluded ? "[" : "(") << lo << ", " << hi << (hiIncluded ? "]" : ")");
		return fail(fn, param, what.str().c_str(), value);
	}
	return true;
}

bool angle(const char* fn, const char* param, btScalar value)
{
	return inRange(fn, param, value, -kMaxAngle, true, kMaxAngle, true);
}

bool limitFactor(const char* fn, const char* param, btScalar value)
{
	return inRange(fn, param, value, -kMaxLimitFactor, true, kMaxLimitFactor, true);
}

bool nonNegative(const char* fn, const char* param, btScalar value)
{
	return value >= 0 || fail(fn, param, "must be >= 0", value);
}

bool finiteNonNegative(const char* fn, const char* param, btScalar value)
{
	return finite(fn, param, value) && nonNegative(fn, param, value);
}

bool positive(const char* fn, const char* param, btScalar value)
{
	return value > 0 || fail(fn, param, "must be > 0", value);
}

}  // namespace check
}  // namespace quathinge
