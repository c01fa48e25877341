// Matched states (MatchedStates.h).
#include "MatchedStates.h"

#include <cmath>
#include <memory>
#include <stdexcept>

namespace quathinge
{
namespace scenes
{
namespace
{
// What a step reads of a body and Bullet does not recompute: its transforms (the interpolation pair too, which
// predictIntegratedTransform and the motion states use) and its velocities.
void copyBodyState(const btRigidBody& from, btRigidBody& to)
{
	to.setCenterOfMassTransform(from.getCenterOfMassTransform());
	to.setInterpolationWorldTransform(from.getInterpolationWorldTransform());
	to.setLinearVelocity(from.getLinearVelocity());
	to.setAngularVelocity(from.getAngularVelocity());
	to.setInterpolationLinearVelocity(from.getInterpolationLinearVelocity());
	to.setInterpolationAngularVelocity(from.getInterpolationAngularVelocity());
}

void addJointErrors(const std::vector<MeasuredJoint>& joints, JointErrorStats& errors)
{
	for (const MeasuredJoint& j : joints) errors.add(measureJointError(j));
}
}  // namespace

MatchedRun runMatched(const SceneSpec& scene, Kind leader, Kind follower, double dt, int iterations, double duration,
					  const std::function<void(btDiscreteDynamicsWorld&)>& prepare)
{
	MatchedRun run;
	if (!scene.unavailable.empty())
	{
		run.skipped = scene.unavailable;
		return run;
	}
	std::unique_ptr<Simulation> lead, follow;
	try
	{
		lead.reset(new Simulation(scene, leader));
		follow.reset(new Simulation(scene, follower));
	}
	catch (const std::exception& e)
	{
		run.skipped = e.what();
		return run;
	}
	if (lead->bodies.size() != follow->bodies.size() || lead->joints.size() != follow->joints.size())
	{
		run.skipped = "the two kinds build different bodies or joints";
		return run;
	}
	if (prepare)
	{
		prepare(lead->world());
		prepare(follow->world());
	}
	run.steps = int(std::lround((duration > 0 ? duration : scene.duration) / dt));
	for (int i = 0; i < run.steps; ++i)
	{
		for (size_t b = 0; b < lead->bodies.size(); ++b) copyBodyState(*lead->bodies[b], *follow->bodies[b]);
		lead->step(dt, iterations);
		follow->step(dt, iterations);
		if (!lead->finiteAndBounded() || !follow->finiteAndBounded())
		{
			run.steps = i + 1;
			run.blewUp = true;
			break;
		}
		addJointErrors(lead->joints, run.leader);
		addJointErrors(follow->joints, run.follower);
	}
	return run;
}
}  // namespace scenes
}  // namespace quathinge
