// Drawing a world with legacy OpenGL: the joints' debug lines, the bodies' shapes, and reading the frame back.
#ifndef QUATHINGE_VIEWER_DRAWING_H
#define QUATHINGE_VIEWER_DRAWING_H

#include <GLFW/glfw3.h>
#include <btBulletDynamicsCommon.h>

#include <cstdio>
#include <vector>

namespace quathinge
{
namespace viewer
{
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

/// The world's bodies, lit; the picked one (may be null) highlighted.
void drawWorld(btDiscreteDynamicsWorld& world, const btRigidBody* picked);

// The default framebuffer as RGB rows, top row first.
std::vector<unsigned char> readPixels(int width, int height);

}  // namespace viewer
}  // namespace quathinge

#endif
