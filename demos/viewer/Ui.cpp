// The viewer's Dear ImGui layer (Viewer.h): each pane's label (its kind and figures), the control panel (scene, kinds,
// the stabilizer's optional parts, time step, iterations, pause, single step, reset) and the live plots of separation,
// misalignment and energy.
#include "Viewer.h"

#include "quathinge/btQuaternionHingeStabilizer.h"

#include <imgui.h>

#include <algorithm>
#include <cfloat>
#include <cstdio>
#include <sstream>

using namespace quathinge::scenes;

namespace quathinge
{
namespace viewer
{
// The kind's name and its figures over each pane (ImGui's foreground draw list: no window).
void Viewer::labels(int width, int height, int paneWidth)
{
	(void)width;
	(void)height;
	ImDrawList* draw = ImGui::GetForegroundDrawList();
	for (int i = 0; i < int(m_panes.size()); ++i)
	{
		const Pane& p = m_panes[size_t(i)];
		std::ostringstream text;
		text << kindName(p.kind);
		if (!p.error.empty()) text << ": " << p.error;
		else if (p.sim && !p.sim->finiteAndBounded()) text << ": blew up";
		else
		{
			char line[160];
			std::snprintf(line, sizeof line, "\nmax separation %.3g mm\nmax misalignment %.3g deg", p.maxSeparation * 1e3,
						  p.maxMisalignmentDeg);
			text << line;
		}
		draw->AddText(ImGui::GetFont(), 17.0f, ImVec2(float(m_left + i * paneWidth + 12), 10),
					  IM_COL32(255, 255, 255, 255), text.str().c_str(), nullptr, float(paneWidth - 24));
	}
	char info[256];
	std::snprintf(info, sizeof info, "%s   t = %.2f s   dt = %.4f s, %d iterations", m_scene.c_str(), m_steps * double(m_dt),
				  double(m_dt), m_iterations);
	draw->AddText(ImGui::GetFont(), 15.0f, ImVec2(float(m_left + 12), float(height - 24)), IM_COL32(220, 220, 220, 255),
				  info);
}

void Viewer::panel()
{
	ImGui::SetNextWindowPos(ImVec2(0, 0), ImGuiCond_Always);
	ImGui::SetNextWindowSize(ImVec2(float(kPanelWidth), ImGui::GetIO().DisplaySize.y), ImGuiCond_Always);
	ImGui::Begin("QuatHinge viewer", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
	ImGui::TextWrapped("%s", m_description.c_str());
	if (ImGui::BeginCombo("scene", m_scene.c_str()))
	{
		for (const std::string& name : m_sceneNames)
			if (ImGui::Selectable(name.c_str(), name == m_scene))
			{
				m_scene = name;
				m_resetRequested = true;
			}
		ImGui::EndCombo();
	}
	for (Kind k : m_allKinds)
	{
		bool on = std::find(m_kinds.begin(), m_kinds.end(), k) != m_kinds.end();
		if (ImGui::Checkbox(kindName(k).c_str(), &on))
		{
			if (on) m_kinds.push_back(k);
			else m_kinds.erase(std::remove(m_kinds.begin(), m_kinds.end(), k), m_kinds.end());
			m_resetRequested = true;
		}
	}
	// the stabilizer's optional parts (quaternion+stab panes), applied at once
	bool changed = ImGui::Checkbox("stab: point constraints", &m_projectPoints);
	changed |= ImGui::Checkbox("stab: sliders and welds", &m_projectLocked);
	changed |= ImGui::Checkbox("stab: contacts", &m_projectContacts);
	changed |= ImGui::Checkbox("stab: carry attached", &m_moveAttached);
	changed |= ImGui::Checkbox("stab: close attached", &m_closeAttached);
	if (changed) applyStabilizerOptions();
	ImGui::SliderFloat("dt (s)", &m_dt, 1.0f / 480, 1.0f / 30, "%.4f");
	ImGui::SliderInt("iterations", &m_iterations, 1, 100);
	ImGui::Checkbox("pause", &m_paused);
	ImGui::SameLine();
	if (ImGui::Button("step")) m_singleStep = true;
	ImGui::SameLine();
	if (ImGui::Button("reset")) m_resetRequested = true;
	ImGui::Separator();
	for (const Pane& p : m_panes)
	{
		if (p.series.separation.empty()) continue;
		ImGui::Text("%s", kindName(p.kind).c_str());
		plot("separation (mm)", p.series.separation);
		plot("misalignment (deg)", p.series.misalignment);
		plot("energy (J)", p.series.energy);
	}
	ImGui::TextWrapped("left drag: pick and drag a body; right drag: orbit; wheel: zoom");
	ImGui::End();
}

void Viewer::applyStabilizerOptions()
{
	for (Pane& p : m_panes)
	{
		btQuaternionHingeStabilizer* stabilizer = p.sim ? p.sim->stabilizer() : nullptr;
		if (!stabilizer) continue;
		btQuaternionHingeStabilizerSettings settings = stabilizer->getSettings();
		settings.projectPointConstraints = m_projectPoints;
		settings.projectLockedConstraints = m_projectLocked;
		settings.projectContacts = m_projectContacts;
		settings.moveAttachedBodies = m_moveAttached;
		settings.closeAttachedConstraints = m_closeAttached;
		stabilizer->setSettings(settings);
	}
}

void Viewer::plot(const char* label, const std::deque<float>& d)
{
	const std::vector<float> v(d.begin(), d.end());
	char overlay[64];
	std::snprintf(overlay, sizeof overlay, "%.3g", double(v.back()));
	ImGui::PlotLines(label, v.data(), int(v.size()), 0, overlay, FLT_MAX, FLT_MAX, ImVec2(0, 40));
}

}  // namespace viewer
}  // namespace quathinge
