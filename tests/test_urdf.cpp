// The URDF loader reads what pybullet's importer reads (capsules, lower > upper as no limit, pybullet's limit
// defaults, STL and OBJ meshes), refuses what it cannot represent with the file, the part and the reason, and the robots from
// Bullet's data/ (demos/models) run with the quaternion kinds and are held by the stabilizer.
// (registered only when built with urdfdom and tinyxml2, which are optional)
#if defined(QUATHINGE_HAVE_SCENES) && defined(QUATHINGE_HAVE_URDF)
#include "JointKinds.h"
#include "SceneSpec.h"
#include "Simulation.h"

#include <BulletCollision/CollisionShapes/btCompoundShape.h>
#include <btBulletDynamicsCommon.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>

using namespace quathinge::scenes;

namespace
{
std::string readFile(const std::string& path)
{
	std::ifstream file(path);
	std::stringstream text;
	text << file.rdbuf();
	return text.str();
}

size_t countOf(const std::string& text, const std::string& word)
{
	size_t n = 0;
	for (size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) ++n;
	return n;
}

/// A folder of its own in the system's temporary directory, removed at the end.
class TempDir
{
public:
	TempDir()
		: m_path(std::filesystem::temp_directory_path() /
				 ("quathinge_urdf_" + std::to_string(::getpid()) + "_" +
				  ::testing::UnitTest::GetInstance()->current_test_info()->name()))
	{
		std::filesystem::create_directories(m_path);
	}
	~TempDir() { std::filesystem::remove_all(m_path); }
	TempDir(const TempDir&) = delete;
	TempDir& operator=(const TempDir&) = delete;
	/// Writes `text` to `name` in the folder; returns its path.
	std::string write(const std::string& name, const std::string& text) const
	{
		const std::string path = (m_path / name).string();
		std::ofstream(path) << text;
		return path;
	}

private:
	std::filesystem::path m_path;
};

/// A two-link robot: base (the world) → arm, joined by a joint `jointType` with the children `jointBody` (axis x
/// unless it has its own <axis>), the arm's collision geometry `geometry`.
std::string robot(const std::string& jointType, const std::string& jointBody, const std::string& geometry = "<box size=\"0.1 0.1 0.5\"/>")
{
	return "<?xml version=\"1.0\"?>\n<robot name=\"tiny\">\n"
		   "  <link name=\"base\"/>\n"
		   "  <link name=\"arm\">\n"
		   "    <inertial><origin xyz=\"0 0 -0.25\"/><mass value=\"1\"/>"
		   "<inertia ixx=\"0.02\" ixy=\"0\" ixz=\"0\" iyy=\"0.02\" iyz=\"0\" izz=\"0.001\"/></inertial>\n"
		   "    <collision><origin xyz=\"0 0 -0.25\"/><geometry>" +
		   geometry +
		   "</geometry></collision>\n"
		   "  </link>\n"
		   "  <joint name=\"shoulder\" type=\"" +
		   jointType +
		   "\"><parent link=\"base\"/><child link=\"arm\"/>" +
		   (jointBody.find("<axis") == std::string::npos ? "<axis xyz=\"1 0 0\"/>" : "") + jointBody +
		   "</joint>\n"
		   "</robot>\n";
}

void expectRefused(const SceneSpec& scene, const std::string& path, const std::vector<std::string>& mentions)
{
	EXPECT_FALSE(scene.unavailable.empty()) << path << " loaded, but should be refused";
	EXPECT_NE(scene.unavailable.find(path), std::string::npos) << "the refusal names the file: " << scene.unavailable;
	for (const std::string& word : mentions)
		EXPECT_NE(scene.unavailable.find(word), std::string::npos) << "the refusal says '" << word << "': " << scene.unavailable;
	EXPECT_TRUE(scene.joints.empty() && scene.bodies.empty()) << "a refused scene has nothing to run";
}
}  // namespace

