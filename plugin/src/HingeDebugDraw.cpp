// Debug drawing. Bullet's btDiscreteDynamicsWorld::debugDrawConstraint draws only the stock types it downcasts, so the
// joint draws itself: both joint frames, the hinge axis, and the limit arc.
#include "quathinge/btQuaternionHingeConstraint.h"

#include "BulletDynamics/Dynamics/btRigidBody.h"
#include "LinearMath/btIDebugDraw.h"

#include <cmath>

void btQuaternionHingeConstraint::debugDraw(btIDebugDraw* drawer, btScalar size) const
{
	if (!drawer) return;
	const btTransform frameA = m_rbA.getCenterOfMassTransform() * m_settings.frameInA;
	const btTransform frameB = m_rbB.getCenterOfMassTransform() * m_settings.frameInB;
	drawer->drawTransform(frameA, size);
	drawer->drawTransform(frameB, size);
	const btVector3 axis = frameA.getBasis().getColumn(2);
	drawer->drawLine(frameA.getOrigin() - axis * size, frameA.getOrigin() + axis * size, btVector3(1, 1, 0));
	if (!m_settings.hasLimit) return;
	// The arc in frame A's xy plane, in the getHingeAngle convention (σ: see getHingeAngle); at most one turn shown.
	const btScalar sigma = m_settings.useReferenceFrameA ? btScalar(1) : btScalar(-1);
	btScalar low = m_settings.lowerLimit, high = m_settings.upperLimit;
	// a side without a stop (±inf) is drawn as half a turn from the other stop; no stop at all, no arc
	const bool lowFinite = std::isfinite(low), highFinite = std::isfinite(high);
	if (!lowFinite && !highFinite) return;
	if (!lowFinite) low = high - SIMD_PI;
	if (!highFinite) high = low + SIMD_PI;
	if (high - low > SIMD_2_PI) high = low + SIMD_2_PI;
	btScalar from = sigma * low, to = sigma * high;
	if (from > to) btSwap(from, to);
	drawer->drawArc(frameA.getOrigin(), axis, frameA.getBasis().getColumn(0), size, size, from, to,
					btVector3(0, 1, 1), true);
}
