// quathinge-viewer (issue 7): any scene of the scene library simulated with two or more joint kinds side by side —
// one viewport per kind, the same camera — with live plots of joint separation, axis misalignment and energy,
// controls for scene, kinds, step, iterations, pause, single step and reset, mouse picking (a btPoint2PointConstraint
// dragged with the left button, as Bullet's example browser does) and the joints' own debug drawing.
//
//   quathinge-viewer [--scene heavy1000] [--kinds stock,quaternion+stab] [--dt 0.0166667] [--iterations 10]
//   quathinge-viewer --screenshot out.png --frames 120      renders headless (xvfb-run) after 120 steps and exits
//   quathinge-viewer --strip out.png --strip-frames 30,60,90,120 --no-ui   one frame per listed step, stacked
//
// GLFW, legacy OpenGL (2.1: what Mesa's software renderer gives under Xvfb) and Dear ImGui's GLFW/OpenGL2 backends,
// all from Debian's packages; the PNG through stb_image_write (libstb-dev).
#include "JointKinds.h"
#include "SceneSpec.h"
#include "Simulation.h"

#include "quathinge/btQuaternionHingeConstraint.h"

#include <CLI/CLI.hpp>
#include <GLFW/glfw3.h>
#include <btBulletDynamicsCommon.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl2.h>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

using namespace quathinge::scenes;

