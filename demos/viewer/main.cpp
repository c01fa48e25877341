// quathinge-viewer: any scene of the scene library simulated with two or more joint kinds side by side —
// one viewport per kind, the same camera — with live plots of joint separation, axis misalignment and energy,
// controls for scene, kinds, step, iterations, pause, single step and reset, mouse picking (a btPoint2PointConstraint
// dragged with the left button, as Bullet's example browser does) and the joints' own debug drawing.
//
//   quathinge-viewer [--scenes heavy1000] [--kinds stock,quaternion+stab] [--dt 0.0166667] [--iterations 10]
//   quathinge-viewer --screenshot out.png --frames 120      renders headless (xvfb-run) after 120 steps and exits
//   quathinge-viewer --strip out.png --strip-frames 30,60,90,120 --no-ui   one frame per listed step, stacked
//
// GLFW, legacy OpenGL (2.1: what Mesa's software renderer gives under Xvfb) and Dear ImGui's GLFW/OpenGL2 backends,
// all from Debian's packages; the PNG through stb_image_write (libstb-dev).
// The app: arguments, the window and ImGui's backends, and the loop (Viewer.h holds the panes, Camera.h, Drawing.h).
#include "Viewer.h"

#include "JointKinds.h"
#include "SceneSpec.h"

#include <CLI/CLI.hpp>
#include <GLFW/glfw3.h>
#include <btBulletDynamicsCommon.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl2.h>
#include <stb/stb_image_write.h>

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

using namespace quathinge::scenes;
using namespace quathinge::viewer;

namespace
{
Viewer* g_viewer = nullptr;

}  // namespace

