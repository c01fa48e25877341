// The URDF loader's collision shapes: a <collision> as pieces of a compound shape (box, sphere, cylinder, capsule),
// and the STL and OBJ meshes it names, found and read as pybullet reads them for a moving link.
#ifdef QUATHINGE_HAVE_URDFDOM
#include "UrdfLoader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <locale>
#include <sstream>

namespace quathinge
{
namespace scenes
{
namespace urdfimport
{
namespace
{
/// The vertices (m, the mesh's frame, times `scale`) of an STL file, binary or ASCII.
std::vector<btVector3> readStl(const std::string& path, const btVector3& scale)
{
	std::ifstream file(path, std::ios::binary);
	if (!file) throw Refusal("mesh file not found: " + path);
	const std::string data((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
	std::vector<btVector3> points;
	uint32_t triangles = 0;
	if (data.size() >= 84) std::memcpy(&triangles, data.data() + 80, 4);  // STL is little-endian, as this machine
	if (data.size() >= 84 && data.size() == 84 + 50 * size_t(triangles))
	{
		for (size_t t = 0; t < triangles; ++t)
			for (int v = 0; v < 3; ++v)
			{
				float xyz[3];
				std::memcpy(xyz, data.data() + 84 + 50 * t + 12 * (1 + v), sizeof xyz);  // after the normal
				points.emplace_back(btScalar(xyz[0]) * scale.x(), btScalar(xyz[1]) * scale.y(), btScalar(xyz[2]) * scale.z());
			}
	}
	else if (data.compare(0, 5, "solid") == 0)
	{
		std::istringstream in(data);
		in.imbue(std::locale::classic());
		std::string word;
		while (in >> word)
			if (word == "vertex")
			{
				double x = 0, y = 0, z = 0;
				if (!(in >> x >> y >> z)) throw Refusal("malformed ASCII STL vertex in " + path);
				points.emplace_back(btScalar(x) * scale.x(), btScalar(y) * scale.y(), btScalar(z) * scale.z());
			}
	}
	else
	{
		throw Refusal("not an STL file (binary size or ASCII 'solid' header): " + path);
	}
	if (points.size() < 4) throw Refusal("mesh has fewer than 4 vertices: " + path);
	for (const btVector3& p : points)
		if (!std::isfinite(double(p.length2()))) throw Refusal("mesh has a non-finite vertex: " + path);
	return points;
}

/// The convex pieces of a Wavefront OBJ file, as pybullet reads one for a moving link: the vertices of each group
/// of faces ('g' and 'o' start a group) are one convex hull (m, the mesh's frame, times `scale`).
std::vector<std::vector<btVector3>> readObj(const std::string& path, const btVector3& scale)
{
	std::ifstream file(path);
	if (!file) throw Refusal("mesh file not found: " + path);
	std::vector<btVector3> vertices;
	std::vector<std::vector<btVector3>> groups(1);
	std::string line;
	for (int number = 1; std::getline(file, line); ++number)
	{
		std::istringstream in(line);
		in.imbue(std::locale::classic());
		std::string tag;
		in >> tag;
		if (tag == "v")
		{
			double x = 0, y = 0, z = 0;
			if (!(in >> x >> y >> z))
				throw Refusal("malformed OBJ vertex at line " + std::to_string(number) + " of " + path);
			vertices.emplace_back(btScalar(x) * scale.x(), btScalar(y) * scale.y(), btScalar(z) * scale.z());
		}
		else if (tag == "f")
		{
			for (std::string corner; in >> corner;)
			{
				long index = 0;  // "v", "v/vt", "v//vn" or "v/vt/vn"; negative counts back from the last vertex
				std::istringstream first(corner.substr(0, corner.find('/')));
				const long count = long(vertices.size());
				if (!(first >> index) || index == 0 || index > count || index < -count)
					throw Refusal("OBJ face index out of range at line " + std::to_string(number) + " of " + path);
				groups.back().push_back(vertices[size_t(index > 0 ? index - 1 : count + index)]);
			}
		}
		else if ((tag == "g" || tag == "o") && !groups.back().empty())
		{
			groups.emplace_back();
		}
	}
	if (groups.back().empty()) groups.pop_back();
	if (groups.empty()) throw Refusal("mesh has no faces: " + path);
	for (const std::vector<btVector3>& g : groups)
		for (const btVector3& p : g)
			if (!std::isfinite(double(p.length2()))) throw Refusal("mesh has a non-finite vertex: " + path);
	return groups;
}

/// A mesh's file as pybullet finds it: package:// and file:// stripped, relative to the URDF's folder.
std::string meshPath(const std::string& urdfPath, std::string name)
{
	for (const char* prefix : {"package://", "file://"})
		if (name.rfind(prefix, 0) == 0) name.erase(0, std::strlen(prefix));
	const std::filesystem::path p(name);
	if (p.is_absolute()) return name;
	return (std::filesystem::path(urdfPath).parent_path() / p).string();
}

}  // namespace

/// One <collision> as pieces of a compound shape, in the link's frame: one piece, or one per convex part of an OBJ.
std::vector<ShapePart> collisionParts(const urdf::Collision& collision, bool capsule, const std::string& urdfPath)
{
	ShapePart part;
	part.local = toBullet(collision.origin);
	// URDF's cylinders and capsules lie along z, the scene's along y: turn y onto z (+90° about x)
	const btTransform yToZ(btQuaternion(btVector3(1, 0, 0), SIMD_HALF_PI));
	const urdf::Geometry* geometry = collision.geometry.get();
	if (!geometry) throw Refusal("a <collision> without geometry");
	switch (geometry->type)
	{
		case urdf::Geometry::SPHERE:
		{
			const btScalar r = btScalar(static_cast<const urdf::Sphere*>(geometry)->radius);
			part.shape = Shape::Sphere;
			part.halfExtents = btVector3(r, r, r);
			break;
		}
		case urdf::Geometry::BOX:
		{
			const urdf::Vector3& dim = static_cast<const urdf::Box*>(geometry)->dim;
			part.shape = Shape::Box;
			part.halfExtents = btVector3(btScalar(dim.x / 2), btScalar(dim.y / 2), btScalar(dim.z / 2));
			break;
		}
		case urdf::Geometry::CYLINDER:
		{
			const auto* c = static_cast<const urdf::Cylinder*>(geometry);
			const btScalar r = btScalar(c->radius), half = btScalar(c->length / 2);
			part.shape = capsule ? Shape::Capsule : Shape::Cylinder;
			part.halfExtents = btVector3(r, capsule ? half + r : half, r);  // a capsule's half length with its caps
			part.local = part.local * yToZ;
			break;
		}
		case urdf::Geometry::MESH:
		{
			const auto* mesh = static_cast<const urdf::Mesh*>(geometry);
			const std::string file = meshPath(urdfPath, mesh->filename);
			std::string extension = std::filesystem::path(file).extension().string();
			std::transform(extension.begin(), extension.end(), extension.begin(),
						   [](unsigned char ch) { return char(std::tolower(ch)); });
			const btVector3 scale(btScalar(mesh->scale.x), btScalar(mesh->scale.y), btScalar(mesh->scale.z));
			part.shape = Shape::ConvexHull;
			if (extension == ".stl")
			{
				part.points = readStl(file, scale);
				break;
			}
			if (extension != ".obj")
				throw Refusal("mesh '" + mesh->filename + "': only STL and OBJ meshes are read");
			std::vector<ShapePart> parts;
			for (std::vector<btVector3>& points : readObj(file, scale))
			{
				parts.push_back(part);
				parts.back().points = std::move(points);
			}
			return parts;
		}
		default: throw Refusal("unknown collision geometry type " + std::to_string(int(geometry->type)));
	}
	for (int k = 0; k < 3; ++k)
		if (part.shape != Shape::ConvexHull && !(part.halfExtents[k] > 0 && std::isfinite(double(part.halfExtents[k]))))
			throw Refusal("collision geometry with a size that is not positive and finite");
	return {part};
}

}  // namespace urdfimport
}  // namespace scenes
}  // namespace quathinge
#endif
