// The viewer's mouse (Viewer.h): the right button orbits, the wheel zooms, the left button picks a body under the
// cursor and drags it with a btPoint2PointConstraint (as Bullet's example browser does); --drag-body's script too.
#include "Viewer.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>

namespace quathinge
{
namespace viewer
{
void Viewer::mouseButton(GLFWwindow* window, int button, int action)
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

void Viewer::cursor(GLFWwindow* window, double x, double y)
{
	int w, h;
	glfwGetWindowSize(window, &w, &h);
	cursorAt(w, h, x, y);
}

void Viewer::cursorAt(int w, int h, double x, double y)
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

void Viewer::scroll(double dy) { m_camera.distance = std::max(0.5f, m_camera.distance * float(std::pow(0.9, dy))); }

void Viewer::pickAt(GLFWwindow* window, double x, double y)
{
	int w, h;
	glfwGetWindowSize(window, &w, &h);
	pickAtPixel(w, h, x, y);
}

// The scripted drag (--drag-body): where scene body `body` of pane `pane` is on the screen, or false.
bool Viewer::bodyPixel(int w, int h, int pane, int body, double& x, double& y) const
{
	if (pane < 0 || pane >= int(m_panes.size()) || !m_panes[size_t(pane)].sim) return false;
	const Simulation& sim = *m_panes[size_t(pane)].sim;
	if (body < 0 || body >= int(sim.bodies.size())) return false;
	const int paneWidth = (w - m_left) / std::max(1, int(m_panes.size()));
	if (!projectToPixel(m_camera, sim.bodies[size_t(body)]->getCenterOfMassPosition(), paneWidth, h, x, y)) return false;
	x += m_left + pane * paneWidth;
	return true;
}

const btRigidBody* Viewer::picked() const
{
	for (const Pane& p : m_panes)
		if (p.picked) return p.picked;
	return nullptr;
}

void Viewer::pickAtPixel(int w, int h, double x, double y)
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

void Viewer::release()
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

}  // namespace viewer
}  // namespace quathinge
