// Issue 16: the double pendulum of the scene library (demos/scenes/scene_double_pendulum.cpp: a 1 kg thin upper link
// on a fixed anchor, a 20 kg wide block below it, gravity 3° off the plane). Gauss–Seidel cannot stop the block's
// swing out of the plane within a step (it reaches the anchor only through the link's small inertia about its own
// axis), so some swing is left at the anchor under any row basis. The anchor's axial row used to take the quaternion
// rows' errors off with their Jacobian (fillBilateralRows, the free axial arm), which made that swing a standing pivot
// offset of lever × swing: 0.052 m, 2.5× stock's largest separation at 250 iterations. Its error is now the pivot's own
// axial offset, as stock's: 1.06×. Figures per iteration count against stock's run of the same scene.
#ifdef QUATHINGE_HAVE_SCENES
#include "JointKinds.h"
#include "SceneSpec.h"
#include "support/SceneRuns.h"

#include <gtest/gtest.h>

#include <cstdio>

using namespace quathinge::scenes;

namespace
{
// the bound on the largest separation, quaternion ÷ stock (before: 2.08 at 50 iterations, 2.50 at 250)
const double kMaxSeparationRatio = 1.2;
// at 50 iterations the largest separation is the elbow's (after: 1.21; before: the anchor's, 2.08)
const double kMaxSeparationRatioAt50 = 1.3;
// RMS over the run (before: 2.09 at 50, 2.10 at 250; after: 1.50, 1.29): not yet within the 1.2, the
// anchor's swing rate left by Gauss–Seidel still moves its pivot along the axis (docs/ROW_BASIS.md)
const double kRmsSeparationRatio = 1.6;
}  // namespace

TEST(DoublePendulum, AnchorSwingLeftByGaussSeidelDoesNotBecomeAStandingSeparation)
{
	const SceneSpec scene = makeScene("double_pendulum");
	for (int iterations : {50, 250})
	{
		const Metrics stock = qh_test::runAtOwnStep(scene, Kind::Stock, iterations);
		const Metrics quaternion = qh_test::runAtOwnStep(scene, Kind::Quaternion, iterations);
		ASSERT_FALSE(stock.blewUp);
		ASSERT_FALSE(quaternion.blewUp);
		const double maxRatio = quaternion.maxSeparation / stock.maxSeparation;
		const double rmsRatio = quaternion.rmsSeparation / stock.rmsSeparation;
		std::printf(
			"[ figures  ] double_pendulum %d iterations: max separation %.3e m (stock %.3e, %.2fx), RMS "
			"%.3e m (stock %.3e, %.2fx)\n",
			iterations, quaternion.maxSeparation, stock.maxSeparation, maxRatio, quaternion.rmsSeparation,
			stock.rmsSeparation, rmsRatio);
		EXPECT_LE(maxRatio, iterations == 250 ? kMaxSeparationRatio : kMaxSeparationRatioAt50) << iterations;
		EXPECT_LE(rmsRatio, kRmsSeparationRatio) << iterations;
	}
}
#endif
