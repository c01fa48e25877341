// The maximal-coordinate joint kinds (JointFactory.h): stock btHingeConstraint, btGeneric6DofSpring2Constraint set
// up as a hinge, btQuaternionHingeConstraint, and each of the three hinges with btQuaternionHingeStabilizer added to
// the world. Angles are θ throughout (SceneSpec.h): each factory maps θ to its constraint's own angle.
#include "JointFactory.h"

#include "quathinge/btQuaternionHingeConstraint.h"
#include "quathinge/btQuaternionHingeStabilizer.h"

#include <stdexcept>

namespace quathinge
{
namespace scenes
{
std::vector<btTypedConstraint*> JointFactory::replaceStockHinges(btDynamicsWorld& world,
																 const btAlignedObjectArray<btHingeConstraint*>& stock,
																 std::vector<StepHook>& hooks) const
{
	std::vector<btTypedConstraint*> added;
	for (int i = 0; i < stock.size(); ++i)
	{
		btTypedConstraint* replacement = convertStock(*stock[i], hooks);
		if (!replacement) continue;
		world.removeConstraint(stock[i]);
		world.addConstraint(replacement, true);
		added.push_back(replacement);
	}
	return added;
}

namespace
{
// A stock hinge's limits on θ: its angle with useReferenceFrameA = false is −θ, so they map to [−high, −low].
struct StockLimits
{
	btScalar sign, lower, upper;
};
StockLimits stockLimitsOnTheta(const btHingeConstraint& h)
{
	const btScalar sign = h.getUseReferenceFrameA() ? 1 : -1;
	btScalar lo = h.getLowerLimit() * sign, hi = h.getUpperLimit() * sign;
	if (lo > hi) btSwap(lo, hi);
	return {sign, lo, hi};
}

class StockFactory : public JointFactory
{
public:
	btTypedConstraint* makeHinge(const JointSpec& j, btRigidBody& a, btRigidBody& b, const btTransform& fa,
								 const btTransform& fb, std::vector<StepHook>& hooks) const override
	{
		auto* h = new btHingeConstraint(a, b, fa, fb, true);  // useReferenceFrameA: getHingeAngle() = θ
		if (j.hasLimit) h->setLimit(j.lower, j.upper);
		if (j.drive == Drive::Velocity)
		{
			h->enableAngularMotor(true, j.target, 0);
			hooks.push_back([h, torque = j.maxEffort](btScalar dt) { h->setMaxMotorImpulse(torque * dt); });
		}
		if (j.drive == Drive::Servo)
		{
			// stock's way to hold an angle: set the motor target every tick, clamped to the servo's speed
			h->enableMotor(true);
			hooks.push_back([h, j](btScalar dt) {
				h->setMaxMotorImpulse(j.maxEffort * dt);
				h->setMotorTarget(j.target, dt);
				h->setMotorTargetVelocity(btMax(-j.maxSpeed, btMin(j.maxSpeed, h->getMotorTargetVelocity())));
			});
		}
		return h;
	}
	btTypedConstraint* convertStock(btHingeConstraint&, std::vector<StepHook>&) const override { return nullptr; }
};

// btGeneric6DofSpring2Constraint set up as a hinge about its frames' z axis: the three linear and the x, y angular
// axes locked, z free or limited. Its z angle is −θ: matrixToEulerXYZ reads the relative rotation A⁻¹B through
// btGetMatrixElem, which indexes column-major, so z = atan2(−R₁₀, R₀₀) = −θ; and its motor row drives (ω_A − ω_B)·z,
// which is d(−θ)/dt. So a θ limit [lo, hi] is [−hi, −lo] on it, and targets go in negated.
class Generic6Dof2Factory : public JointFactory
{
public:
	btTypedConstraint* makeHinge(const JointSpec& j, btRigidBody& a, btRigidBody& b, const btTransform& fa,
								 const btTransform& fb, std::vector<StepHook>&) const override
	{
		btScalar offset = 0;
		auto* d = hinge(a, b, fa, fb, j.hasLimit, j.lower, j.upper, offset);
		if (j.drive == Drive::Velocity)
		{
			d->enableMotor(5, true);
			d->setTargetVelocity(5, -j.target);
			d->setMaxMotorForce(5, j.maxEffort);  // N·m (the constraint turns it into an impulse per step)
		}
		else if (j.drive == Drive::Servo)
		{
			d->enableMotor(5, true);
			d->setServo(5, true);
			d->setServoTarget(5, btNormalizeAngle(-(j.target - offset)));  // its angle is −(θ − offset), wrapped
			d->setTargetVelocity(5, j.maxSpeed);                           // a speed: the servo picks the sign
			d->setMaxMotorForce(5, j.maxEffort);
		}
		return d;
	}
	btTypedConstraint* convertStock(btHingeConstraint& h, std::vector<StepHook>& hooks) const override
	{
		const StockLimits limits = stockLimitsOnTheta(h);
		btScalar offset = 0;
		auto* d = hinge(h.getRigidBodyA(), h.getRigidBodyB(), h.getAFrame(), h.getBFrame(), h.hasLimit(), limits.lower,
						limits.upper, offset);
		if (h.getEnableAngularMotor())
		{
			d->enableMotor(5, true);
			d->setTargetVelocity(5, -limits.sign * h.getMotorTargetVelocity());  // stock drives sign·θ̇; this, −θ̇
			// the file's motor is an impulse per step: the same impulse at this run's step, as a torque
			hooks.push_back([d, impulse = h.getMaxMotorImpulse()](btScalar dt) { d->setMaxMotorForce(5, impulse / dt); });
		}
		return d;
	}

private:
	// 6dof2 wraps its limits into [−π, π] (setAngularLower/UpperLimit call btNormalizeAngle), so a θ range that maps
	// outside it — one straddling ±π, such as [2.5, 3.8] — would wrap to lower > upper and leave the joint free. As a
	// user would, the child's frame is then turned by the range's centre c about z (θ = 0 of the constraint's own angle
	// at c), so the stops [−(hi − c), −(lo − c)] lie inside (−π, π) for any range narrower than a turn. `offset` returns
	// c (0 when no turn was needed: every other joint is built exactly as before). A range of a turn or more cannot be
	// expressed by a wrapped angle: it is passed as it is (both ends wrap to ±π, a stop at π, as stock's).
	static btGeneric6DofSpring2Constraint* hinge(btRigidBody& a, btRigidBody& b, const btTransform& fa,
												 const btTransform& fb, bool hasLimit, btScalar lower, btScalar upper,
												 btScalar& offset)
	{
		offset = 0;
		if (hasLimit && (-upper < -SIMD_PI || -lower > SIMD_PI) && upper - lower < SIMD_2_PI)
			offset = btScalar(0.5) * (lower + upper);
		btTransform childFrame = fb;
		if (offset != 0) childFrame.setBasis(fb.getBasis() * btMatrix3x3(btQuaternion(btVector3(0, 0, 1), -offset)));
		auto* d = new btGeneric6DofSpring2Constraint(a, b, fa, childFrame, RO_XYZ);
		d->setLinearLowerLimit(btVector3(0, 0, 0));
		d->setLinearUpperLimit(btVector3(0, 0, 0));
		if (hasLimit)
		{
			d->setAngularLowerLimit(btVector3(0, 0, -(upper - offset)));
			d->setAngularUpperLimit(btVector3(0, 0, -(lower - offset)));
		}
		else
		{
			d->setAngularLowerLimit(btVector3(0, 0, 1));  // z free (lower > upper)
			d->setAngularUpperLimit(btVector3(0, 0, -1));
		}
		return d;
	}
};

// A kind with btQuaternionHingeStabilizer added to the world as it is: its defaults hold the stock and 6-dof hinges.
template <class Base>
class Stabilized : public Base
{
public:
	std::unique_ptr<btActionInterface> makeAction() const override
	{
		return std::unique_ptr<btActionInterface>(new btQuaternionHingeStabilizer);
	}
};

class QuaternionFactory : public JointFactory
{
public:
	btTypedConstraint* makeHinge(const JointSpec& j, btRigidBody& a, btRigidBody& b, const btTransform& fa,
								 const btTransform& fb, std::vector<StepHook>& hooks) const override
	{
		auto* q = new btQuaternionHingeConstraint(a, b, fa, fb, true);
		if (j.hasLimit) q->setLimit(j.lower, j.upper);
		if (j.drive == Drive::Velocity)
		{
			q->enableAngularMotor(true, j.target, 0);
			hooks.push_back([q, torque = j.maxEffort](btScalar dt) { q->setMaxMotorImpulse(torque * dt); });
		}
		if (j.drive == Drive::Servo) q->setServoTarget(j.target, j.maxSpeed, j.maxEffort);
		return q;
	}
	btTypedConstraint* convertStock(btHingeConstraint& h, std::vector<StepHook>&) const override
	{
		return new btQuaternionHingeConstraint(h);
	}
	std::vector<btTypedConstraint*> replaceStockHinges(btDynamicsWorld& world,
													   const btAlignedObjectArray<btHingeConstraint*>& stock,
													   std::vector<StepHook>&) const override
	{
		// what a Bullet user does with a loaded file: one call swaps every stock hinge for its quaternion hinge
		// (btQuaternionHingeConstraint(const btHingeConstraint&) each); the removed stock hinges stay the loader's
		btAlignedObjectArray<btQuaternionHingeConstraint*> added;
		const int replaced = btReplaceHingeConstraints(&world, &added);
		if (replaced != stock.size())
			throw std::runtime_error("btReplaceHingeConstraints replaced " + std::to_string(replaced) + " of " +
									 std::to_string(stock.size()) + " stock hinges");
		std::vector<btTypedConstraint*> joints;
		for (int i = 0; i < added.size(); ++i) joints.push_back(added[i]);
		return joints;
	}
};

class StabilizedQuaternionFactory : public QuaternionFactory
{
public:
	StabilizedQuaternionFactory(bool conserveEnergy, bool keepEnergy)
		: m_conserveEnergy(conserveEnergy), m_keepEnergy(keepEnergy)
	{
	}
	std::unique_ptr<btActionInterface> makeAction() const override
	{
		btQuaternionHingeStabilizerSettings settings;
		settings.conserveEnergy = m_conserveEnergy;
		settings.keepEnergyAndMomentum = m_keepEnergy;
		return std::unique_ptr<btActionInterface>(new btQuaternionHingeStabilizer(settings));
	}

private:
	bool m_conserveEnergy;
	bool m_keepEnergy;
};
}  // namespace

const JointFactory* jointFactory(Kind kind)
{
	static const StockFactory stock;
	static const Generic6Dof2Factory generic6Dof2;
	static const QuaternionFactory quaternion;
	static const StabilizedQuaternionFactory stabilized(false, true);
	static const StabilizedQuaternionFactory stabilizedEnergy(true, true);
	static const StabilizedQuaternionFactory stabilizedDamped(false, false);
	static const Stabilized<StockFactory> stockStabilized;
	static const Stabilized<Generic6Dof2Factory> generic6Dof2Stabilized;
	switch (kind)
	{
		case Kind::Stock: return &stock;
		case Kind::Generic6Dof2: return &generic6Dof2;
		case Kind::Quaternion: return &quaternion;
		case Kind::QuaternionStabilized: return &stabilized;
		case Kind::QuaternionStabilizedEnergy: return &stabilizedEnergy;
		case Kind::QuaternionStabilizedDamped: return &stabilizedDamped;
		case Kind::MultiBody: return nullptr;
		case Kind::StockStabilized: return &stockStabilized;
		case Kind::Generic6Dof2Stabilized: return &generic6Dof2Stabilized;
		case Kind::StockMLCP:
		case Kind::StockNNCG: return &stock;  // the same joints; the solver differs (solverOf)
		case Kind::QuaternionMLCP:
		case Kind::QuaternionNNCG: return &quaternion;
		case Kind::MultiBodyDamped: return nullptr;
	}
	return nullptr;
}

}  // namespace scenes
}  // namespace quathinge
