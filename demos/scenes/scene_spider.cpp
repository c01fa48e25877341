// The spider of bullet3's MotorDemo, read from demos/models/spider.bullet with Debian's world importer: 27
// bodies, 24 btHingeConstraints with limits and motors. The kinds convert its hinges (Simulation.cpp).
#include "SceneSpec.h"

#include <fstream>

namespace quathinge
{
namespace scenes
{
SceneSpec spiderScene(const std::string& modelsDir)
{
	SceneSpec s;
	s.name = "spider";
	s.description = "spider.bullet: 27 bodies, 24 hinges with limits and motors, standing on the ground";
	s.bulletFile = modelsDir + "/spider.bullet";
	s.reference = Reference::None;
	s.gravity = btVector3(0, -10, 0);
	s.duration = 3;
	if (!std::ifstream(s.bulletFile)) s.unavailable = "spider.bullet not found at " + s.bulletFile;
	return s;
}

}  // namespace scenes
}  // namespace quathinge