namespace
{
const int kPlotSamples = 600;  // 10 s at 60 Hz

// ---- Debug drawing with GL lines ---------------------------------------------------------------------------------

class GlDebugDraw : public btIDebugDraw
{
public:
	void drawLine(const btVector3& from, const btVector3& to, const btVector3& color) override
	{
		glColor3f(float(color.x()), float(color.y()), float(color.z()));
		glBegin(GL_LINES);
		glVertex3f(float(from.x()), float(from.y()), float(from.z()));
		glVertex3f(float(to.x()), float(to.y()), float(to.z()));
		glEnd();
	}
	void drawContactPoint(const btVector3&, const btVector3&, btScalar, int, const btVector3&) override {}
	void reportErrorWarning(const char* warning) override { std::fprintf(stderr, "bullet: %s\n", warning); }
	void draw3dText(const btVector3&, const char*) override {}
	void setDebugMode(int mode) override { m_mode = mode; }
	int getDebugMode() const override { return m_mode; }

private:
	int m_mode = DBG_DrawConstraints | DBG_DrawConstraintLimits;
};

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

void measure(Pane& p)
{
	double sep = 0, mis = 0;
	for (const MeasuredJoint& j : p.sim->joints)
	{
		const btTransform fa = j.a->getCenterOfMassTransform() * j.frameA;
		const btTransform fb = j.b->getCenterOfMassTransform() * j.frameB;
		sep = std::max(sep, double((fb.getOrigin() - fa.getOrigin()).length()));
		const btVector3 za = fa.getBasis().getColumn(2), zb = fb.getBasis().getColumn(2);
		mis = std::max(mis, std::atan2(double(za.cross(zb).length()), double(za.dot(zb))) * 180.0 / M_PI);
	}
	p.maxSeparation = std::max(p.maxSeparation, sep);
	p.maxMisalignmentDeg = std::max(p.maxMisalignmentDeg, mis);
	p.series.push(p.series.separation, float(sep * 1e3));
	p.series.push(p.series.misalignment, float(mis));
	p.series.push(p.series.energy, float(p.sim->energy()));
}

// ---- Camera --------------------------------------------------------------------------------------------------------

struct Camera
{
	btVector3 target = btVector3(0, 0, 0);
	float yaw = 0.3f, pitch = 0.25f, distance = 8;
	btVector3 eye() const
	{
		return target + distance * btVector3(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
	}
	/// The view basis: f forward (eye to target), s to the right, u up (what lookAt, pixelRay and projectToPixel use).
	void basis(btVector3& f, btVector3& s, btVector3& u) const
	{
		f = (target - eye()).normalized();
		s = f.cross(btVector3(0, 1, 0));
		if (s.length2() < 1e-8f) s = btVector3(1, 0, 0);
		s.normalize();
		u = s.cross(f);
	}
};

void lookAt(const Camera& cam, float* m)
{
	const btVector3 eye = cam.eye();
	btVector3 f, s, u;
	cam.basis(f, s, u);
	const float r[16] = {float(s.x()), float(u.x()), float(-f.x()), 0, float(s.y()), float(u.y()), float(-f.y()), 0,
						 float(s.z()), float(u.z()), float(-f.z()), 0, float(-s.dot(eye)), float(-u.dot(eye)), float(f.dot(eye)), 1};
	std::copy(r, r + 16, m);
}

const float kFovY = 45.0f * float(M_PI) / 180.0f, kNear = 0.05f, kFar = 500.0f;
// Narrower panes than this (four or five kinds beside the panel) keep this aspect's horizontal field of view and see
// more vertically instead, so a scene framed for two panes is not cropped at the sides.
const float kMinAspect = 0.4f;

// The frustum's half extents at distance `scale` for a viewport of this aspect (w / h): one definition for drawing,
// picking rays and projection back to pixels.
void frustumHalfExtents(float aspect, float scale, float& top, float& right)
{
	if (aspect >= kMinAspect)
	{
		top = scale * std::tan(kFovY / 2);
		right = top * aspect;
	}
	else
	{
		right = scale * std::tan(kFovY / 2) * kMinAspect;
		top = right / aspect;
	}
}

void applyCamera(const Camera& cam, float aspect)
{
	glMatrixMode(GL_PROJECTION);
	glLoadIdentity();
	float top, right;
	frustumHalfExtents(aspect, kNear, top, right);
	glFrustum(-right, right, -top, top, kNear, kFar);
	glMatrixMode(GL_MODELVIEW);
	float m[16];
	lookAt(cam, m);
	glLoadMatrixf(m);
}

// The world ray through a pixel (x, y from the top left) of a viewport of size w × h.
void pixelRay(const Camera& cam, double x, double y, int w, int h, btVector3& from, btVector3& to)
{
	const btVector3 eye = cam.eye();
	btVector3 f, s, u;
	cam.basis(f, s, u);
	float top, right;
	frustumHalfExtents(float(w) / float(h), 1, top, right);
	const float nx = float(2 * x / w - 1), ny = float(1 - 2 * y / h);
	from = eye;
	to = eye + (f + s * (nx * right) + u * (ny * top)) * btScalar(kFar);
}

// The pixel (from the top left) where a world point appears in a viewport of size w × h (the inverse of pixelRay).
bool projectToPixel(const Camera& cam, const btVector3& point, int w, int h, double& x, double& y)
{
	const btVector3 eye = cam.eye();
	btVector3 f, s, u;
	cam.basis(f, s, u);
	const btVector3 d = point - eye;
	const double depth = d.dot(f);
	if (depth <= kNear) return false;
	float top, right;
	frustumHalfExtents(float(w) / float(h), 1, top, right);
	const double nx = d.dot(s) / depth / right, ny = d.dot(u) / depth / top;
	x = (nx + 1) * w / 2;
	y = (1 - ny) * h / 2;
	return true;
}

// ---- Drawing bodies ------------------------------------------------------------------------------------------------

// Multiplies GL's current matrix by a transform (btScalar may be double: GL 2.1's fixed pipeline here takes floats).
void multMatrix(const btTransform& t)
{
	btScalar m[16];
	t.getOpenGLMatrix(m);
	float f[16];
	for (int i = 0; i < 16; ++i) f[i] = float(m[i]);
	glMultMatrixf(f);
}

void drawBox(const btVector3& h)
{
	static const int faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
	static const float normals[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
	btVector3 v[8];
	for (int i = 0; i < 8; ++i) v[i] = btVector3(i & 4 ? h.x() : -h.x(), i & 2 ? h.y() : -h.y(), i & 1 ? h.z() : -h.z());
	glBegin(GL_QUADS);
	for (int f = 0; f < 6; ++f)
	{
		glNormal3fv(normals[f]);
		for (int k = 0; k < 4; ++k) glVertex3f(float(v[faces[f][k]].x()), float(v[faces[f][k]].y()), float(v[faces[f][k]].z()));
	}
	glEnd();
}

void drawSphere(float radius, float offsetAlongUp = 0, int upAxis = 1)
{
	const int slices = 16, stacks = 10;
	for (int i = 0; i < stacks; ++i)
	{
		const float a0 = float(M_PI) * (float(i) / stacks - 0.5f), a1 = float(M_PI) * (float(i + 1) / stacks - 0.5f);
		const float shift = (i < stacks / 2 ? -offsetAlongUp : offsetAlongUp);
		glBegin(GL_QUAD_STRIP);
		for (int j = 0; j <= slices; ++j)
		{
			const float b = 2 * float(M_PI) * float(j) / slices;
			for (float a : {a0, a1})
			{
				float n[3] = {std::cos(a) * std::cos(b), std::sin(a), std::cos(a) * std::sin(b)};
				float p[3] = {radius * n[0], radius * n[1] + shift, radius * n[2]};
				if (upAxis != 1)
				{
					std::swap(n[1], n[upAxis]);
					std::swap(p[1], p[upAxis]);
				}
				glNormal3fv(n);
				glVertex3fv(p);
			}
		}
		glEnd();
	}
}

void drawShape(const btCollisionShape* shape)
{
	switch (shape->getShapeType())
	{
		case BOX_SHAPE_PROXYTYPE:
			drawBox(static_cast<const btBoxShape*>(shape)->getHalfExtentsWithMargin());
			break;
		case SPHERE_SHAPE_PROXYTYPE:
			drawSphere(float(static_cast<const btSphereShape*>(shape)->getRadius()));
			break;
		case CAPSULE_SHAPE_PROXYTYPE:
		{
			const auto* c = static_cast<const btCapsuleShape*>(shape);
			// two half spheres pushed apart, and the cylinder between them
			const float r = float(c->getRadius()), h = float(c->getHalfHeight());
			const int up = c->getUpAxis();
			drawSphere(r, h, up);
			glBegin(GL_QUAD_STRIP);
			for (int j = 0; j <= 16; ++j)
			{
				const float b = 2 * float(M_PI) * float(j) / 16;
				float n[3] = {std::cos(b), 0, std::sin(b)}, p0[3] = {r * n[0], -h, r * n[2]}, p1[3] = {r * n[0], h, r * n[2]};
				if (up != 1)
				{
					std::swap(n[1], n[up]);
					std::swap(p0[1], p0[up]);
					std::swap(p1[1], p1[up]);
				}
				glNormal3fv(n);
				glVertex3fv(p0);
				glVertex3fv(p1);
			}
			glEnd();
			break;
		}
		case STATIC_PLANE_PROXYTYPE:
		{
			glBegin(GL_QUADS);
			glNormal3f(0, 1, 0);
			const float s = 20;
			glVertex3f(-s, 0, -s);
			glVertex3f(-s, 0, s);
			glVertex3f(s, 0, s);
			glVertex3f(s, 0, -s);
			glEnd();
			break;
		}
		case COMPOUND_SHAPE_PROXYTYPE:
		{
			const auto* c = static_cast<const btCompoundShape*>(shape);
			for (int i = 0; i < c->getNumChildShapes(); ++i)
			{
				glPushMatrix();
				multMatrix(c->getChildTransform(i));
				drawShape(c->getChildShape(i));
				glPopMatrix();
			}
			break;
		}
		default:
		{
			btVector3 lo, hi;
			shape->getAabb(btTransform::getIdentity(), lo, hi);
			drawBox((hi - lo) / 2);  // other shapes: their box
		}
	}
}

void drawWorld(btDiscreteDynamicsWorld& world, const btRigidBody* picked)
{
	glEnable(GL_LIGHTING);
	glEnable(GL_LIGHT0);
	glEnable(GL_COLOR_MATERIAL);
	glEnable(GL_NORMALIZE);
	const float light[4] = {0.4f, 1.0f, 0.6f, 0};
	glLightfv(GL_LIGHT0, GL_POSITION, light);
	const btCollisionObjectArray& objects = world.getCollisionObjectArray();
	for (int i = 0; i < objects.size(); ++i)
	{
		const btCollisionObject* o = objects[i];
		const btRigidBody* body = btRigidBody::upcast(o);
		if (o->isStaticObject()) glColor3f(0.45f, 0.45f, 0.5f);
		else if (body && body == picked) glColor3f(1.0f, 0.55f, 0.2f);
		else glColor3f(0.35f, 0.6f, 0.9f);
		glPushMatrix();
		multMatrix(o->getWorldTransform());
		drawShape(o->getCollisionShape());
		glPopMatrix();
	}
	glDisable(GL_LIGHTING);
}

// ---- The viewer ----------------------------------------------------------------------------------------------------

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

// The dynamic bodies joined to `start` through joints between dynamic bodies, and the distinct world points where
// they are jointed to static bodies (`anchors`).
std::vector<const btRigidBody*> connectedBodies(const Simulation& sim, const btRigidBody* start, std::vector<btVector3>& anchors)
{
	std::vector<const btRigidBody*> found = {start};
	for (size_t next = 0; next < found.size(); ++next)
		for (const MeasuredJoint& j : sim.joints)
		{
			const btRigidBody* other = j.a == found[next] ? j.b : j.b == found[next] ? j.a : nullptr;
			if (!other) continue;
			if (other->getInvMass() == 0)
			{
				const btVector3 anchor = other == j.a ? j.a->getCenterOfMassTransform() * j.frameA.getOrigin()
													  : j.b->getCenterOfMassTransform() * j.frameB.getOrigin();
				bool known = false;
				for (const btVector3& a : anchors) known = known || (a - anchor).length() < btScalar(1e-3);
				if (!known) anchors.push_back(anchor);
			}
			else if (std::find(found.begin(), found.end(), other) == found.end())
				found.push_back(other);
		}
	return found;
}

class Viewer
{
public:
	explicit Viewer(const Options& o) : m_opt(o)
	{
		for (const std::string& name : sceneNames()) m_sceneNames.push_back(name);
		for (Kind k : allKinds()) m_allKinds.push_back(k);
		for (const std::string& k : o.kinds) m_kinds.push_back(parseKind(k));
		m_scene = o.scene;
		m_dt = float(o.dt);
		m_iterations = o.iterations;
		reset();
	}

	void reset()
	{
		m_panes.clear();
		m_steps = 0;
		const SceneSpec spec = makeScene(m_scene, 1, m_opt.models);
		m_description = spec.unavailable.empty() ? spec.description : spec.unavailable;
		for (Kind k : m_kinds)
		{
			Pane p;
			p.kind = k;
			if (spec.unavailable.empty())
			{
				try
				{
					p.sim.reset(new Simulation(spec, k));
					p.sim->world().setDebugDrawer(&m_debugDraw);
				}
				catch (const std::exception& e)
				{
					p.error = e.what();
				}
			}
			else
				p.error = spec.unavailable;
			m_panes.push_back(std::move(p));
		}
		frameCamera();
	}

	// The box around every pane's dynamic bodies (false if there are none).
	bool bodyBox(btVector3& lo, btVector3& hi) const
	{
		lo = btVector3(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT);
		hi = -lo;
		bool any = false;
		for (const Pane& p : m_panes)
			if (p.sim && p.sim->finiteAndBounded())
				for (const btRigidBody* b : p.sim->bodies)
				{
					lo.setMin(b->getCenterOfMassPosition());
					hi.setMax(b->getCenterOfMassPosition());
					any = true;
				}
		return any;
	}

	// Aims the camera at the scene's dynamic bodies, far enough to see them swing through their extent.
	void frameCamera()
	{
		btVector3 lo, hi;
		if (!bodyBox(lo, hi)) return;
		// A scene hung from the world swings around its anchor (the first joint on a static body): aim below the
		// anchor, far enough for the whole swing either side. A mechanism anchored at two or more points (a loop
		// closed on the world: the four-bar) or a scene without anchors: aim at the box of its bodies and anchors.
		for (const Pane& p : m_panes)
			if (p.sim)
				for (const MeasuredJoint& j : p.sim->joints)
					if (j.a->getInvMass() == 0 && j.b->getInvMass() > 0)
					{
						const btVector3 anchor = j.a->getCenterOfMassTransform() * j.frameA.getOrigin();
						std::vector<btVector3> anchors;
						const std::vector<const btRigidBody*> mechanism = connectedBodies(*p.sim, j.b, anchors);
						if (anchors.size() > 1)
						{
							lo = hi = anchor;
							for (const btVector3& a : anchors)
							{
								lo.setMin(a);
								hi.setMax(a);
							}
							for (const btRigidBody* b : mechanism)
							{
								lo.setMin(b->getCenterOfMassPosition());
								hi.setMax(b->getCenterOfMassPosition());
							}
							m_camera.target = (lo + hi) / 2;
							m_camera.distance = std::max(2.5f, float((hi - lo).length()) * 2.5f + 1.0f);
							return;
						}
						btScalar reach = 0;
						for (const btRigidBody* b : p.sim->bodies)
							reach = btMax(reach, (b->getCenterOfMassPosition() - anchor).length());
						m_camera.target = anchor - btVector3(0, reach / 2, 0);
						m_camera.distance = std::max(3.0f, float(reach) * 3.6f + 1.0f);
						return;
					}
		const float extent = float((hi - lo).length());
		m_camera.target = (lo + hi) / 2;
		m_camera.distance = std::max(2.5f, extent * 1.3f + 1.0f);
	}



	void step()
	{
		for (Pane& p : m_panes)
			if (p.sim && p.sim->finiteAndBounded())
			{
				p.sim->step(m_dt, m_iterations);
				measure(p);
			}
		++m_steps;
	}

	void render(int width, int height, bool ui)
	{
		glViewport(0, 0, width, height);
		glClearColor(0.12f, 0.12f, 0.14f, 1);
		glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
		glEnable(GL_DEPTH_TEST);
		const int n = std::max(1, int(m_panes.size()));
		m_left = ui ? kPanelWidth : 0;
		const int paneWidth = (width - m_left) / n;
		for (int i = 0; i < int(m_panes.size()); ++i)
		{
			Pane& p = m_panes[size_t(i)];
			glViewport(m_left + i * paneWidth, 0, paneWidth, height);
			applyCamera(m_camera, float(paneWidth) / float(height));
			if (!p.sim) continue;
			drawWorld(p.sim->world(), p.picked);
			glDisable(GL_DEPTH_TEST);
			p.sim->world().debugDrawWorld();  // the joints draw themselves (frames, axis, limit arc)
			for (int c = 0; c < p.sim->world().getNumConstraints(); ++c)
			{
				btTypedConstraint* tc = p.sim->world().getConstraint(c);
				if (const btQuaternionHingeConstraint* hinge = btQuaternionHingeConstraint::upcast(tc))
					hinge->debugDraw(&m_debugDraw, btScalar(0.3));
			}
			glEnable(GL_DEPTH_TEST);
		}
		glViewport(0, 0, width, height);
		// pane separators
		glDisable(GL_DEPTH_TEST);
		glMatrixMode(GL_PROJECTION);
		glLoadIdentity();
		glOrtho(0, width, 0, height, -1, 1);
		glMatrixMode(GL_MODELVIEW);
		glLoadIdentity();
		glColor3f(0.6f, 0.6f, 0.6f);
		glBegin(GL_LINES);
		for (int i = ui ? 0 : 1; i < n; ++i)
		{
			glVertex2f(float(m_left + i * paneWidth), 0);
			glVertex2f(float(m_left + i * paneWidth), float(height));
		}
		glEnd();
		labels(width, height, paneWidth);
		if (ui) panel();
	}

	// The kind's name and its figures over each pane (ImGui's foreground draw list: no window).
	void labels(int width, int height, int paneWidth)
	{
		(void)width;
		(void)height;
		ImDrawList* draw = ImGui::GetForegroundDrawList();
		for (int i = 0; i < int(m_panes.size()); ++i)
		{
			const Pane& p = m_panes[size_t(i)];
			std::ostringstream text;
			text << kindName(p.kind);
			if (!p.error.empty()) text << ": " << p.error;
			else if (p.sim && !p.sim->finiteAndBounded()) text << ": blew up";
			else
			{
				char line[160];
				std::snprintf(line, sizeof line, "\nmax separation %.3g mm\nmax misalignment %.3g deg", p.maxSeparation * 1e3,
							  p.maxMisalignmentDeg);
				text << line;
			}
			draw->AddText(ImGui::GetFont(), 17.0f, ImVec2(float(m_left + i * paneWidth + 12), 10),
						  IM_COL32(255, 255, 255, 255), text.str().c_str(), nullptr, float(paneWidth - 24));
		}
		char info[256];
		std::snprintf(info, sizeof info, "%s   t = %.2f s   dt = %.4f s, %d iterations", m_scene.c_str(), m_steps * double(m_dt),
					  double(m_dt), m_iterations);
		draw->AddText(ImGui::GetFont(), 15.0f, ImVec2(float(m_left + 12), float(height - 24)), IM_COL32(220, 220, 220, 255),
					  info);
	}

	void panel()
	{
		ImGui::SetNextWindowPos(ImVec2(0, 0), ImGuiCond_Always);
		ImGui::SetNextWindowSize(ImVec2(float(kPanelWidth), ImGui::GetIO().DisplaySize.y), ImGuiCond_Always);
		ImGui::Begin("QuatHinge viewer", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
		ImGui::TextWrapped("%s", m_description.c_str());
		if (ImGui::BeginCombo("scene", m_scene.c_str()))
		{
			for (const std::string& name : m_sceneNames)
				if (ImGui::Selectable(name.c_str(), name == m_scene))
				{
					m_scene = name;
					m_resetRequested = true;
				}
			ImGui::EndCombo();
		}
		for (Kind k : m_allKinds)
		{
			bool on = std::find(m_kinds.begin(), m_kinds.end(), k) != m_kinds.end();
			if (ImGui::Checkbox(kindName(k).c_str(), &on))
			{
				if (on) m_kinds.push_back(k);
				else m_kinds.erase(std::remove(m_kinds.begin(), m_kinds.end(), k), m_kinds.end());
				m_resetRequested = true;
			}
		}
		ImGui::SliderFloat("dt (s)", &m_dt, 1.0f / 480, 1.0f / 30, "%.4f");
		ImGui::SliderInt("iterations", &m_iterations, 1, 100);
		ImGui::Checkbox("pause", &m_paused);
		ImGui::SameLine();
		if (ImGui::Button("step")) m_singleStep = true;
		ImGui::SameLine();
		if (ImGui::Button("reset")) m_resetRequested = true;
		ImGui::Separator();
		for (const Pane& p : m_panes)
		{
			if (p.series.separation.empty()) continue;
			ImGui::Text("%s", kindName(p.kind).c_str());
			plot("separation (mm)", p.series.separation);
			plot("misalignment (deg)", p.series.misalignment);
			plot("energy (J)", p.series.energy);
		}
		ImGui::TextWrapped("left drag: pick and drag a body; right drag: orbit; wheel: zoom");
		ImGui::End();
	}

	static void plot(const char* label, const std::deque<float>& d)
	{
		const std::vector<float> v(d.begin(), d.end());
		char overlay[64];
		std::snprintf(overlay, sizeof overlay, "%.3g", double(v.back()));
		ImGui::PlotLines(label, v.data(), int(v.size()), 0, overlay, FLT_MAX, FLT_MAX, ImVec2(0, 40));
	}

	// ---- input ----
	void mouseButton(GLFWwindow* window, int button, int action)
	{
		if (ImGui::GetIO().WantCaptureMouse) return;
		double x, y;
		glfwGetCursorPos(window, &x, &y);
		if (button == GLFW_MOUSE_BUTTON_RIGHT) m_orbiting = action == GLFW_PRESS;
		if (button != GLFW_MOUSE_BUTTON_LEFT) return;
		if (action == GLFW_PRESS) pickAt(window, x, y);
		else release();
		m_lastX = x;
		m_lastY = y;
	}

	void cursor(GLFWwindow* window, double x, double y)
	{
		int w, h;
		glfwGetWindowSize(window, &w, &h);
		cursorAt(w, h, x, y);
	}

	void cursorAt(int w, int h, double x, double y)
	{
		if (m_orbiting)
		{
			m_camera.yaw -= float(x - m_lastX) * 0.01f;
			m_camera.pitch = std::max(-1.5f, std::min(1.5f, m_camera.pitch + float(y - m_lastY) * 0.01f));
		}
		for (Pane& p : m_panes)
			if (p.pick)
			{
				const int paneWidth = (w - m_left) / std::max(1, int(m_panes.size()));
				btVector3 from, to;
				pixelRay(m_camera, x - m_left - m_pickPane * paneWidth, y, paneWidth, h, from, to);
				p.pick->setPivotB(from + (to - from).normalized() * p.pickDistance);
			}
		m_lastX = x;
		m_lastY = y;
	}

	void scroll(double dy) { m_camera.distance = std::max(0.5f, m_camera.distance * float(std::pow(0.9, dy))); }

	void pickAt(GLFWwindow* window, double x, double y)
	{
		int w, h;
		glfwGetWindowSize(window, &w, &h);
		pickAtPixel(w, h, x, y);
	}

	// The scripted drag (--drag-body): where scene body `body` of pane `pane` is on the screen, or false.
	bool bodyPixel(int w, int h, int pane, int body, double& x, double& y) const
	{
		if (pane < 0 || pane >= int(m_panes.size()) || !m_panes[size_t(pane)].sim) return false;
		const Simulation& sim = *m_panes[size_t(pane)].sim;
		if (body < 0 || body >= int(sim.bodies.size())) return false;
		const int paneWidth = (w - m_left) / std::max(1, int(m_panes.size()));
		if (!projectToPixel(m_camera, sim.bodies[size_t(body)]->getCenterOfMassPosition(), paneWidth, h, x, y)) return false;
		x += m_left + pane * paneWidth;
		return true;
	}

	const btRigidBody* picked() const
	{
		for (const Pane& p : m_panes)
			if (p.picked) return p.picked;
		return nullptr;
	}

	void pickAtPixel(int w, int h, double x, double y)
	{
		const int paneWidth = (w - m_left) / std::max(1, int(m_panes.size()));
		if (x < m_left || m_panes.empty()) return;
		const int index = std::min(int(m_panes.size()) - 1, int(x - m_left) / std::max(1, paneWidth));
		Pane& p = m_panes[size_t(index)];
		if (!p.sim) return;
		btVector3 from, to;
		pixelRay(m_camera, x - m_left - index * paneWidth, y, paneWidth, h, from, to);
		// every object, whatever its collision filter (the scenes turn contacts off between jointed links, which
		// would hide them from a broadphase ray query too)
		btCollisionWorld::ClosestRayResultCallback hit(from, to);
		const btTransform rayFrom(btQuaternion::getIdentity(), from), rayTo(btQuaternion::getIdentity(), to);
		const btCollisionObjectArray& objects = p.sim->world().getCollisionObjectArray();
		for (int i = 0; i < objects.size(); ++i)
			btCollisionWorld::rayTestSingle(rayFrom, rayTo, objects[i], objects[i]->getCollisionShape(),
											objects[i]->getWorldTransform(), hit);
		btRigidBody* body = hit.hasHit() ? const_cast<btRigidBody*>(btRigidBody::upcast(hit.m_collisionObject)) : nullptr;
		if (!body || body->isStaticOrKinematicObject()) return;
		p.picked = body;
		p.savedActivation = body->getActivationState();
		body->setActivationState(DISABLE_DEACTIVATION);
		const btVector3 local = body->getCenterOfMassTransform().inverse() * hit.m_hitPointWorld;
		p.pick.reset(new btPoint2PointConstraint(*body, local));
		p.pick->m_setting.m_impulseClamp = 30;
		p.pick->m_setting.m_tau = btScalar(0.001);
		p.sim->world().addConstraint(p.pick.get(), true);
		p.pickDistance = (hit.m_hitPointWorld - from).length();
		m_pickPane = index;
	}

	void release()
	{
		for (Pane& p : m_panes)
			if (p.pick)
			{
				p.sim->world().removeConstraint(p.pick.get());
				p.pick.reset();
				p.picked->forceActivationState(p.savedActivation);
				p.picked->activate();
				p.picked = nullptr;
			}
	}

	void frame()
	{
		if (m_resetRequested)
		{
			release();
			reset();
			m_resetRequested = false;
		}
		if (!m_paused || m_singleStep) step();
		m_singleStep = false;
	}

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
	static const int kPanelWidth = 330;
};

// The default framebuffer as RGB rows, top row first.
std::vector<unsigned char> readPixels(int width, int height)
{
	std::vector<unsigned char> rgb(size_t(width) * size_t(height) * 3), flipped(rgb.size());
	glPixelStorei(GL_PACK_ALIGNMENT, 1);
	glReadBuffer(GL_BACK);
	glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, rgb.data());
	const size_t row = size_t(width) * 3;
	for (int y = 0; y < height; ++y)
		std::copy(rgb.begin() + long(size_t(height - 1 - y) * row), rgb.begin() + long(size_t(height - y) * row),
				  flipped.begin() + long(size_t(y) * row));
	return flipped;
}

Viewer* g_viewer = nullptr;

}  // namespace

int main(int argc, char** argv)
{
	Options o;
	CLI::App app{"quathinge-viewer: joint kinds side by side on the scene library"};
	app.add_option("--scene", o.scene, "scene name (quathinge-compare --list shows them)");
	app.add_option("--kinds", o.kinds, "kinds, side by side: stock 6dof2 quaternion quaternion+stab multibody")->delimiter(',');
	app.add_option("--dt", o.dt, "time step (s)");
	app.add_option("--iterations", o.iterations, "solver iterations");
	app.add_option("--models", o.models, "directory of the models (default: as quathinge-compare --help says)");
	app.add_option("--screenshot", o.screenshot, "render headless: write this PNG after --frames steps and exit");
	app.add_option("--frames", o.frames, "steps before the screenshot");
	app.add_option("--strip", o.strip, "write a frame strip (frames at --strip-frames, stacked) to this PNG and exit");
	app.add_option("--strip-frames", o.stripFrames, "steps at which the strip's frames are taken")->delimiter(',');
	app.add_flag("--no-ui", o.noUi, "no control panel (labels stay)");
	app.add_option("--drag-body", o.drag, "scripted mouse drag (headless test of picking): pane,body,dx,dy — from step 10 "
										  "the body is picked where it appears on screen and dragged dx, dy pixels over "
										  "30 steps")->delimiter(',')->expected(4);
	app.add_option("--size", o.width, "window width (the height is 9/16 of it)");
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
