// The URDF loader's pre-pass (tinyxml2): the XML read as pybullet reads it where urdfdom would refuse it or read it
// differently (<capsule>, limit defaults, a material defined twice, vectors and inertias), before urdfdom parses it.
#ifdef QUATHINGE_HAVE_URDFDOM
#include "UrdfLoader.h"

#include <tinyxml2.h>

#include <algorithm>
#include <cstring>
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
double attributeOr(const tinyxml2::XMLElement& e, const char* name, double fallback)
{
	const char* text = e.Attribute(name);
	if (!text) return fallback;
	std::istringstream in(text);
	in.imbue(std::locale::classic());
	double value = fallback;
	in >> value;
	return value;
}

/// A vector attribute as pybullet reads it (the first three numbers of three or more; a mesh's single scale
/// number for all three); left as it is when it does not read as numbers (urdfdom then says what is wrong).
void normalizeVector(tinyxml2::XMLElement& e, const char* attribute, bool scalarForAll)
{
	const char* text = e.Attribute(attribute);
	if (!text) return;
	std::istringstream in(text);
	in.imbue(std::locale::classic());
	std::vector<std::string> words;
	for (std::string w; in >> w;) words.push_back(w);
	for (const std::string& w : words)
	{
		std::istringstream number(w);
		number.imbue(std::locale::classic());
		double value = 0;
		if (!(number >> value) || !number.eof()) return;
	}
	if (words.size() == 1 && scalarForAll) words = {words[0], words[0], words[0]};
	if (words.size() <= 3) return;
	e.SetAttribute(attribute, (words[0] + " " + words[1] + " " + words[2]).c_str());
}

void normalizeVectors(tinyxml2::XMLElement& e)
{
	const std::string name = e.Name();
	if (name == "origin")
	{
		normalizeVector(e, "xyz", false);
		normalizeVector(e, "rpy", false);
	}
	else if (name == "axis") normalizeVector(e, "xyz", false);
	else if (name == "box") normalizeVector(e, "size", false);
	else if (name == "mesh") normalizeVector(e, "scale", true);
	else if (name == "inertia" && e.Attribute("ixx") && e.Attribute("iyy") && e.Attribute("izz") &&
			 !(e.Attribute("ixy") && e.Attribute("ixz") && e.Attribute("iyz")))
	{
		for (const char* product : {"ixy", "ixz", "iyz"}) e.SetAttribute(product, 0);  // pybullet: all three 0
	}
	for (tinyxml2::XMLElement* child = e.FirstChildElement(); child; child = child->NextSiblingElement())
		normalizeVectors(*child);
}

}  // namespace

/// Reads the XML as pybullet does where urdfdom differs: <capsule> becomes a <cylinder> (remembered, so the shape
/// stays a capsule), a <limit> gets urdfdom's required effort and velocity (0, pybullet's default; neither is
/// modelled), pybullet's limit defaults are kept, a top-level material defined again is dropped (urdfdom refuses
/// it), vectors and inertias are read as pybullet reads them (normalizeVectors), and a joint type no hinge can be is
/// refused by name.
Preprocessed preprocess(const std::string& text)
{
	tinyxml2::XMLDocument doc;
	if (doc.Parse(text.c_str(), text.size()) != tinyxml2::XML_SUCCESS)
		throw Refusal(std::string("not well-formed XML: ") + doc.ErrorStr());
	Preprocessed out;
	tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
	if (!robot) throw Refusal("no <robot> element");
	auto capsuleToCylinder = [](tinyxml2::XMLElement* holder) {
		tinyxml2::XMLElement* geometry = holder->FirstChildElement("geometry");
		tinyxml2::XMLElement* shape = geometry ? geometry->FirstChildElement() : nullptr;
		if (!shape || std::strcmp(shape->Name(), "capsule") != 0) return false;
		shape->SetName("cylinder");  // same attributes (radius, length)
		return true;
	};
	// a material defined twice at the top level: urdfdom refuses the file, pybullet takes it (materials only colour
	// visuals, which are not used): the later definitions go
	std::vector<std::string> materials;
	for (tinyxml2::XMLElement* m = robot->FirstChildElement("material"); m;)
	{
		tinyxml2::XMLElement* next = m->NextSiblingElement("material");
		const std::string name = m->Attribute("name") ? m->Attribute("name") : "";
		if (std::find(materials.begin(), materials.end(), name) != materials.end()) robot->DeleteChild(m);
		else materials.push_back(name);
		m = next;
	}
	for (tinyxml2::XMLElement* link = robot->FirstChildElement("link"); link; link = link->NextSiblingElement("link"))
	{
		const char* name = link->Attribute("name");
		std::vector<bool>& capsules = out.capsule[name ? name : ""];
		if (link->FirstChildElement("inertial")) out.inertial.push_back(name ? name : "");
		for (tinyxml2::XMLElement* c = link->FirstChildElement("collision"); c; c = c->NextSiblingElement("collision"))
			capsules.push_back(capsuleToCylinder(c));
		for (tinyxml2::XMLElement* v = link->FirstChildElement("visual"); v; v = v->NextSiblingElement("visual"))
			capsuleToCylinder(v);  // visuals are not used: only so that urdfdom accepts the file
	}
	for (tinyxml2::XMLElement* joint = robot->FirstChildElement("joint"); joint; joint = joint->NextSiblingElement("joint"))
	{
		const std::string name = joint->Attribute("name") ? joint->Attribute("name") : "";
		const std::string type = joint->Attribute("type") ? joint->Attribute("type") : "";
		if (type == "planar" || type == "floating" || type == "spherical")
			throw Refusal("joint '" + name + "': type " + type + " cannot be represented (hinges and sliders only)");
		if (tinyxml2::XMLElement* limit = joint->FirstChildElement("limit"))
		{
			out.limits[name] = {attributeOr(*limit, "lower", 0), attributeOr(*limit, "upper", -1)};
			if (!limit->Attribute("effort")) limit->SetAttribute("effort", 0);
			if (!limit->Attribute("velocity")) limit->SetAttribute("velocity", 0);
		}
	}
	normalizeVectors(*robot);
	tinyxml2::XMLPrinter printer;
	doc.Print(&printer);
	out.xml = printer.CStr();
	return out;
}

}  // namespace urdfimport
}  // namespace scenes
}  // namespace quathinge
#endif
