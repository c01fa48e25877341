// A scene run as the kind comparisons in the tests run it: at the scene's own step (sceneStep), with the given solver
// iterations, without the fine-step reference. For test files built with the scene library (QUATHINGE_HAVE_SCENES).
#ifndef QUATHINGE_TEST_SCENE_RUNS_H
#define QUATHINGE_TEST_SCENE_RUNS_H

#include "JointKinds.h"
#include "SceneSpec.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

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

/// Every library scene (sceneNames, seed 1) this build can make. The models are the project's own (demos/models): only
/// a build without an optional library may leave a scene out, and it says so (checked, and printed as left out).
inline std::vector<quathinge::scenes::SceneSpec> availableScenes()
{
	std::vector<quathinge::scenes::SceneSpec> scenes;
	for (const std::string& name : quathinge::scenes::sceneNames())
	{
		quathinge::scenes::SceneSpec scene = quathinge::scenes::makeScene(name, 1);
		if (!scene.unavailable.empty())
		{
			EXPECT_EQ(scene.unavailable.rfind("built without", 0), 0u) << name << ": " << scene.unavailable;
			std::printf("[ left out ] %s: %s\n", name.c_str(), scene.unavailable.c_str());
			continue;
		}
		scenes.push_back(std::move(scene));
	}
	return scenes;
}
}  // namespace qh_test

#endif