TEST(Urdf, HumanoidLoadsEveryCollisionShape)
{
	const SceneSpec scene = makeScene("humanoid");
	ASSERT_TRUE(scene.unavailable.empty()) << scene.unavailable;
	const std::string text = readFile(defaultModelsDir() + "/humanoid.urdf");
	const size_t collisions = countOf(text, "<collision>");
	ASSERT_EQ(countOf(text, "<visual"), 0u);  // so every <capsule>/<sphere> in the file is a collision's
	ASSERT_GT(collisions, 0u);
	size_t parts = scene.worldParts.size(), capsules = 0, spheres = 0;
	for (const ShapePart& p : scene.worldParts) capsules += p.shape == Shape::Capsule, spheres += p.shape == Shape::Sphere;
	for (const BodySpec& b : scene.bodies)
	{
		parts += b.parts.size();
		for (const ShapePart& p : b.parts) capsules += p.shape == Shape::Capsule, spheres += p.shape == Shape::Sphere;
	}
	EXPECT_EQ(parts, collisions);
	EXPECT_EQ(capsules, countOf(text, "<capsule"));
	EXPECT_EQ(spheres, countOf(text, "<sphere"));
	// the torso (the root: the world) first collision: <capsule length="0.14" radius="0.07"/> turned −90° about x,
	// so its axis is world y; the scene's capsule is along its local y with the caps in its half length
	ASSERT_EQ(scene.worldParts.size(), 3u);
	const ShapePart& torso = scene.worldParts[0];
	ASSERT_EQ(torso.shape, Shape::Capsule);
	const double kDimensionTolerance = 1e-6;  // m: the file's decimals read back
	EXPECT_NEAR(torso.halfExtents.x(), 0.07, kDimensionTolerance);
	EXPECT_NEAR(torso.halfExtents.y(), 0.07 + 0.07, kDimensionTolerance);
	const btVector3 axis = torso.local.getBasis() * btVector3(0, 1, 0);
	const double kAxisTolerance = 1e-4;  // rad: the file writes −1.57080 for −π/2
	EXPECT_NEAR(std::fabs(axis.y()), 1, kAxisTolerance) << axis.x() << " " << axis.y() << " " << axis.z();

	// and the worlds built from it carry them: each body's compound has its pieces
	for (Kind kind : {Kind::Stock, Kind::Quaternion})
	{
		Simulation sim(scene, kind);
		ASSERT_EQ(sim.bodies.size(), scene.bodies.size());
		size_t built = 0;
		for (size_t i = 0; i < sim.bodies.size(); ++i)
		{
			const btCollisionShape* shape = sim.bodies[i]->getCollisionShape();
			if (scene.bodies[i].parts.empty()) continue;
			ASSERT_EQ(shape->getShapeType(), COMPOUND_SHAPE_PROXYTYPE);
			const auto* compound = static_cast<const btCompoundShape*>(shape);
			EXPECT_EQ(size_t(compound->getNumChildShapes()), scene.bodies[i].parts.size());
			for (int c = 0; c < compound->getNumChildShapes(); ++c)
			{
				const int type = compound->getChildShape(c)->getShapeType();
				EXPECT_EQ(type, scene.bodies[i].parts[size_t(c)].shape == Shape::Capsule ? CAPSULE_SHAPE_PROXYTYPE
																						 : SPHERE_SHAPE_PROXYTYPE);
			}
			built += size_t(compound->getNumChildShapes());
		}
		EXPECT_EQ(built + scene.worldParts.size(), collisions) << kindName(kind);
	}
}

TEST(Urdf, KukaMeshesAreConvexHulls)
{
	const SceneSpec scene = makeScene("kuka_iiwa");
	ASSERT_TRUE(scene.unavailable.empty()) << scene.unavailable;
	size_t hulls = scene.worldParts.size();
	for (const BodySpec& b : scene.bodies)
		for (const ShapePart& p : b.parts)
		{
			EXPECT_EQ(p.shape, Shape::ConvexHull);
			EXPECT_GE(p.points.size(), 4u);
			++hulls;
		}
	EXPECT_EQ(hulls, countOf(readFile(defaultModelsDir() + "/kuka_iiwa_model.urdf"), "<collision>"));
}

