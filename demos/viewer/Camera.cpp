// The viewer's camera (Camera.h): its view and projection in GL, and the one frustum that drawing, picking rays and
// projection back to pixels share.
#include "Camera.h"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>

namespace quathinge
{
namespace viewer
{
namespace
{
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

}  // namespace

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

}  // namespace viewer
}  // namespace quathinge
