// The three point rows along world x, y, z (docs/MATH.md Q13), as the stabilizer evaluates them: for a quaternion
// hinge (btQuaternionHingeConstraint::computePositionRows) and for Bullet's own point constraints
// (plugin/stabilizer/PointRows.h). Header-only and internal: the stabilizer library includes it from the source tree.
#ifndef QUATHINGE_WORLD_POINT_ROWS_H
#define QUATHINGE_WORLD_POINT_ROWS_H

#include "LinearMath/btVector3.h"

namespace quathinge
{
/// Pivots at r_A and r_B from the bodies' centres of mass (world), `offset` = p_B − p_A: row i has
/// J_A = (−e_i, e_i × r_A), J_B = (e_i, r_B × e_i) (12 numbers: v_A, ω_A, v_B, ω_B) and C_i = offset_i.
inline void writeWorldPointRows(const btVector3& rA, const btVector3& rB, const btVector3& offset, btScalar* C,
								btScalar* jacobian)
{
	for (int row = 0; row < 3; ++row)
	{
		btVector3 e(0, 0, 0);
		e[row] = 1;
		const btVector3 angularA = e.cross(rA), angularB = rB.cross(e);
		btScalar* j = jacobian + 12 * row;
		for (int k = 0; k < 3; ++k)
		{
			j[k] = -e[k];
			j[3 + k] = angularA[k];
			j[6 + k] = e[k];
			j[9 + k] = angularB[k];
		}
		C[row] = offset[row];
	}
}
}  // namespace quathinge

#endif