TEST(Urdf, LowerAboveUpperIsContinuous)
{
	// Base_2.urdf writes lower="1" upper="0" on every revolute joint: URDF2Bullet reads it as no limit
	const SceneSpec base2 = makeScene("base_2");
	ASSERT_TRUE(base2.unavailable.empty()) << base2.unavailable;
	const std::string text = readFile(defaultModelsDir() + "/Base_2.urdf");
	ASSERT_EQ(base2.joints.size(), countOf(text, "type=\"revolute\""));
	for (const JointSpec& j : base2.joints) EXPECT_FALSE(j.hasLimit);

	TempDir dir;
	struct Case
	{
		std::string limit;
		bool hasLimit;
		double lower, upper;
	};
	const Case cases[] = {
		{"<limit effort=\"0\" lower=\"1\" upper=\"0\" velocity=\"1\"/>", false, 0, 0},  // lower > upper: free
		{"<limit effort=\"1\" lower=\"-0.5\" upper=\"0.5\" velocity=\"1\"/>", true, -0.5, 0.5},
		{"<limit effort=\"1\" velocity=\"1\"/>", false, 0, 0},  // pybullet's defaults 0 and −1 (urdfdom: locked at 0)
		{"<limit lower=\"-1\" upper=\"2\"/>", true, -1, 2},     // no effort or velocity: pybullet reads it
		{"<limit lower=\"0.25\" upper=\"0.25\"/>", true, 0.25, 0.25},
	};
	for (const Case& c : cases)
	{
		const std::string path = dir.write("limit.urdf", robot("revolute", c.limit));
		const SceneSpec s = urdfScene("limit", path);
		ASSERT_TRUE(s.unavailable.empty()) << c.limit << ": " << s.unavailable;
		ASSERT_EQ(s.joints.size(), 1u);
		EXPECT_EQ(s.joints[0].hasLimit, c.hasLimit) << c.limit;
		if (c.hasLimit)
		{
			EXPECT_EQ(double(s.joints[0].lower), double(btScalar(c.lower))) << c.limit;
			EXPECT_EQ(double(s.joints[0].upper), double(btScalar(c.upper))) << c.limit;
		}
	}
	// and the free joint swings past where a [0, 1] or [1, 0] stop would hold it: the arm, released horizontally
	// about x, falls through −π/2
	const std::string path = dir.write("free.urdf", robot("revolute", "<origin rpy=\"1.5708 0 0\"/><limit lower=\"1\" upper=\"0\"/>"));
	const SceneSpec s = urdfScene("free", path);
	ASSERT_TRUE(s.unavailable.empty()) << s.unavailable;
	for (Kind kind : {Kind::Stock, Kind::Quaternion, Kind::QuaternionStabilized})
	{
		Simulation sim(s, kind);
		double lowest = 0;
		for (int i = 0; i < 60; ++i)
		{
			sim.step(1.0 / 60, 10);
			lowest = std::min(lowest, double(sim.bodies[0]->getCenterOfMassPosition().z()));
		}
		const double kSwing = 0.2;  // m: the centre 0.25 m from the pivot passes well below it
		EXPECT_LT(lowest, -kSwing) << kindName(kind);
	}
}

