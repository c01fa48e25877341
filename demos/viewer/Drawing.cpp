// Drawing (Drawing.h): the bodies' collision shapes as GL primitives (box, sphere, capsule, plane, compound), the
// world's bodies with a light, and the framebuffer read back for screenshots.
#include "Drawing.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace quathinge
{
namespace viewer
{
namespace
{
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

}  // namespace

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

}  // namespace viewer
}  // namespace quathinge
