// btQuaternionHingeConstraint::computePositionRows: the same equations as the solver's rows, at given transforms and
// unrotated, for post-stabilizers.
#include "quathinge/btQuaternionHingeConstraint.h"

#include "AxisRows.h"
#include "HingeAngle.h"
#include "InputChecks.h"
#include "MatrixLanes.h"
#include "QuaternionHingeRows.h"
#include "RowKinds.h"
#include "SolverRowBasis.h"
#include "WorldPointRows.h"

#include "BulletDynamics/Dynamics/btRigidBody.h"

#include <cmath>
#include <cstring>
#include <type_traits>

using namespace quathinge;

int btQuaternionHingeConstraint::computePositionRows(const btTransform& transA, const btTransform& transB, btScalar* C,
													 btScalar* jacobian) const
{
	Pose pose;
	poseAt(transA, transB, pose);
	return positionRowsAt(pose, transA, transB, C, jacobian);
}

int btQuaternionHingeConstraint::computePositionRows(const btTransform& transA, const btTransform& transB, btScalar* C,
													 btScalar* jacobian, btScalar previousAngle, btScalar& angle,
													 btVector3& angleGradient) const
{
	Pose pose;
	poseAt(transA, transB, pose);
	angle = angleRowAt(pose, previousAngle, angleGradient);
	return positionRowsAt(pose, transA, transB, C, jacobian);
}

int btQuaternionHingeConstraint::positionRowsAt(const Pose& pose, const btTransform& transA, const btTransform& transB,
												btScalar* C, btScalar* jacobian) const
{
	return framePositionRowsAt(pose, transA, transB, m_settings.angularOnly, C, jacobian);
}

int btQuaternionHingeConstraint::computeFramePositionRows(const btTransform& frameInA, const btTransform& frameInB,
														  bool angularOnly, const btTransform& transA,
														  const btTransform& transB, btScalar* C, btScalar* jacobian,
														  btScalar previousAngle, btScalar& angle,
														  btVector3& angleGradient)
{
	Pose pose;
	framePoseAt(frameInA, frameInB, transA, transB, pose);
	angle = frameAngleRowAt(pose, btScalar(1), previousAngle, angleGradient);
	return framePositionRowsAt(pose, transA, transB, angularOnly, C, jacobian);
}

int btQuaternionHingeConstraint::computeFramePositionRows(const btTransform& frameInA, const btTransform& frameInB,
														  bool angularOnly, const btTransform& transA,
														  const btTransform& transB, btScalar* C, btScalar* jacobian)
{
	Pose pose;
	framePoseAt(frameInA, frameInB, transA, transB, pose);
	return framePositionRowsAt(pose, transA, transB, angularOnly, C, jacobian);
}

int btQuaternionHingeConstraint::framePositionRowsAt(const Pose& pose, const btTransform& transA,
													 const btTransform& transB, bool angularOnly, btScalar* C,
													 btScalar* jacobian)
{
	// The same equations as the solver's rows, unrotated: point rows along world x, y, z (row i: J1 = (−e_i, e_i × r_A),
	// J2 = (e_i, r_B × e_i)), then the two quaternion rows (Q7, Q9; Q12 past 90°): J1 = (0, −g), J2 = (0, g).
	int rows = 0;
	if (!angularOnly)
	{
		const btVector3 rA = pose.pivotA - transA.getOrigin();
		const btVector3 rB = pose.pivotB - transB.getOrigin();
		writeWorldPointRows(rA, rB, pose.pivotB - pose.pivotA, C, jacobian);
		rows = 3;
	}
	AngularRows angular;
	computeAngularRowsFromAxes(pose.axesA, pose.q, angular);
	const btVector3* g[2] = {&angular.rowU, &angular.rowV};
	const btScalar value[2] = {angular.errorU, angular.errorV};
	for (int r = 0; r < 2; ++r, ++rows)
	{
		btScalar* j = jacobian + 12 * rows;
		for (int k = 0; k < 3; ++k)
		{
			j[k] = 0;
			j[3 + k] = -(*g[r])[k];
			j[6 + k] = 0;
			j[9 + k] = (*g[r])[k];
		}
		C[rows] = value[r];
	}
	return rows;
}