TEST(Urdf, APrismaticJointIsASliderThatEveryKindBuilds)
{
	// base (the world) → arm, hinged about x, hanging along −z → finger, sliding along the arm (z) as a gripper's
	// finger does (panda.urdf, r2d2.urdf); pybullet loads such a file, and so must the scene library. The
	// maximal-coordinate kinds build the slider alike (a 6-dof constraint); the multibody kind, a prismatic link
	const auto gripper = [](const std::string& limit) {
		return std::string(
				   "<?xml version=\"1.0\"?>\n<robot name=\"gripper\">\n  <link name=\"base\"/>\n"
				   "  <link name=\"arm\"><inertial><origin xyz=\"0 0 -0.25\"/><mass value=\"1\"/>"
				   "<inertia ixx=\"0.02\" ixy=\"0\" ixz=\"0\" iyy=\"0.02\" iyz=\"0\" izz=\"0.001\"/></inertial></link>\n"
				   "  <link name=\"finger\"><inertial><mass value=\"0.1\"/>"
				   "<inertia ixx=\"1e-4\" ixy=\"0\" ixz=\"0\" iyy=\"1e-4\" iyz=\"0\" izz=\"1e-4\"/></inertial></link>\n"
				   "  <joint name=\"shoulder\" type=\"continuous\"><parent link=\"base\"/><child link=\"arm\"/>"
				   "<axis xyz=\"1 0 0\"/></joint>\n"
				   "  <joint name=\"slide\" type=\"prismatic\"><parent link=\"arm\"/><child link=\"finger\"/>"
				   "<origin xyz=\"0 0 -0.5\"/><axis xyz=\"0 0 1\"/>") +
			   limit + "</joint>\n</robot>\n";
	};
	TempDir dir;
	const SceneSpec limited = urdfScene("limited", dir.write("limited.urdf", gripper("<limit lower=\"-0.1\" upper=\"0\"/>")));
	ASSERT_TRUE(limited.unavailable.empty()) << limited.unavailable;
	ASSERT_EQ(limited.joints.size(), 1u);  // the hinge: the only compared joint
	ASSERT_EQ(limited.sliders.size(), 1u);
	const SliderSpec& s = limited.sliders[0];
	EXPECT_EQ(s.parent, 0);
	EXPECT_EQ(s.child, 1);
	EXPECT_NEAR(double(s.axis.z()), 1, 1e-6);
	EXPECT_NEAR(double(s.pivot.z()), -0.5, 1e-6);
	EXPECT_TRUE(s.hasLimit);
	EXPECT_EQ(double(s.lower), double(btScalar(-0.1)));
	EXPECT_EQ(double(s.upper), 0.0);
	EXPECT_FALSE(limited.conservative) << "a stop can take energy out";
	const SceneSpec free = urdfScene("free", dir.write("free.urdf", gripper("<limit lower=\"1\" upper=\"0\"/>")));
	ASSERT_TRUE(free.unavailable.empty()) << free.unavailable;
	ASSERT_EQ(free.sliders.size(), 1u);
	EXPECT_FALSE(free.sliders[0].hasLimit) << "lower > upper: no limit, as pybullet";
	// 1 s at 60 Hz: gravity (−z) pulls the finger down the arm. Limited, it rests on its stop 0.1 m down; free, it
	// falls on (5 m in a second); either way it stays on the arm's line
	const double kStopSlack = 5e-3;  // m: how far from its stop the solver may leave the finger
	const double kOffLine = 1e-3;    // m: the slider's distance from its line (a 6-dof constraint at 10 iterations)
	const double kFreeFall = 1.0;    // m: the free finger falls at least this far
	for (Kind kind : {Kind::Stock, Kind::Generic6Dof2, Kind::Quaternion, Kind::QuaternionStabilized, Kind::MultiBody})
	{
		for (const SceneSpec* scene : {&limited, &free})
		{
			Simulation sim(*scene, kind);
			ASSERT_EQ(sim.sliders.size(), 1u);
			for (int i = 0; i < 60; ++i) sim.step(1.0 / 60, 10);
			const double z = double(sim.bodies[1]->getCenterOfMassPosition().z());
			if (scene == &limited)
			{
				EXPECT_NEAR(z, -0.6, kStopSlack) << kindName(kind);
			}
			else
			{
				EXPECT_LT(z, -0.5 - kFreeFall) << kindName(kind);
			}
			EXPECT_LT(measureSliderSeparation(sim.sliders[0]), kOffLine) << kindName(kind);
		}
		RunSettings settings;
		settings.duration = 1;
		settings.reference = false;
		const Metrics m = runScene(limited, kind, settings);
		ASSERT_TRUE(m.skipped.empty()) << m.skipped;
		EXPECT_GE(m.maxSliderSeparation, 0.0) << kindName(kind) << ": the slider is measured";
		EXPECT_LT(m.maxSliderSeparation, kOffLine) << kindName(kind);
	}
	EXPECT_TRUE(isTree(limited));
}

