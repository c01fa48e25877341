// One line of --help per joint kind, for quathinge-compare and quathinge-viewer: what a Bullet user would build for a
// hinge with that kind. A new kind (JointKinds.h) adds its line here; the order is the order --help lists them in.
#ifndef QUATHINGE_KIND_HELP_H
#define QUATHINGE_KIND_HELP_H

#include <string>

namespace quathinge
{
namespace scenes
{
struct KindHelp
{
	const char* name;  ///< as --kinds takes it (kindName)
	const char* help;  ///< one line
};

inline const KindHelp kKindHelp[] = {
	{"stock", "Bullet's btHingeConstraint"},
	{"6dof2", "btGeneric6DofSpring2Constraint with five axes locked: Bullet's other way to build a hinge"},
	{"quaternion", "btQuaternionHingeConstraint, the rows alone"},
	{"quaternion+stab", "btQuaternionHingeConstraint with btQuaternionHingeStabilizer (post-stabilization)"},
	{"quaternion+stab+energy", "the same with the stabilizer's conserveEnergy option (conservative scenes only; not in the default list)"},
	{"multibody", "btMultiBody revolute joints (Featherstone, reduced coordinates): tree scenes only"},
};

/// The table as --help shows it: "  name  help" per line, names padded to one column.
inline std::string kindHelpText()
{
	std::string text;
	for (const KindHelp& k : kKindHelp)
		text += "  " + std::string(k.name) + std::string(24 - std::string(k.name).size(), ' ') + k.help + "\n";
	return text;
}
}  // namespace scenes
}  // namespace quathinge

#endif
