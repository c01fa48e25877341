#include "InputChecks.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace quathinge
{
namespace check
{
void fail(const char* fn, const char* param, const char* what, btScalar value)
{
	std::ostringstream message;
	message << fn << ": " << param << " (" << value << ") " << what;
	throw std::invalid_argument(message.str());
}

void fail(const char* fn, const char* message) { throw std::invalid_argument(std::string(fn) + ": " + message); }

void finite(const char* fn, const char* param, btScalar value)
{
	if (!std::isfinite(value)) fail(fn, param, "must be finite", value);
}

void finite(const char* fn, const char* param, const btVector3& value)
{
	for (int i = 0; i < 3; ++i)
		if (!std::isfinite(value[i]))
		{
			std::ostringstream message;
			message << param << " must be finite (component " << i << " is " << value[i] << ")";
			fail(fn, message.str().c_str());
		}
}

void pivot(const char* fn, const char* param, const btVector3& value)
{
	finite(fn, param, value);
	if (value.length() > kMaxPivotDistance)
		fail(fn, (std::string(param) + " distance from the centre of mass (m)").c_str(), "must be at most 1e6", value.length());
}

btVector3 direction(const char* fn, const char* param, const btVector3& axis)
{
	finite(fn, param, axis);
	const btScalar length = axis.length();
	if (length >= SIMD_EPSILON && length <= btScalar(1) / SIMD_EPSILON) return axis / length;
	// scaled by its largest component first, so a tiny axis (1e-30, whose squared length underflows) or a huge one
	// still normalizes
	const btScalar largest = btMax(btFabs(axis.x()), btMax(btFabs(axis.y()), btFabs(axis.z())));
	if (largest == 0) fail(fn, (std::string(param) + " must not be the zero vector").c_str());
	const btVector3 scaled = axis / largest;
	return scaled / scaled.length();
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

void rigidFrame(const char* fn, const char* param, const btTransform& frame)
{
	pivot(fn, (std::string(param) + " origin").c_str(), frame.getOrigin());
	if (!isRigidFrame(frame))
		fail(fn, (std::string(param) + " basis must be orthonormal and right-handed (a rotation)").c_str());
}

void inRange(const char* fn, const char* param, btScalar value, btScalar lo, bool loIncluded, btScalar hi,
			 bool hiIncluded)
{
	const bool aboveLo = loIncluded ? value >= lo : value > lo;
	const bool belowHi = hiIncluded ? value <= hi : value < hi;
	if (!(aboveLo && belowHi))  // also catches NaN
	{
		std::ostringstream what;
		what << "must be in " << (loIncluded ? "[" : "(") << lo << ", " << hi << (hiIncluded ? "]" : ")");
		fail(fn, param, what.str().c_str(), value);
	}
}

void angle(const char* fn, const char* param, btScalar value)
{
	inRange(fn, param, value, -kMaxAngle, true, kMaxAngle, true);
}

void nonNegative(const char* fn, const char* param, btScalar value)
{
	if (!(value >= 0)) fail(fn, param, "must be >= 0", value);
}

void positive(const char* fn, const char* param, btScalar value)
{
	if (!(value > 0)) fail(fn, param, "must be > 0", value);
}

}  // namespace check
}  // namespace quathinge
