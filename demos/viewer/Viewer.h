// The viewer's state (quathinge-viewer): one pane per joint kind (its world and plots), the camera they share, the
// controls' settings. Set-up and stepping: Viewer.cpp; mouse and picking: Picking.cpp; labels and panel: Ui.cpp.
#ifndef QUATHINGE_VIEWER_VIEWER_H
#define QUATHINGE_VIEWER_VIEWER_H

#include "Camera.h"
#include "Drawing.h"

#include "JointKinds.h"
#include "Simulation.h"

#include <btBulletDynamicsCommon.h>

#include <deque>
#include <memory>
#include <string>
#include <vector>

namespace quathinge
{
namespace viewer
{
using scenes::Kind;
using scenes::Simulation;

const int kPlotSamples = 600;  // 10 s at 60 Hz

// ---- One kind's world and its plots -------------------------------------------------------------------------------

struct Series
{
	std::deque<float> separation, misalignment, energy;  // mm, degrees, J
	void push(std::deque<float>& d, float v)
	{
		d.push_back(v);
		if (int(d.size()) > kPlotSamples) d.pop_front();
	}
};

struct Pane
{
	Kind kind;
	std::unique_ptr<Simulation> sim;
	std::string error;  // why the kind cannot run the scene (multibody: loops)
	Series series;
	double maxSeparation = 0, maxMisalignmentDeg = 0;
	// picking
	btRigidBody* picked = nullptr;
	std::unique_ptr<btPoint2PointConstraint> pick;
	int savedActivation = 0;
	btScalar pickDistance = 0;
};

struct Options
{
	std::string scene = "heavy1000";
	std::vector<std::string> kinds = {"stock", "quaternion+stab"};
	double dt = 1.0 / 60;
	int iterations = 10;
	std::string models;
	std::string screenshot;
	int frames = 120;
	std::string strip;
	std::vector<int> stripFrames = {30, 60, 90, 120};
	bool noUi = false;
	std::vector<double> drag;  // scripted drag: pane, body, dx, dy (px over 30 steps from step 10)
	int width = 1280, height = 720;
};

class Viewer
{
public:
	explicit Viewer(const Options& o);
	void reset();
	bool bodyBox(btVector3& lo, btVector3& hi) const;
	void frameCamera();
	void step();
	void render(int width, int height, bool ui);
	void labels(int width, int height, int paneWidth);
	void panel();
	static void plot(const char* label, const std::deque<float>& d);
	// ---- input ----
	void mouseButton(GLFWwindow* window, int button, int action);
	void cursor(GLFWwindow* window, double x, double y);
	void cursorAt(int w, int h, double x, double y);
	void scroll(double dy);
	void pickAt(GLFWwindow* window, double x, double y);
	bool bodyPixel(int w, int h, int pane, int body, double& x, double& y) const;
	const btRigidBody* picked() const;
	void pickAtPixel(int w, int h, double x, double y);
	void release();
	void frame();

	int steps() const { return m_steps; }

private:
	Options m_opt;
	std::vector<std::string> m_sceneNames;
	std::vector<Kind> m_allKinds, m_kinds;
	std::string m_scene, m_description;
	float m_dt;
	int m_iterations;
	std::vector<Pane> m_panes;
	GlDebugDraw m_debugDraw;
	Camera m_camera;
	int m_steps = 0;
	bool m_paused = false, m_singleStep = false, m_resetRequested = false, m_orbiting = false;
	double m_lastX = 0, m_lastY = 0;
	int m_pickPane = 0;
	int m_left = 0;  // px: the panel's column, left of the panes
	// The stabilizer's optional parts (btQuaternionHingeStabilizerSettings), set on every pane with a stabilizer
	bool m_projectPoints = false, m_projectLocked = false, m_projectContacts = false, m_moveAttached = false,
		 m_closeAttached = false;
	void applyStabilizerOptions();
	static const int kPanelWidth = 330;
};

}  // namespace viewer
}  // namespace quathinge

#endif
