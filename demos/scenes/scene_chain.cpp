// 3-D chains of 10, 30 and 100 links released horizontally; hinge axes alternate between z and a tilted axis, so the
// motion leaves the plane.
#include "SceneSpec.h"

namespace quathinge
{
namespace scenes
{
SceneSpec chainScene(int links, unsigned seed)
{
	SceneSpec s;
	s.name = "chain" + std::to_string(links);
	s.description = std::to_string(links) + "-link 3-D chain (0.5 m links, alternating axes) released horizontally";
	(void)seed;  // the chain is fully determined; the seed is accepted for a uniform interface
	appendChain(s, links, btScalar(0.5), 1, btVector3(0, 0, 0),
				[](int i) { return i % 2 == 0 ? btVector3(0, 0, 1) : btVector3(0, 1, 1); });
	s.conservative = true;
	s.duration = 5;
	return s;
}

}  // namespace scenes
}  // namespace quathinge
