// A scene run as the kind comparisons in the tests run it: at the scene's own step (sceneStep), with the given solver
// iterations, without the fine-step reference. For test files built with the scene library (QUATHINGE_HAVE_SCENES).
#ifndef QUATHINGE_TEST_SCENE_RUNS_H
#define QUATHINGE_TEST_SCENE_RUNS_H

#include "JointKinds.h"
#include "SceneSpec.h"

namespace qh_test
{
inline quathinge::scenes::Metrics runAtOwnStep(const quathinge::scenes::SceneSpec& scene,
											   quathinge::scenes::Kind kind, int iterations)
{
	quathinge::scenes::RunSettings settings;
	settings.dt = quathinge::scenes::sceneStep(scene);
	settings.iterations = iterations;
	settings.reference = false;
	return quathinge::scenes::runScene(scene, kind, settings);
}
}  // namespace qh_test

#endif
