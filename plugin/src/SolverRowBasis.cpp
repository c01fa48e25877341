// The basis the solver's bilateral rows are written in. Why and what stays exact: SolverRowBasis.h.
#include "SolverRowBasis.h"

namespace quathinge
{
PointRowBasis pointRowBasis(const btTransform& frameA, const btTransform& frameB, const btVector3& comA,
							const btVector3& comB, btScalar invMassA, btScalar invMassB)
{
	// Weights as btHingeConstraint's: the lighter side's geometry counts more (a static side: the dynamic side's).
	const btScalar invMassSum = invMassA + invMassB;
	btScalar weightA = invMassSum > btScalar(0) ? invMassB / invMassSum : btScalar(0.5);
	btScalar weightB = btScalar(1) - weightA;
	const btVector3 axisA = frameA.getBasis().getColumn(2);
	const btVector3 axisB = frameB.getBasis().getColumn(2);
	PointRowBasis basis;
	basis.a = axisA * weightA + axisB * weightB;
	if (basis.a.length2() < SIMD_EPSILON)  // axes opposed (a flipped start): take B's, as stock does
	{
		weightA = 0;
		weightB = 1;
		basis.a = axisB;
	}
	basis.a.normalize();
	// Radial: the parts of the lever arms across the axis, blended with the weights swapped (stock's choice).
	const btVector3 armA = frameA.getOrigin() - comA;
	const btVector3 armB = frameB.getOrigin() - comB;
	const btVector3 acrossA = armA - basis.a * armA.dot(basis.a);
	const btVector3 acrossB = armB - basis.a * armB.dot(basis.a);
	btVector3 radial = acrossB * weightA + acrossA * weightB;
	if (!(radial.length2() > SIMD_EPSILON))
	{
		// Pivots on the axis through the centres of mass: any direction across the axis decouples as well. Frame A's x
		// (or y, if x lies along the blended axis), so the basis turns with the joint and warm starting stays meaningful.
		radial = frameA.getBasis().getColumn(0);
		if (basis.a.cross(radial).length2() < SIMD_EPSILON) radial = frameA.getBasis().getColumn(1);
	}
	// t first, then p = t × a: orthonormal to round-off however short the radial part was (a row-space rotation).
	basis.t = basis.a.cross(radial).normalized();
	basis.p = basis.t.cross(basis.a);
	return basis;
}

void quaternionRowTurn(const btVector3& radialInFrameA, const btQuaternion& q, btScalar& cosPsi, btScalar& sinPsi)
{
	cosPsi = 1;
	sinPsi = 0;
	const btScalar ex = radialInFrameA.x(), ey = radialInFrameA.y();
	const btScalar e2 = ex * ex + ey * ey;
	if (!(e2 > SIMD_EPSILON)) return;
	// Row u's direction across the axis in joint frame A: (q0, q_z)/c (Q7), and at the exact flip (c = 0) the same
	// sign-carrying limit the log form takes (QuaternionHingeRows.cpp), so the turn flips with q like the rows.
	btScalar dw = q.w(), dz = q.z();
	const btScalar c2 = dw * dw + dz * dz;
	if (c2 > SIMD_EPSILON * SIMD_EPSILON)
	{
		const btScalar invC = btScalar(1) / btSqrt(c2);
		dw *= invC;
		dz *= invC;
	}
	else
	{
		const btScalar dominant = btFabs(q.x()) >= btFabs(q.y()) ? q.x() : q.y();
		dw = dominant >= 0 ? btScalar(1) : btScalar(-1);
		dz = 0;
	}
	const btScalar invE = btScalar(1) / btSqrt(e2);
	const btScalar ux = ex * invE, uy = ey * invE;
	// (cos ψ, sin ψ) turns (dw, dz) onto (ux, uy).
	cosPsi = dw * ux + dz * uy;
	sinPsi = dw * uy - dz * ux;
}

}  // namespace quathinge
