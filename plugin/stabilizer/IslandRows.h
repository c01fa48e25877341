// The rows of an island at its bodies' current state (docs/MATH.md Q13, Q14): C and J of every joint (the joint's
// own computePositionRows and computeAngleRow; a stock or 6-dof hinge's, StockHingeRows.h), J v, and how far each is from converged against its tolerance and
// rounding floor (see IslandProjection.cpp for the thresholds' reasons).
#ifndef QUATHINGE_STABILIZER_ISLAND_ROWS_H
#define QUATHINGE_STABILIZER_ISLAND_ROWS_H

#include "CompilerExtensions.h"
#include "ConeTwistRows.h"
#include "IslandContacts.h"
#include "LockedRows.h"
#include "PointRows.h"
#include "StabilizerIsland.h"
#include "StockHingeRows.h"

#include "quathinge/btQuaternionHingeConstraint.h"

#include "BulletDynamics/Dynamics/btRigidBody.h"

namespace quathinge
{
namespace stabilizer
{
inline btScalar maxAbs(const btVector3& v) { return btMax(btFabs(v.x()), btMax(btFabs(v.y()), btFabs(v.z()))); }

// The rounding floor of a quantity of magnitude up to `scale` (units of it): 4ε·max(1, scale). A linear row's C at
// bodies whose coordinates reach `scale` m cannot be resolved below it (float Bullet: ~1e-6 m at 10 m), nor J v below
// it at speeds |v| + |ω|·1 m up to `scale`; an angular row's floor is 4ε rad (scale 1).
inline btScalar roundingFloor(btScalar scale) { return 4 * SIMD_EPSILON * btMax(btScalar(1), scale); }

// A row is converged once |C| ≤ its threshold: the tolerance, or the row's rounding floor where that is larger.
inline btScalar linearRowThreshold(btScalar tolerance, btScalar coordinate)
{
	return btMax(tolerance, roundingFloor(coordinate));
}
inline btScalar angularRowThreshold(btScalar tolerance) { return btMax(tolerance, roundingFloor(0)); }

#ifdef BT_DEBUG
// The linear part of every row is ±[I₃; 0] (point rows) or 0 (quaternion rows): what JointSlot::linearSign encodes.
inline bool hasPointStructure(const btScalar* jac, int rows, int linearRows)
{
	for (int r = 0; r < rows; ++r)
		for (int k = 0; k < 3; ++k)
		{
			const btScalar expected = (r < linearRows && r == k) ? btScalar(1) : btScalar(0);
			if (jac[12 * r + k] != -expected || jac[12 * r + 6 + k] != expected) return false;
		}
	return true;
}
#endif

// A cone twist with a limit row (ConeTwistRows.h): its point rows and the swing, or, in its twist slot, the twist
// alone; the limit's variable into js.angle, its gradient into g. Returns the bilateral rows written.
inline int coneLimitRows(JointSlot& js, const btTransform& tA, const btTransform& tB, btScalar* C, btScalar* jacobian,
						 btVector3& g)
{
	const btConeTwistConstraint& cone = *static_cast<const btConeTwistConstraint*>(js.point);
	if (js.limitOnly)
	{
		js.angle = coneTwistVariable(cone, tA, tB, g);
		return 0;
	}
	js.angle = coneSwingVariable(cone, coneLimits(cone), tA, tB, g);
	return pointPositionRows(cone, tA, tB, C, jacobian);
}

struct PositionResidual
{
	btScalar linear = 0;         // ‖C‖∞ over the linear rows (m)
	btScalar angular = 0;        // over the quaternion and limit rows (rad)
	btScalar normalized = 0;     // max over rows of |C| / max(tolerance, the row's rounding floor): ≤ 1 is converged
	bool limitsChanged = false;  // some limit row's activity differs from the factorized K
	btScalar max() const { return btMax(linear, angular); }
};

// The rows of every joint at the bodies' current transforms, and ‖C‖ against tolerance and the rounding floors.
template <int R>
PositionResidual evaluatePositions(BlockIsland<R>& island, btScalar tolerance)
{
	PositionResidual res;
	const btScalar angularThreshold = angularRowThreshold(tolerance);
	btScalar c[6];  // up to 6 rows: a weld (LockedRows.h)
	btScalar jac[72];
	for (size_t j = 0; j < island.joints.size(); ++j)
	{
		JointSlot& js = island.joints[j];
		JointBlock<R>& jb = island.blocks[j];
		if (QUATHINGE_UNLIKELY(js.contact >= 0))  // a contact slot (IslandContacts.h): linear rows, at the bodies' coordinate
		{
			btScalar coordinate = maxAbs(js.rigid[0]->getCenterOfMassPosition());
			if (js.rigid[1]) coordinate = btMax(coordinate, maxAbs(js.rigid[1]->getCenterOfMassPosition()));
			js.linearThreshold = linearRowThreshold(tolerance, coordinate);
			js.angularThreshold = angularThreshold;
			const btScalar worst = evaluateContactRows(island, js, jb, js.linearThreshold);
			res.linear = btMax(res.linear, worst);
			res.normalized = btMax(res.normalized, worst / js.linearThreshold);
			if (js.contactTouched != js.contactActiveInFactor) res.limitsChanged = true;
			continue;
		}
		const btTransform& tA = js.rigid[0]->getCenterOfMassTransform();
		const btTransform& tB = js.rigid[1]->getCenterOfMassTransform();
		// A joint with a limit slot also needs its angle row: both from one evaluation of the joint frames.
		btVector3 g;
		LockedLimit lockedLimit;  // a locked 6-dof's limited axis (LockedRows.h)
		lockedLimit.axis = js.limitAxis;
		const int rows = js.point        ? (js.limitSlot ? coneLimitRows(js, tA, tB, c, jac, g) : pointPositionRows(*js.point, tA, tB, c, jac))
						 : js.locked     ? lockedPositionRows(*js.locked, tA, tB, c, jac, js.limitSlot ? &lockedLimit : nullptr,
															  !js.limitOnly)
						 : js.frameHinge ? (js.limitSlot ? frameHingePositionRows(js.hinge, tA, tB, c, jac,
																				  js.angleReference, js.angle, g)
														 : frameHingePositionRows(js.hinge, tA, tB, c, jac))
						 : js.limitSlot  ? js.joint->computePositionRows(tA, tB, c, jac, js.angleReference, js.angle, g)
										 : js.joint->computePositionRows(tA, tB, c, jac);
		const int linearRows = js.linearRows;
		btAssert(js.generalLinear() || hasPointStructure(jac, rows, linearRows));
		btScalar linear = 0, angular = 0;
		for (int r = 0; r < rows; ++r)
		{
			jb.c[r] = c[r];
			// the angular part (the linear part is fixed, written when the island was built: IslandBuilder.cpp)
			for (int k = 0; k < 3; ++k)
			{
				jb.jacobian(r, 3 + k) = jac[12 * r + 3 + k];
				jb.jacobian(r, 9 + k) = jac[12 * r + 9 + k];
			}
			btScalar& worst = r < linearRows ? linear : angular;
			worst = btMax(worst, btFabs(c[r]));
		}
		if (QUATHINGE_UNLIKELY(js.generalLinear()))  // a locked 6-dof: its linear part turns with body A
			for (int r = 0; r < rows; ++r)
				for (int k = 0; k < 3; ++k)
				{
					jb.jacobian(r, k) = jac[12 * r + k];
					jb.jacobian(r, 6 + k) = jac[12 * r + 6 + k];
				}
		// The pivot's rounding floor at the larger of the two bodies' coordinates.
		const btScalar coordinate = btMax(maxAbs(tA.getOrigin()), maxAbs(tB.getOrigin()));
		const btScalar linearThreshold = linearRowThreshold(tolerance, coordinate);
		js.linearThreshold = linearThreshold;
		js.angularThreshold = angularThreshold;
		res.linear = btMax(res.linear, linear);
		res.angular = btMax(res.angular, angular);
		res.normalized = btMax(res.normalized, btMax(linear / linearThreshold, angular / angularThreshold));
		if (!js.limitSlot) continue;
		btAssert(R == 6);  // an island with a limit slot works in 6-row blocks

		// The limit row: the multi-turn angle α continued from the step's reference, and its gradient g (the joint's own
		// Q11, btQuaternionHingeConstraint::computeAngleRow; computed above with the position rows); a locked 6-dof's
		// limited axis, its variable and whole gradient (linear too: the slot's linear part is general).
		if (js.locked)
		{
			js.angle = lockedLimit.value;
			for (int k = 0; k < 12; ++k) js.limitGradient[k] = lockedLimit.gradient[k];
		}
		else
			for (int k = 0; k < 3; ++k)
			{
				js.limitGradient[k] = 0;
				js.limitGradient[3 + k] = -g[k];
				js.limitGradient[6 + k] = 0;
				js.limitGradient[9 + k] = g[k];
			}
		if (js.limitTouched == 0)
		{
			if (js.angle < js.lowerStop) js.limitTouched = 1;
			else if (js.angle > js.upperStop) js.limitTouched = -1;
		}
		// a driven axis is held at its angle at the step's start (StockHingeRows.h, "Drive"), unless past a stop
		js.limitActive = js.limitTouched != 0 || js.held;
		const int r = js.bilateralRows;
		const btScalar stop = js.limitTouched > 0 ? js.lowerStop : js.limitTouched < 0 ? js.upperStop
																					   : js.angleReference;
		jb.c[r] = js.limitActive ? js.angle - stop : 0;
		if (js.limitActive) jb.jacobian.row(r) = js.limitGradient;
		else jb.jacobian.row(r).setZero();
		btScalar& worst = js.limitLinear() ? res.linear : res.angular;  // a locked 6-dof's linear axis: a length
		worst = btMax(worst, btFabs(btScalar(jb.c[r])));
		res.normalized = btMax(res.normalized, btFabs(btScalar(jb.c[r])) / (js.limitLinear() ? linearThreshold : angularThreshold));
		if (js.limitActive != js.limitActiveInFactor) res.limitsChanged = true;
	}
	return res;
}

// A static body at rest, standing in for a contact slot's fixed partners where a velocity is read.
inline const btRigidBody* atRest()
{
	static const btRigidBody body(btRigidBody::btRigidBodyConstructionInfo(0, nullptr, nullptr));
	return &body;
}

struct VelocityResidual
{
	btScalar max = 0;            // ‖J v‖∞ (m/s, rad/s)
	btScalar normalized = 0;     // max over rows of |J v| / its threshold: ≤ 1 is converged
	bool limitsChanged = false;  // some limit row's activity differs from the factorized K
};

// J v per row (into JointBlock::jv). decideLimits: choose which limit rows take part (else keep the choice).
// A row's threshold is its position threshold over the time step (what it would drift in the next step), or the
// rounding floor of J v itself, 4ε·(|v| + |ω|·1 m) of the joint's bodies.
template <int R>
VelocityResidual evaluateVelocities(BlockIsland<R>& island, bool decideLimits, btScalar timeStep)
{
	VelocityResidual res;
	for (size_t j = 0; j < island.joints.size(); ++j)
	{
		JointSlot& js = island.joints[j];
		JointBlock<R>& jb = island.blocks[j];
		Eigen::Matrix<double, 12, 1> v;
		btScalar speed = 0;
		// a contact slot's fixed partners (no body: static or asleep) are at rest; point them at a body at rest
		const btRigidBody* const rigid[2] = {js.rigid[0], js.rigid[1] ? js.rigid[1] : atRest()};
		for (int s = 0; s < 2; ++s)
		{
			const btVector3& lin = rigid[s]->getLinearVelocity();
			const btVector3& ang = rigid[s]->getAngularVelocity();
			for (int k = 0; k < 3; ++k)
			{
				v[6 * s + k] = lin[k];
				v[6 * s + 3 + k] = ang[k];
			}
			speed = btMax(speed, maxAbs(lin) + maxAbs(ang));
		}
		if (js.limitSlot)
		{
			const int r = js.bilateralRows;
			if (decideLimits)
			{
				// α̇ = 0 only while moving further past a stop violated this step (lower: α̇ < 0, upper: α̇ > 0).
				const double rate = js.limitGradient.dot(v.transpose());
				const bool stopped = (js.limitTouched > 0 && rate < 0) || (js.limitTouched < 0 && rate > 0);
				// a driven axis keeps the rate Bullet's step gave it (0 while pushing into a stop): its row's target
				js.limitActive = stopped || js.held;
				js.heldRate = js.held && !stopped ? btScalar(rate) : btScalar(0);
			}
			if (js.limitActive) jb.jacobian.row(r) = js.limitGradient;
			else jb.jacobian.row(r).setZero();
			if (js.limitActive != js.limitActiveInFactor) res.limitsChanged = true;
		}
		if (js.contact >= 0 && js.contactTouched != js.contactActiveInFactor) res.limitsChanged = true;
		jb.jv.noalias() = jb.jacobian * v;
		// a held row's J v is α̇ less its target (heldRate: 0 for a limit row)
		if (js.limitSlot && js.limitActive) jb.jv[js.bilateralRows] -= double(js.heldRate);
		if (js.contact >= 0 && !js.rigid[1])  // a fixed partner's own velocity: Ċ_r = J_r v − s_r n_r·v_partner
		{
			const ContactSet& set = island.contacts[size_t(js.contact)];
			for (int r = 0; r < set.count; ++r)
				if (js.contactTouched & (1u << r))
					jb.jv[r] -= double(set.rows[r].sign * set.rows[r].normal.dot(set.rows[r].partnerVelocity));
		}
		const btScalar floor = roundingFloor(speed);
		const int linearRows = js.linearRows;
		for (int r = 0; r < js.rows; ++r)
		{
			const btScalar value = btFabs(btScalar(jb.jv[r]));
			const bool linear = r < linearRows || (r == js.bilateralRows && js.limitLinear());
			const btScalar threshold = (linear ? js.linearThreshold : js.angularThreshold) / timeStep;
			res.max = btMax(res.max, value);
			res.normalized = btMax(res.normalized, value / btMax(threshold, floor));
		}
	}
	return res;
}

}  // namespace stabilizer
}  // namespace quathinge

#endif
