// The quaternion two-row part (MATH.md Q2–Q10, Q12). Derivation and glossary: QuaternionHingeRows.h.
#include "QuaternionHingeRows.h"

#include "LinearMath/btMatrix3x3.h"
#include "MatrixLanes.h"

namespace quathinge
{
namespace
{
struct SwingPolar
{
	btScalar s;    // |(q_x, q_y)| = sin(φ/2)
	btScalar c;    // sqrt(q0² + q_z²) = cos(φ/2)
	btScalar phi;  // swing angle φ ∈ [0, π]
};

SwingPolar swingPolar(const btQuaternion& q)
{
	SwingPolar p;
	p.s = btSqrt(q.x() * q.x() + q.y() * q.y());
	p.c = btSqrt(q.w() * q.w() + q.z() * q.z());
	p.phi = btScalar(2) * btAtan2(p.s, p.c);
	return p;
}

}  // namespace

void logFormRowsInFrameA(const btQuaternion& q, const btVector3& hu, const btVector3& hv, btVector3& gu, btVector3& gv,
						 btScalar& cu, btScalar& cv)
{
	const btScalar w = q.w(), x = q.x(), y = q.y(), z = q.z();
	// Swing logarithm C_L = (φ/s)(q_x, q_y) and its exact derivative (header, Q12):
	//   dφ = m,  m = rotate((q_x, q_y)/s, by the angle of (q0, q_z)/c)   (unit, ⟂ ẑ)
	//   d(q_x) = ½ hu,  d(q_y) = ½ hv,  d(φ/s) = β m,  β = (2s − φc)/(2s²)
	const SwingPolar p = swingPolar(q);  // s ≥ 1/√2 here
	btScalar cw, cz;                     // (q0, q_z)/c, the limit (1, 0) at the exact flip
	if (p.c > SIMD_EPSILON)
	{
		cw = w / p.c;
		cz = z / p.c;
	}
	else
	{
		// Exact flip: any swing axis escapes. Take n with a sign that flips with q, so that the rows, like every
		// other row here, change sign with q (Q3): (cw, cz) must then flip too.
		const btScalar dominant = btFabs(x) >= btFabs(y) ? x : y;
		cw = dominant >= 0 ? btScalar(1) : btScalar(-1);
		cz = 0;
	}
	const btScalar nx = x / p.s, ny = y / p.s;
	const btVector3 m(nx * cw - ny * cz, nx * cz + ny * cw, 0);
	const btScalar kappa = p.phi / (btScalar(2) * p.s);  // κ = φ/(2s)
	const btScalar beta = (btScalar(2) * p.s - p.phi * p.c) / (btScalar(2) * p.s * p.s);
	gu = kappa * hu + (x * beta) * m;
	gv = kappa * hv + (y * beta) * m;
	cu = btScalar(2) * kappa * x;
	cv = btScalar(2) * kappa * y;
}

btScalar swingAngle(const btQuaternion& q) { return swingPolar(q).phi; }

void angularConstraintValue(const btQuaternion& a, const btQuaternion& b, btScalar& cu, btScalar& cv)
{
	btVector3 gu, gv;
	bool logForm;
	rowsInFrameA(relativeQuaternion(a, b), gu, gv, cu, cv, logForm);
}

void computeAngularRows(const btMatrix3x3& frameAInWorld, const btQuaternion& q, AngularRows& out)
{
	btVector3 gu, gv;
	rowsInFrameA(q, gu, gv, out.errorU, out.errorV, out.logForm);
	// (Q7) Ċ = g·(ω_B − ω_A) with g = R_A (…): rows in world coordinates.
	out.rowU = frameAInWorld * gu;
	out.rowV = frameAInWorld * gv;
}

void computeAngularRows(const btQuaternion& a, const btQuaternion& b, AngularRows& out)
{
	computeAngularRows(btMatrix3x3(a), relativeQuaternion(a, b), out);
}

}  // namespace quathinge
