// The one interface a maximal-coordinate joint kind implements: it turns a scene's hinges into Bullet constraints
// for a btDiscreteDynamicsWorld, converts the stock hinges of a loaded file, and may add an action to the world (a
// post-stabilizer). Simulation (Simulation.h) builds the bodies, asks the kind's factory for the joints and measures
// them; scenes never see a factory. A new kind is a new factory (JointFactory.cpp) and a name (JointKinds.cpp).
// The multibody kind has no factory: reduced coordinates build whole trees in a world of their own
// (Simulation::buildMultiBodies).
#ifndef QUATHINGE_JOINT_FACTORY_H
#define QUATHINGE_JOINT_FACTORY_H

#include "JointKinds.h"
#include "SceneSpec.h"

#include <btBulletDynamicsCommon.h>

#include <functional>
#include <memory>
#include <vector>

namespace quathinge
{
namespace scenes
{
/// Called before every step with the step h (s): drive settings that depend on h (a torque as an impulse per step,
/// a servo target set every tick).
using StepHook = std::function<void(btScalar h)>;

class JointFactory
{
public:
	virtual ~JointFactory() = default;
	/// The constraint for hinge `j` between `a` and `b`, joint frames `fa` in a and `fb` in b (their z axes the hinge
	/// axis, θ = 0 where their x axes coincide), with j's limit and drive. The caller owns it and adds it to the world.
	virtual btTypedConstraint* makeHinge(const JointSpec& j, btRigidBody& a, btRigidBody& b, const btTransform& fa,
										 const btTransform& fb, std::vector<StepHook>& hooks) const = 0;
	/// A stock hinge of a loaded file as this kind's joint, with its limit and motor; null keeps the stock hinge.
	virtual btTypedConstraint* convertStock(btHingeConstraint& stock, std::vector<StepHook>& hooks) const = 0;
	/// Swaps the stock hinges `stock` of a loaded file in `world` for this kind's joints and returns them (the caller
	/// owns them; the stock hinges stay their loader's). Default: convertStock for each, removed and added one by one.
	virtual std::vector<btTypedConstraint*> replaceStockHinges(btDynamicsWorld& world,
															   const btAlignedObjectArray<btHingeConstraint*>& stock,
															   std::vector<StepHook>& hooks) const;
	/// Something this kind adds to the world besides its joints (a post-stabilizer), or null. Simulation adds it after
	/// the joints and removes it first.
	virtual std::unique_ptr<btActionInterface> makeAction() const { return nullptr; }
};

/// The factory of a maximal-coordinate kind (the solver kinds share stock's and the quaternion hinge's); null for the
/// multibody kinds.
const JointFactory* jointFactory(Kind kind);

}  // namespace scenes
}  // namespace quathinge

#endif
