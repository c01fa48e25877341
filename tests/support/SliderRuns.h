// A scene with sliders (SceneSpec::sliders: Bullet's Panda, its fingers on 6-dof sliders) run at 60 Hz, 10 iterations,
// with the stabilizer's settings given: the largest distance of a slider's child off its slide line, the farthest past
// its limits, and the largest hinge separation (m) after any step. For the stabilizer test files built with the scene library.
#ifndef QUATHINGE_TEST_SLIDER_RUNS_H
#define QUATHINGE_TEST_SLIDER_RUNS_H

#include "JointKinds.h"
#include "SceneSpec.h"
#include "Simulation.h"

#include "quathinge/btQuaternionHingeStabilizer.h"

#include <algorithm>

namespace qh_test
{
struct SliderRunErrors
{
	double sliders = 0;      // m
	double hinges = 0;       // m
	double slidersPast = 0;  // m: the farthest a slider's child is past its limits along the slide
};

inline SliderRunErrors runWithSliders(const quathinge::scenes::SceneSpec& scene, quathinge::scenes::Kind kind,
									  const btQuaternionHingeStabilizerSettings& settings, int steps = 180)
{
	using namespace quathinge::scenes;
	Simulation sim(scene, kind);
	if (sim.stabilizer()) sim.stabilizer()->setSettings(settings);
	SliderRunErrors worst;
	for (int i = 0; i < steps; ++i)
	{
		sim.step(1.0 / 60, 10);
		for (const MeasuredJoint& s : sim.sliders)
		{
			worst.sliders = std::max(worst.sliders, measureSliderSeparation(s));
			worst.slidersPast = std::max(worst.slidersPast, measureSliderPastLimits(s));
		}
		for (const MeasuredJoint& j : sim.joints) worst.hinges = std::max(worst.hinges, measureJointError(j).separation);
	}
	return worst;
}
}  // namespace qh_test

#endif
