// The viewer's panes (Viewer.h): one world per kind built from the scene, the camera aimed at it, the steps and their
// measures, and each frame's layout (the panes side by side, separators, labels and panel over them).
#include "Viewer.h"

#include "SceneSpec.h"

#include "quathinge/btQuaternionHingeConstraint.h"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>
#include <exception>

using namespace quathinge::scenes;

namespace quathinge
{
namespace viewer
{
namespace
{
void measure(Pane& p)
{
	double sep = 0, mis = 0;
	for (const MeasuredJoint& j : p.sim->joints)
	{
		const JointError error = measureJointError(j);
		sep = std::max(sep, error.separation);
		mis = std::max(mis, error.misalignmentDeg);
	}
	p.maxSeparation = std::max(p.maxSeparation, sep);
	p.maxMisalignmentDeg = std::max(p.maxMisalignmentDeg, mis);
	p.series.push(p.series.separation, float(sep * 1e3));
	p.series.push(p.series.misalignment, float(mis));
	p.series.push(p.series.energy, float(p.sim->energy()));
}

// The dynamic bodies joined to `start` through joints between dynamic bodies, and the distinct world points where
// they are jointed to static bodies (`anchors`).
std::vector<const btRigidBody*> connectedBodies(const Simulation& sim, const btRigidBody* start, std::vector<btVector3>& anchors)
{
	std::vector<const btRigidBody*> found = {start};
	for (size_t next = 0; next < found.size(); ++next)
		for (const MeasuredJoint& j : sim.joints)
		{
			const btRigidBody* other = j.a == found[next] ? j.b : j.b == found[next] ? j.a
																					 : nullptr;
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
}  // namespace

Viewer::Viewer(const Options& o) : m_opt(o)
{
	for (const std::string& name : sceneNames()) m_sceneNames.push_back(name);
	for (Kind k : allKinds()) m_allKinds.push_back(k);
	for (const std::string& k : o.kinds) m_kinds.push_back(parseKind(k));
	m_scene = o.scene;
	m_dt = float(o.dt);
	m_iterations = o.iterations;
	reset();
}

void Viewer::reset()
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
	applyStabilizerOptions();
	frameCamera();
}

// The box around every pane's dynamic bodies (false if there are none).
bool Viewer::bodyBox(btVector3& lo, btVector3& hi) const
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
void Viewer::frameCamera()
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

void Viewer::step()
{
	for (Pane& p : m_panes)
		if (p.sim && p.sim->finiteAndBounded())
		{
			p.sim->step(m_dt, m_iterations);
			measure(p);
		}
	++m_steps;
}

void Viewer::render(int width, int height, bool ui)
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

void Viewer::frame()
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

}  // namespace viewer
}  // namespace quathinge