int main(int argc, char** argv)
{
	Options o;
	CLI::App app{"quathinge-viewer: joint kinds side by side on the scene library"};
	app.add_option("-s,--scenes,--scene", o.scene, "the scene's name (quathinge-compare --list shows them)")
		->capture_default_str();
	app.add_option("-k,--kinds", o.kinds, "joint kinds side by side (below): -k a b or --kinds a,b")
		->delimiter(',')
		->capture_default_str();
	app.add_option("--dt", o.dt, "time step (s)")->capture_default_str();
	app.add_option("--iterations", o.iterations, "solver iterations")->capture_default_str();
	app.add_option("--models", o.models, "directory of the models (default: as quathinge-compare --help says)");
	app.add_option("--screenshot", o.screenshot, "render headless: write this PNG after --frames steps and exit");
	app.add_option("--frames", o.frames, "steps before the screenshot")->capture_default_str();
	app.add_option("--strip", o.strip, "write a frame strip (frames at --strip-frames, stacked) to this PNG and exit");
	app.add_option("--strip-frames", o.stripFrames, "steps at which the strip's frames are taken")->delimiter(',')->capture_default_str();
	app.add_flag("--no-ui", o.noUi, "no control panel (labels stay)");
	app.add_option("--drag-body", o.drag,
				   "scripted mouse drag (headless test of picking): pane,body,dx,dy — from step 10 "
				   "the body is picked where it appears on screen and dragged dx, dy pixels over "
				   "30 steps")
		->delimiter(',')
		->expected(4);
	app.add_option("--size", o.width, "window width in pixels (the height is 9/16 of it)")->capture_default_str();
	app.footer(
		"Mouse: left drag pulls the body under the cursor (a btPoint2PointConstraint, as Bullet's example "
		"browser does); right drag orbits the camera; the wheel zooms. The panel sets scene, kinds, step, "
		"iterations, pause, single step, reset and the stabilizer's options.\n\nJoint kinds (--kinds):" +
		kindsHelp() +
		"\n\nExample: quathinge-viewer --scenes chain30 --kinds stock,quaternion,quaternion+stab\n\nThe manual "
		"(DEMOS.md: the viewer and the other programs) is in " +
		manualDir());
	CLI11_PARSE(app, argc, argv);
	o.height = o.width * 9 / 16;
	const bool headless = !o.screenshot.empty() || !o.strip.empty();
	if (!o.strip.empty()) o.height = o.width * 3 / 8;

	// the scene and kinds checked before any window, so a typo is reported as one even without a display
	try
	{
		for (const std::string& k : o.kinds) parseKind(k);
		makeScene(o.scene, 1, o.models);
	}
	catch (const std::exception& e)
	{
		std::fprintf(stderr, "quathinge-viewer: %s\n", e.what());
		return 1;
	}

	if (!glfwInit())
	{
		std::fprintf(stderr, "quathinge-viewer: no display (for headless rendering run it under xvfb-run)\n");
		return 1;
	}
	glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 2);
	glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 1);
	GLFWwindow* window = glfwCreateWindow(o.width, o.height, "QuatHinge viewer", nullptr, nullptr);
	if (!window)
	{
		std::fprintf(stderr, "quathinge-viewer: could not open an OpenGL 2.1 window\n");
		glfwTerminate();
		return 1;
	}
	glfwMakeContextCurrent(window);
	glfwSwapInterval(headless ? 0 : 1);
	// the viewer's callbacks first: ImGui's backend installs its own and chains to these
	glfwSetMouseButtonCallback(window, [](GLFWwindow* w, int button, int action, int) {
		if (g_viewer) g_viewer->mouseButton(w, button, action);
	});
	glfwSetCursorPosCallback(window, [](GLFWwindow* w, double x, double y) {
		if (g_viewer) g_viewer->cursor(w, x, y);
	});
	glfwSetScrollCallback(window, [](GLFWwindow*, double, double dy) {
		if (g_viewer && !ImGui::GetIO().WantCaptureMouse) g_viewer->scroll(dy);
	});
	IMGUI_CHECKVERSION();
	ImGui::CreateContext();
	ImGui::GetIO().IniFilename = nullptr;
	ImGui::StyleColorsDark();
	ImGui_ImplGlfw_InitForOpenGL(window, true);
	ImGui_ImplOpenGL2_Init();

	int status = 0;
	try
	{
		Viewer viewer(o);
		g_viewer = &viewer;
		std::vector<unsigned char> strip;
		size_t nextStrip = 0;
		btVector3 dragStart(0, 0, 0);
		while (!glfwWindowShouldClose(window))
		{
			glfwPollEvents();
			viewer.frame();
			int width, height;
			glfwGetFramebufferSize(window, &width, &height);
			if (o.drag.size() == 4)
			{
				// the same path as the mouse: a pixel, the ray through it, the pick constraint, then cursor moves
				static double startX = 0, startY = 0;
				const int s = viewer.steps();
				if (s == 10 && viewer.bodyPixel(width, height, int(o.drag[0]), int(o.drag[1]), startX, startY))
				{
					viewer.pickAtPixel(width, height, startX, startY);
					const btRigidBody* body = viewer.picked();
					std::printf("quathinge-viewer: drag from (%.0f, %.0f): %s\n", startX, startY,
								body ? "picked a body" : "nothing under the cursor");
					if (body) dragStart = body->getCenterOfMassPosition();
				}
				else if (s > 10 && s <= 40)
					viewer.cursorAt(width, height, startX + o.drag[2] * (s - 10) / 30, startY + o.drag[3] * (s - 10) / 30);
				if (s == 40 && viewer.picked())
					std::printf("quathinge-viewer: the picked body moved %.3f m while dragged\n",
								double((viewer.picked()->getCenterOfMassPosition() - dragStart).length()));
			}
			ImGui_ImplOpenGL2_NewFrame();
			ImGui_ImplGlfw_NewFrame();
			ImGui::NewFrame();
			viewer.render(width, height, !o.noUi);
			ImGui::Render();
			ImGui_ImplOpenGL2_RenderDrawData(ImGui::GetDrawData());
			if (!o.screenshot.empty() && viewer.steps() >= o.frames)
			{
				const std::vector<unsigned char> rgb = readPixels(width, height);
				if (!stbi_write_png(o.screenshot.c_str(), width, height, 3, rgb.data(), width * 3))
					throw std::runtime_error("could not write " + o.screenshot);
				std::printf("quathinge-viewer: wrote %s (%dx%d, after %d steps)\n", o.screenshot.c_str(), width, height,
							viewer.steps());
				break;
			}
			if (!o.strip.empty() && nextStrip < o.stripFrames.size() && viewer.steps() >= o.stripFrames[nextStrip])
			{
				const std::vector<unsigned char> rgb = readPixels(width, height);
				strip.insert(strip.end(), rgb.begin(), rgb.end());
				if (++nextStrip == o.stripFrames.size())
				{
					const int rows = int(o.stripFrames.size()) * height;
					if (!stbi_write_png(o.strip.c_str(), width, rows, 3, strip.data(), width * 3))
						throw std::runtime_error("could not write " + o.strip);
					std::printf("quathinge-viewer: wrote %s (%zu frames of %dx%d)\n", o.strip.c_str(), o.stripFrames.size(),
								width, height);
					break;
				}
			}
			glfwSwapBuffers(window);
		}
	}
	catch (const std::exception& e)
	{
		std::fprintf(stderr, "quathinge-viewer: %s\n", e.what());
		status = 1;
	}
	g_viewer = nullptr;
	ImGui_ImplOpenGL2_Shutdown();
	ImGui_ImplGlfw_Shutdown();
	ImGui::DestroyContext();
	glfwDestroyWindow(window);
	glfwTerminate();
	return status;
}
