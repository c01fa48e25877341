// The joint's row kinds, as setParam's axis numbers them (per-row ERP and CFM): shared by the parameters
// (HingeErpCfm.cpp) and the rows that use them (HingeSolverRows.cpp, HingeBilateralRows.cpp).
#ifndef QUATHINGE_ROW_KINDS_H
#define QUATHINGE_ROW_KINDS_H

namespace quathinge
{
const int kLinearKind = 0;   // 0..2: the point rows
const int kAngularKind = 3;  // 3..4: the quaternion rows
const int kAxialKind = 5;    // the axial rows (drive, friction, limit): stock's joint axis
}  // namespace quathinge

#endif
