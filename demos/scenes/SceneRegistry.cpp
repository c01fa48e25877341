// The list of scenes, by name, and the helpers several scenes share.
#include "SceneSpec.h"

#include <cstdlib>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <utility>

namespace quathinge
{
namespace scenes
{
bool isTree(const SceneSpec& scene)
{
	// the edges: hinges and sliders alike
	std::vector<std::pair<int, int>> edges;  // parent, child
	for (const JointSpec& j : scene.joints) edges.emplace_back(j.parent, j.child);
	for (const SliderSpec& j : scene.sliders) edges.emplace_back(j.parent, j.child);
	std::vector<int> parents(scene.bodies.size(), 0);
	for (const auto& e : edges)
		if (++parents[size_t(e.second)] > 1) return false;
	// one parent each; a loop would need a body to be its own ancestor
	for (const auto& start : edges)
	{
		int body = start.first;
		for (size_t hops = 0; body >= 0 && hops <= edges.size(); ++hops)
		{
			int next = -1;
			for (const auto& e : edges)
				if (e.second == body) next = e.first;
			if (next == start.second) return false;
			body = next;
		}
	}
	return true;
}

void appendChain(SceneSpec& scene, int links, btScalar length, btScalar mass, const btVector3& top,
				 const std::function<btVector3(int)>& axisOf)
{
	// links laid along +x from `top` (released horizontally), each a box whose long local y axis lies along the chain
	const btQuaternion alongX(btVector3(0, 0, 1), -SIMD_HALF_PI);  // local +y → world +x
	const int first = int(scene.bodies.size());
	for (int i = 0; i < links; ++i)
	{
		BodySpec body;
		body.mass = mass;
		body.halfExtents = btVector3(btScalar(0.05), length / 2, btScalar(0.05));
		body.pose = btTransform(alongX, top + btVector3(length * (btScalar(i) + btScalar(0.5)), 0, 0));
		scene.bodies.push_back(body);
		JointSpec joint;
		joint.parent = i == 0 ? -1 : first + i - 1;
		joint.child = first + i;
		joint.pivot = top + btVector3(length * btScalar(i), 0, 0);
		joint.axis = axisOf(i).normalized();
		scene.joints.push_back(joint);
	}
}

std::vector<std::string> sceneNames()
{
	// the scenes this build can make: the .bullet scene needs Bullet's world importer, the URDF robots urdfdom and
	// tinyxml2 (both optional; configure says which are left out)
	std::vector<std::string> names = {"pendulum", "chain10", "chain30", "chain100", "heavy10",
									  "heavy100", "heavy1000", "heavy10000", "double_pendulum", "rotor100",
									  "rotor1000", "flipped90", "flipped179", "flipped180", "limit_hit",
									  "limit_across_pi", "limit_wide", "motor_lift", "four_bar", "ragdoll"};
#ifdef QUATHINGE_HAVE_WORLD_IMPORTER
	names.push_back("spider");
#endif
#ifdef QUATHINGE_HAVE_URDFDOM
	for (const char* robot : {"kuka_iiwa", "pendulum5", "humanoid", "base_2", "quadruped", "two_joint_robot", "minitaur",
							  "r2d2", "panda"})
		names.push_back(robot);
#endif
	for (const char* name : {"inertia_ratio", "rest500", "rest500_asleep"}) names.push_back(name);
	return names;
}

std::string defaultModelsDir()
{
	if (const char* dir = std::getenv("QUATHINGE_MODELS_DIR"); dir && *dir) return dir;
	// An installed program: <prefix>/bin/quathinge-compare finds <prefix>/share/quathinge/models.
	std::error_code error;
	const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", error);
	if (!error)
	{
		const std::filesystem::path installed = exe.parent_path().parent_path() / "share" / "quathinge" / "models";
		if (std::filesystem::is_directory(installed, error)) return installed.string();
	}
	return QUATHINGE_SOURCE_MODELS_DIR;  // the build tree: this source tree's demos/models
}

std::string manualDir()
{
	// An installed program: <prefix>/bin/quathinge-compare finds <prefix>/share/doc/quathinge/docs (QuatHingeInstall.cmake).
	std::error_code error;
	const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", error);
	if (!error)
	{
		const std::filesystem::path installed =
			exe.parent_path().parent_path() / "share" / "doc" / "quathinge" / "docs";
		if (std::filesystem::is_directory(installed, error)) return installed.string();
	}
	return QUATHINGE_SOURCE_DOCS_DIR;  // the build tree: this source tree's docs
}

SceneSpec makeScene(const std::string& name, unsigned seed, const std::string& modelsArgument)
{
	const std::string modelsDir = modelsArgument.empty() ? defaultModelsDir() : modelsArgument;
	if (name == "pendulum") return pendulumScene();
	if (name == "chain10") return chainScene(10, seed);
	if (name == "chain30") return chainScene(30, seed);
	if (name == "chain100") return chainScene(100, seed);
	if (name == "heavy10") return heavyLoadScene(10);
	if (name == "heavy100") return heavyLoadScene(100);
	if (name == "heavy1000") return heavyLoadScene(1000);
	if (name == "heavy10000") return heavyLoadScene(10000);
	if (name == "double_pendulum") return doublePendulumScene();
	if (name == "rotor100") return rotorScene(100);
	if (name == "rotor1000") return rotorScene(1000);
	if (name == "flipped90") return flippedStartScene(90);
	if (name == "flipped179") return flippedStartScene(179);
	if (name == "flipped180") return flippedStartScene(180);
	if (name == "limit_hit") return limitHitScene();
	if (name == "limit_across_pi") return limitAcrossPiScene();
	if (name == "limit_wide") return limitWideScene();
	if (name == "motor_lift") return motorLiftScene();
	if (name == "four_bar") return fourBarScene();
	if (name == "ragdoll") return ragdollScene(seed);
	if (name == "rest500") return restScene(50, 10, false);
	if (name == "rest500_asleep") return restScene(50, 10, true);
	// Gazebo's inertia-ratio pendulum (scene_inertia_ratio.cpp), and its family inertia_ratio_<N>, a 1:N mass ratio
	if (name == "inertia_ratio") return inertiaRatioScene(0);
	if (name.rfind("inertia_ratio_", 0) == 0)
	{
		const std::string ratio = name.substr(14);
		if (!ratio.empty() && ratio.find_first_not_of("0123456789") == std::string::npos && ratio.size() < 7 &&
			std::stoi(ratio) >= 1)
			return inertiaRatioScene(std::stoi(ratio));
	}
	if (name == "spider") return spiderScene(modelsDir);
	if (name == "kuka_iiwa") return urdfScene(name, modelsDir + "/kuka_iiwa_model.urdf");
	if (name == "pendulum5") return urdfScene(name, modelsDir + "/pendulum5.urdf");
	// robots from Bullet's data/ (demos/models/NOTICE.md), read as pybullet reads them
	if (name == "humanoid") return urdfScene(name, modelsDir + "/humanoid.urdf");
	if (name == "base_2") return urdfScene(name, modelsDir + "/Base_2.urdf");
	if (name == "quadruped") return urdfScene(name, modelsDir + "/quadruped.urdf");
	if (name == "two_joint_robot") return urdfScene(name, modelsDir + "/TwoJointRobot_w_fixedJoints.urdf");
	if (name == "minitaur") return urdfScene(name, modelsDir + "/minitaur.urdf");
	// with prismatic joints (SceneSpec::sliders): r2d2's gripper extension, the panda's fingers
	if (name == "r2d2") return urdfScene(name, modelsDir + "/r2d2/r2d2.urdf");
	if (name == "panda") return urdfScene(name, modelsDir + "/franka_panda/panda.urdf");
	if (name.size() > 5 && name.compare(name.size() - 5, 5, ".urdf") == 0) return urdfScene(name, name);
	throw std::invalid_argument("makeScene: name: unknown scene '" + name + "'");
}

}  // namespace scenes
}  // namespace quathinge
