// The viewer's camera: an orbit around a target, applied to GL, and the maths between pixels and the world (the
// ray through a pixel for picking, the pixel where a point appears).
#ifndef QUATHINGE_VIEWER_CAMERA_H
#define QUATHINGE_VIEWER_CAMERA_H

#include <btBulletDynamicsCommon.h>

#include <cmath>

namespace quathinge
{
namespace viewer
{
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

void applyCamera(const Camera& cam, float aspect);

// The world ray through a pixel (x, y from the top left) of a viewport of size w × h.
void pixelRay(const Camera& cam, double x, double y, int w, int h, btVector3& from, btVector3& to);

// The pixel (from the top left) where a world point appears in a viewport of size w × h (the inverse of pixelRay).
bool projectToPixel(const Camera& cam, const btVector3& point, int w, int h, double& x, double& y);

}  // namespace viewer
}  // namespace quathinge

#endif
