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
	return {Kind::Stock, Kind::Generic6Dof2, Kind::Quaternion, Kind::QuaternionStabilized,
			Kind::MultiBody, Kind::StockStabilized, Kind::Generic6Dof2Stabilized};
}

std::vector<Kind> peerKinds()
{
	return {Kind::StockMLCP, Kind::StockNNCG, Kind::QuaternionMLCP, Kind::QuaternionNNCG, Kind::MultiBodyDamped};
}

namespace
{
// Every kind with its name and one line of help (quathinge-compare --help): one entry per kind, append new ones.
struct KindEntry
{
	Kind kind;
	const char* name;
	const char* help;
};
const std::vector<KindEntry>& kindCatalog()
{
	static const std::vector<KindEntry> catalog = {
		{Kind::Stock, "stock", "Bullet's btHingeConstraint, sequential impulse"},
		{Kind::Generic6Dof2, "6dof2", "btGeneric6DofSpring2Constraint with five axes locked: Bullet's other hinge"},
		{Kind::Quaternion, "quaternion", "btQuaternionHingeConstraint, the rows alone"},
		{Kind::QuaternionStabilized, "quaternion+stab", "btQuaternionHingeConstraint + btQuaternionHingeStabilizer"},
		{Kind::MultiBody, "multibody", "btMultiBody revolute links, damping 0; loops closed by btMultiBodyPoint2Point"},
		{Kind::StockStabilized, "stock+stab", "btHingeConstraint + btQuaternionHingeStabilizer (no class swapped)"},
		{Kind::Generic6Dof2Stabilized, "6dof2+stab", "the 6dof2 hinges + btQuaternionHingeStabilizer (no class swapped)"},
		{Kind::QuaternionStabilizedEnergy, "quaternion+stab+energy",
		 "quaternion+stab with the deprecated conserveEnergy option (conservative scenes only; not in the defaults)"},
		{Kind::QuaternionStabilizedDamped, "quaternion+stab-damped",
		 "quaternion+stab with keepEnergyAndMomentum off: the projection's own damping (docs/ENERGY.md)"},
		{Kind::StockMLCP, "stock+mlcp", "btHingeConstraint, btMLCPSolver + btDantzigSolver (<= 200 rows)"},
		{Kind::StockNNCG, "stock+nncg", "btHingeConstraint, btNNCGConstraintSolver"},
		{Kind::QuaternionMLCP, "quaternion+mlcp", "btQuaternionHingeConstraint, btMLCPSolver + btDantzigSolver"},
		{Kind::QuaternionNNCG, "quaternion+nncg", "btQuaternionHingeConstraint, btNNCGConstraintSolver"},
		{Kind::MultiBodyDamped, "multibody-damped", "multibody with btMultiBody's default damping 0.04"},
	};
	return catalog;
}
}  // namespace

std::string kindsHelp()
{
	std::string help;
	for (const KindEntry& e : kindCatalog()) help += std::string("\n  ") + e.name + std::string(24 - std::string(e.name).size(), ' ') + e.help;
	return help;
}

SolverChoice solverOf(Kind kind)
{
	switch (kind)
	{
		case Kind::StockMLCP:
		case Kind::QuaternionMLCP: return SolverChoice::MLCPDantzig;
		case Kind::StockNNCG:
		case Kind::QuaternionNNCG: return SolverChoice::NNCG;
		case Kind::MultiBody:
		case Kind::MultiBodyDamped: return SolverChoice::MultiBody;
		default: return SolverChoice::SequentialImpulse;
	}
}

std::string kindName(Kind kind)
{
	for (const KindEntry& e : kindCatalog())
		if (e.kind == kind) return e.name;
	return "?";
}

Kind parseKind(const std::string& name)
{
	std::string names;
	for (const KindEntry& e : kindCatalog())
	{
		if (name == e.name) return e.kind;
		names += std::string(names.empty() ? "" : ", ") + e.name;
	}
	throw std::invalid_argument("parseKind: kind: unknown joint kind '" + name + "' (" + names + ")");
}

}  // namespace scenes
}  // namespace quathinge
