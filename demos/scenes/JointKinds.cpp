// The joint kinds' names (JointKinds.h): the kinds every table runs, a kind's name and a name's kind. The world for
// one kind is Simulation.cpp; running and measuring a scene is RunScene.cpp.
#include "JointKinds.h"

#include <stdexcept>

namespace quathinge
{
namespace scenes
{
std::vector<Kind> allKinds()
{
	return {Kind::Stock,	 Kind::Generic6Dof2,	Kind::Quaternion,			 Kind::QuaternionStabilized,
			Kind::MultiBody, Kind::StockStabilized, Kind::Generic6Dof2Stabilized};
}

std::string kindName(Kind kind)
{
	switch (kind)
	{
		case Kind::Stock: return "stock";
		case Kind::Generic6Dof2: return "6dof2";
		case Kind::Quaternion: return "quaternion";
		case Kind::QuaternionStabilized: return "quaternion+stab";
		case Kind::MultiBody: return "multibody";
		case Kind::QuaternionStabilizedEnergy: return "quaternion+stab+energy";
		case Kind::StockStabilized: return "stock+stab";
		case Kind::Generic6Dof2Stabilized: return "6dof2+stab";
	}
	return "?";
}

Kind parseKind(const std::string& name)
{
	for (Kind k : allKinds())
		if (kindName(k) == name) return k;
	if (name == kindName(Kind::QuaternionStabilizedEnergy)) return Kind::QuaternionStabilizedEnergy;
	throw std::invalid_argument("parseKind: kind: unknown joint kind '" + name +
								"' (stock, 6dof2, quaternion, quaternion+stab, multibody, stock+stab, 6dof2+stab, "
								"quaternion+stab+energy)");
}

}  // namespace scenes
}  // namespace quathinge
