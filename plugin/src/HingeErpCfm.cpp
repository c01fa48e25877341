// btQuaternionHingeConstraint's setParam/getParam: ERP and CFM per row kind (stock's axis −1 and 5 for the joint,
// beyond stock 0–2 the linear rows and 3–4 the quaternion rows), and the values each row uses (RowKinds.h).
#include "quathinge/btQuaternionHingeConstraint.h"

#include "InputChecks.h"
#include "RowKinds.h"

using namespace quathinge;

void btQuaternionHingeConstraint::setParam(int num, btScalar value, int axis)
{
	// Stock's meaning for axis −1 and 5 (btHingeConstraint::setParam treats both as "the joint"): its normal ERP acts
	// on every row, its normal CFM on the motor row only, STOP_* on the limit row. Axes 0..4 (which stock ignores)
	// reach the linear and quaternion rows one kind at a time.
	const char* fn = "btQuaternionHingeConstraint::setParam";
	if (axis < -1 || axis > 5)
	{
		check::fail(fn, "axis", "must be -1 (the joint) or 0..5", btScalar(axis));
		return;
	}
	const char* name = num == BT_CONSTRAINT_ERP        ? "value (ERP)"
					   : num == BT_CONSTRAINT_CFM      ? "value (CFM)"
					   : num == BT_CONSTRAINT_STOP_ERP ? "value (STOP_ERP)"
													   : "value (STOP_CFM)";
	if (num != BT_CONSTRAINT_ERP && num != BT_CONSTRAINT_CFM && num != BT_CONSTRAINT_STOP_ERP &&
		num != BT_CONSTRAINT_STOP_CFM)
	{
		check::fail(fn, "num", "must be BT_CONSTRAINT_ERP, _STOP_ERP, _CFM or _STOP_CFM", btScalar(num));
		return;
	}
	// Finite, ERP in [0, 2) and CFM in [0, 1): stock takes any value, but a negative one asks for error growth or a
	// negative compliance, an ERP of 2 or more overshoots by more than it corrects, and a CFM of 1 or more makes
	// Bullet's Gauss–Seidel update diverge on an unbounded row (stock's CFM reaches only its bounded motor row; here
	// a servo row may be unbounded): no value there has a meaning a solve can reach.
	const bool erpLike = num == BT_CONSTRAINT_ERP || num == BT_CONSTRAINT_STOP_ERP;
	if (!check::inRange(fn, name, value, 0, true, erpLike ? btScalar(2) : btScalar(1), false)) return;
	const bool joint = axis == -1 || axis == kAxialKind;
	switch (num)
	{
		case BT_CONSTRAINT_ERP:
		{
			const int first = joint ? 0 : axis, last = joint ? 5 : axis;
			for (int kind = first; kind <= last; ++kind)
			{
				m_settings.rowErp[kind] = value;
				m_settings.flags |= BT_QHINGE_FLAGS_ERP_ROW0 << kind;
			}
			m_settings.flags |= BT_QHINGE_FLAGS_ERP_NORM;
			break;
		}
		case BT_CONSTRAINT_CFM:
		{
			const int kind = joint ? kAxialKind : axis;
			m_settings.rowCfm[kind] = value;
			m_settings.flags |= (BT_QHINGE_FLAGS_CFM_ROW0 << kind) | BT_QHINGE_FLAGS_CFM_NORM;
			break;
		}
		case BT_CONSTRAINT_STOP_ERP:
		case BT_CONSTRAINT_STOP_CFM:
			if (!joint)
			{
				check::fail(fn, "axis", "must be -1 or 5 for STOP_ERP/STOP_CFM (the limit row)", btScalar(axis));
				return;
			}
			if (num == BT_CONSTRAINT_STOP_ERP)
			{
				m_settings.stopErp = value;
				m_settings.flags |= BT_QHINGE_FLAGS_ERP_STOP;
			}
			else
			{
				m_settings.stopCfm = value;
				m_settings.flags |= BT_QHINGE_FLAGS_CFM_STOP;
			}
			break;
		default:
			break;  // refused above
	}
}

btScalar btQuaternionHingeConstraint::getParam(int num, int axis) const
{
	// As stock: the value set, else 0 (stock's members start at 0); an unknown num or axis gives 0 (stock asserts in
	// a debug build and returns 0). Never throws: a const getter.
	if (axis < -1 || axis > 5) return 0;
	const int kind = axis < 0 ? kAxialKind : axis;
	switch (num)
	{
		case BT_CONSTRAINT_ERP:
			return (m_settings.flags & (BT_QHINGE_FLAGS_ERP_ROW0 << kind)) ? m_settings.rowErp[kind] : btScalar(0);
		case BT_CONSTRAINT_CFM:
			return (m_settings.flags & (BT_QHINGE_FLAGS_CFM_ROW0 << kind)) ? m_settings.rowCfm[kind] : btScalar(0);
		case BT_CONSTRAINT_STOP_ERP:
			if (kind != kAxialKind) return 0;
			return (m_settings.flags & BT_QHINGE_FLAGS_ERP_STOP) ? m_settings.stopErp : btScalar(0);
		case BT_CONSTRAINT_STOP_CFM:
			if (kind != kAxialKind) return 0;
			return (m_settings.flags & BT_QHINGE_FLAGS_CFM_STOP) ? m_settings.stopCfm : btScalar(0);
		default:
			return 0;
	}
}

btScalar btQuaternionHingeConstraint::rowErp(int kind, btScalar globalErp) const
{
	return (m_settings.flags & (BT_QHINGE_FLAGS_ERP_ROW0 << kind)) ? m_settings.rowErp[kind] : globalErp;
}

btScalar btQuaternionHingeConstraint::rowCfm(int kind, btScalar globalCfm) const
{
	return (m_settings.flags & (BT_QHINGE_FLAGS_CFM_ROW0 << kind)) ? m_settings.rowCfm[kind] : globalCfm;
}
