// Never off for good (issue 37): the energy default's state lives with the island, so an app that rebuilds the
// stabilizer's islands every step (invalidateStructure()) must get the same energies. Measured on the energy scenes
// the stabilizer tests use: a chain of 1, 3 and 10 links and a 4-link chain with a 1:100 tip, 20 s at 60 Hz.
#ifdef QUATHINGE_HAVE_STABILIZER
#include "support/StabilizerScene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

using namespace qh_test;

namespace
{
// The swing energy (J): kinetic plus m g (y − y_low) per link, y_low its centre's height with the chain hanging
// straight down from the world pivot at height 10 m (links 0.5 m); its average over the last second of 20 s.
double lastSecondEnergy(int links, btScalar tipMass, bool invalidateEveryStep)
{
	StabilizerScene scene;
	const std::vector<btRigidBody*> chain = scene.chain(links, tipMass);
	btQuaternionHingeStabilizer stabilizer;
	scene.addAction(&stabilizer);
	const int steps = 20 * 60, averaged = 60;
	double sum = 0;
	for (int i = 0; i < steps; ++i)
	{
		if (invalidateEveryStep) stabilizer.invalidateStructure();
		scene.world().stepSimulation(kTimeStep, 0);
		if (i < steps - averaged) continue;
		double e = 0;
		for (size_t k = 0; k < chain.size(); ++k)
		{
			const btRigidBody& b = *chain[k];
			const double m = 1 / double(b.getInvMass());
			const btVector3 w = b.getAngularVelocity() * b.getCenterOfMassTransform().getBasis();  // body frame
			const btVector3& inv = b.getInvInertiaDiagLocal();
			e += 0.5 * m * double(b.getLinearVelocity().length2()) +
				 0.5 * double(w.x() * w.x() / inv.x() + w.y() * w.y() / inv.y() + w.z() * w.z() / inv.z()) +
				 m * 10 * (double(b.getCenterOfMassPosition().y()) - (10 - 0.25 - 0.5 * double(k)));
		}
		sum += e;
	}
	return sum / averaged;
}
}  // namespace

TEST(StabilizerNeverOff, InvalidatingEveryStepChangesNoEnergyByMoreThanOnePercent)
{
	const double kChange = 0.01;  // of the run's own swing energy (1 s average at 20 s)
	const struct
	{
		int links;
		btScalar tip;
	} cases[] = {{1, 1}, {3, 1}, {10, 1}, {4, 100}};
	for (const auto& c : cases)
	{
		const double kept = lastSecondEnergy(c.links, c.tip, false);
		const double rebuilt = lastSecondEnergy(c.links, c.tip, true);
		std::printf("[ figures  ] %d links, tip %g kg: swing energy at 20 s %.5g J, rebuilt every step %.5g J (%+.3g%%)\n",
					c.links, double(c.tip), kept, rebuilt, 100 * (rebuilt / kept - 1));
		EXPECT_NEAR(rebuilt / kept, 1, kChange) << c.links << " links, tip " << c.tip;
	}
}
#endif