TEST(Urdf, RefusesWhatItCannotRepresent)
{
	TempDir dir;
	struct Case
	{
		std::string name, text;
		std::vector<std::string> mentions;
	};
	const Case cases[] = {
		{"planar.urdf", robot("planar", "<limit lower=\"0\" upper=\"1\" effort=\"1\" velocity=\"1\"/>"), {"shoulder", "planar"}},
		{"spherical.urdf", robot("spherical", ""), {"shoulder", "spherical"}},
		{"floating.urdf", robot("floating", ""), {"shoulder", "floating"}},
		{"zero_axis.urdf", robot("continuous", "<axis xyz=\"0 0 0\"/>"), {"shoulder", "axis"}},
		{"dae_mesh.urdf", robot("continuous", "", "<mesh filename=\"arm.dae\"/>"), {"arm", "arm.dae", "STL and OBJ"}},
		{"missing_obj.urdf", robot("continuous", "", "<mesh filename=\"arm.obj\"/>"), {"arm", "arm.obj", "not found"}},
		{"missing_mesh.urdf", robot("continuous", "", "<mesh filename=\"nowhere.stl\"/>"), {"arm", "nowhere.stl", "not found"}},
		{"unknown_shape.urdf", robot("continuous", "", "<cone radius=\"0.1\" length=\"0.2\"/>"), {"urdfdom"}},
		{"broken.urdf", "<robot name=\"x\"><link name=\"a\">", {"XML"}},
	};
	for (const Case& c : cases)
	{
		const std::string path = dir.write(c.name, c.text);
		expectRefused(urdfScene(c.name, path), path, c.mentions);
	}
	// an STL that is there loads (binary: header, count, one triangle of 50 bytes — 4 vertices needed, so two)
	std::string stl(80, ' ');
	const uint32_t triangles = 2;
	stl.append(reinterpret_cast<const char*>(&triangles), 4);
	const float tri[2][12] = {{0, 0, 1, 0, 0, 0, 0.1f, 0, 0, 0, 0.1f, 0}, {0, 0, 1, 0, 0, 0, 0.1f, 0, 0, 0, 0, -0.5f}};
	for (const auto& t : tri)
	{
		stl.append(reinterpret_cast<const char*>(t), sizeof t);
		stl.append(2, '\0');
	}
	dir.write("arm.stl", stl);
	const std::string path = dir.write("stl_mesh.urdf", robot("continuous", "", "<mesh filename=\"arm.stl\" scale=\"2 2 2\"/>"));
	const SceneSpec s = urdfScene("stl", path);
	ASSERT_TRUE(s.unavailable.empty()) << s.unavailable;
	ASSERT_EQ(s.bodies.size(), 1u);
	ASSERT_EQ(s.bodies[0].parts.size(), 1u);
	EXPECT_EQ(s.bodies[0].parts[0].points.size(), 6u);
	EXPECT_EQ(double(s.bodies[0].parts[0].points[5].z()), -1.0);  // −0.5 m scaled by 2

	// an OBJ is a convex hull per group of faces ('g' and 'o' start one; indices from 1, negative from the end),
	// each a piece at the <collision>'s pose
	dir.write("arm.obj",
			  "# two pieces\nv 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 -0.5\n"
			  "g first\nf 1 2 3\nf 1/1 2/2 4/4\no second\nv 0.2 0 0\nf -1//1 -2 -3\n");
	const std::string objPath = dir.write("obj_mesh.urdf", robot("continuous", "", "<mesh filename=\"arm.obj\"/>"));
	const SceneSpec o = urdfScene("obj", objPath);
	ASSERT_TRUE(o.unavailable.empty()) << o.unavailable;
	ASSERT_EQ(o.bodies.size(), 1u);
	ASSERT_EQ(o.bodies[0].parts.size(), 2u);
	EXPECT_EQ(o.bodies[0].parts[0].points.size(), 6u);
	EXPECT_EQ(o.bodies[0].parts[1].points.size(), 3u);
	EXPECT_EQ(double(o.bodies[0].parts[1].points[0].x()), double(btScalar(0.2)));  // index −1: the last vertex
	EXPECT_TRUE(o.bodies[0].parts[0].local == o.bodies[0].parts[1].local);
	const std::string badPath = dir.write("bad_obj.urdf", robot("continuous", "", "<mesh filename=\"bad.obj\"/>"));
	dir.write("bad.obj", "v 0 0 0\nf 1 2 3\n");
	expectRefused(urdfScene("bad", badPath), badPath, {"arm", "out of range"});
}

TEST(Urdf, BulletRobotsRunWithTheQuaternionKinds)
{
	// 3 s at 60 Hz, 10 iterations (the default settings): every robot that stock runs runs with the quaternion kinds
	// and the stabilizer holds it
	RunSettings settings;
	settings.duration = 3;
	settings.reference = false;
	const double kHeld = 1e-4;  // m: the stabilizer's separation bound
	for (const char* name :
		 {"humanoid", "base_2", "quadruped", "two_joint_robot", "kuka_iiwa", "pendulum5", "minitaur", "r2d2", "panda"})
	{
		const SceneSpec scene = makeScene(name);
		ASSERT_TRUE(scene.unavailable.empty()) << name << ": " << scene.unavailable;
		const Metrics stock = runScene(scene, Kind::Stock, settings);
		ASSERT_TRUE(stock.skipped.empty()) << name << ": " << stock.skipped;
		EXPECT_FALSE(stock.blewUp) << name;  // the robots were chosen so: then the rest must follow
		if (stock.blewUp) continue;
		for (Kind kind : {Kind::Quaternion, Kind::QuaternionStabilized})
		{
			const Metrics m = runScene(scene, kind, settings);
			ASSERT_TRUE(m.skipped.empty()) << name << " " << kindName(kind) << ": " << m.skipped;
			EXPECT_FALSE(m.blewUp) << name << " " << kindName(kind);
			EXPECT_TRUE(std::isfinite(m.maxSeparation)) << name << " " << kindName(kind);
			if (kind == Kind::QuaternionStabilized)
			{
				EXPECT_LE(m.maxSeparation, kHeld) << name;
			}
			std::printf("[ measured ] %-16s stock %.3g m, %s %.3g m\n", name, stock.maxSeparation,
						kindName(kind).c_str(), m.maxSeparation);
		}
	}
}
#endif
