#include "articula/subject/slicer_scene.hpp"

#include <array>
#include <cstdio>

#include "articula/report/diverging_colour.hpp"
#include "articula/report/markup_text.hpp"

namespace articula::subject {
namespace {

using report::escapeMarkup;

std::string number(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", v);
  return buffer;
}

// Slicer's ColorTable with its colours inline: the reports' diverging scale
// (red inside, blue outside) sampled at 256 entries. Slicer's own
// DivergingBlueRed runs the other way. `type` (13: user) must come before
// the colours, which it would clear.
std::string colourTable(const std::string& id) {
  std::string colours;
  for (int i = 0; i < 256; ++i) {
    const std::array<std::uint8_t, 3> rgb = report::divergingRgb(-1.0 + 2.0 * i / 255.0);
    colours += (i ? " " : "") + std::to_string(i) + " d" + std::to_string(i);
    for (const std::uint8_t c : rgb) colours += " " + number(c / 255.0);
    colours += " 1";
  }
  return " <ColorTable id=\"" + id + "\" name=\"articula signed distance (red inside, blue outside)\" type=\"13\" "
         "numcolors=\"256\" colors=\"" + colours + "\"></ColorTable>\n";
}

struct ModelNode {
  std::string name, file, colour = "0.9 0.9 0.3";
  double opacity = 1;
  bool visible = true, points = false;
  std::string scalar_name, colour_node;
  double range = 0;
};

std::string modelNodes(const ModelNode& m, int index) {
  const std::string n = std::to_string(index);
  std::string display = " <ModelDisplay id=\"vtkMRMLModelDisplayNode" + n + "\" name=\"" + escapeMarkup(m.name) +
                        " display\" color=\"" + m.colour + "\" opacity=\"" + number(m.opacity) + "\" visibility=\"" +
                        (m.visible ? "true" : "false") + "\" visibility3D=\"true\" visibility2D=\"" +
                        (m.points ? "false" : "true") + "\"";
  if (m.points) display += " representation=\"0\" pointSize=\"5\"";
  if (!m.scalar_name.empty())
    display += " scalarVisibility=\"true\" activeScalarName=\"" + escapeMarkup(m.scalar_name) +
               "\" activeAttributeLocation=\"point\" scalarRangeFlag=\"UseManual\" scalarRange=\"" + number(-m.range) + " " +
               number(m.range) + "\" colorNodeID=\"" + m.colour_node + "\"";
  else
    display += " scalarVisibility=\"false\"";
  return " <ModelStorage id=\"vtkMRMLModelStorageNode" + n + "\" name=\"" + escapeMarkup(m.name) + " storage\" fileName=\"" +
         escapeMarkup(m.file) + "\" coordinateSystem=\"LPS\"></ModelStorage>\n" + display + "></ModelDisplay>\n" +
         " <Model id=\"vtkMRMLModelNode" + n + "\" name=\"" + escapeMarkup(m.name) + "\" references=\"display:vtkMRMLModelDisplayNode" +
         n + ";storage:vtkMRMLModelStorageNode" + n + ";\"></Model>\n";
}

std::string markupNodes(const MarkupFile& f, int index) {
  const std::string n = std::to_string(index);
  const std::string tag = f.is_line ? "MarkupsLine" : "MarkupsFiducial";
  const std::string display_tag = f.is_line ? "MarkupsDisplay" : "MarkupsFiducialDisplay";
  return " <MarkupsJsonStorage id=\"vtkMRMLMarkupsJsonStorageNode" + n + "\" name=\"" + escapeMarkup(f.name) +
         " storage\" fileName=\"slicer/" + escapeMarkup(f.file_name) + "\" coordinateSystem=\"LPS\"></MarkupsJsonStorage>\n" +
         " <" + display_tag + " id=\"vtkMRML" + display_tag + "Node" + n + "\" name=\"" + escapeMarkup(f.name) +
         " display\" visibility=\"true\" color=\"1 1 0\" selectedColor=\"1 0.5 0\" glyphScale=\"2\" textScale=\"2\"></" +
         display_tag + ">\n <" + tag + " id=\"vtkMRML" + tag + "Node" + n + "\" name=\"" + escapeMarkup(f.name) +
         "\" references=\"display:vtkMRML" + display_tag + "Node" + n + ";storage:vtkMRMLMarkupsJsonStorageNode" + n +
         ";\"></" + tag + ">\n";
}

}  // namespace

std::string slicerSceneXml(const SlicerSceneContent& content) {
  const std::string colour_node = "vtkMRMLColorTableNodeArticulaSignedDistance";
  // A positive revision: Slicer 5.10+ reads an old-style version as a legacy
  // scene and forces RAS on files without SPACE.
  std::string xml = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<MRML version=\"Slicer 5.0.0 1\" userTags=\"\">\n" +
                    colourTable(colour_node);
  int index = 1;
  const auto plain = [](const std::string& name, const std::string& file, const std::string& colour, double opacity) {
    ModelNode m;
    m.name = name, m.file = file, m.colour = colour, m.opacity = opacity;
    return m;
  };
  if (content.bone) xml += modelNodes(plain("bone", "bone.vtp", "0.89 0.84 0.72", 0.6), index++);
  static const std::array<const char*, 6> palette = {"0.30 0.69 0.29", "1 0.5 0", "0.6 0.31 0.64",
                                                     "0.65 0.34 0.16", "0.91 0.16 0.54", "0.6 0.6 0.6"};
  for (size_t i = 0; i < content.models.size(); ++i) {
    const std::string& model = content.models[i];
    const auto range = content.colour_range_mm.find(model);
    ModelNode points = plain(model + " points", "errors/points_" + model + ".vtp", "0.9 0.9 0.3", 1.0);
    points.visible = model == content.selected_model;
    points.points = true;
    points.scalar_name = "signed_distance_mm";
    points.colour_node = colour_node;
    points.range = range == content.colour_range_mm.end() ? 1.0 : range->second;
    xml += modelNodes(points, index++);
    ModelNode surface = plain(model + " fitted", "errors/surface_" + model + ".ply", palette[i % palette.size()], 0.4);
    surface.visible = false;
    xml += modelNodes(surface, index++);
  }
  int markup_index = 1;
  for (const auto& f : content.markups) xml += markupNodes(f, markup_index++);
  return xml + "</MRML>\n";
}

}  // namespace articula::subject
