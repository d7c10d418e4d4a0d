#include "articula/pipeline/stage_options.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <map>

#include "articula/core/error.hpp"
#include "articula/core/excerpt.hpp"
#include "articula/core/number_text.hpp"
#include "articula/fit/fit_hierarchy.hpp"
#include "articula/geometry/shape.hpp"
#include "articula/pipeline/stages.hpp"

namespace articula::pipeline {

FitSettings::FitSettings() {
  const fit::Options defaults;
  for (const auto model : defaults.models) models.push_back(geometry::modelName(model));
  objective = fit::objectiveName(defaults.objective);
  strategy = fit::strategyName(defaults.strategy);
  local_algorithm = defaults.local_algorithm;
  max_evaluations = defaults.max_evaluations;
  sample_points = defaults.sample_points;
}

namespace {

// The settings field an option binds: `FIELD(segment().head.hu_min)`.
#define FIELD(path) [](StageSettings& s) -> OptionField { return &s.path; }

constexpr auto option = stageOption;

std::vector<std::string> modelNames() {
  std::vector<std::string> names;
  for (const auto model : geometry::allModels()) names.push_back(geometry::modelName(model));
  return names;
}

// The stages' options. A range here is what the command line refuses before
// any work; the library's validate() of each options struct still guards its
// own callers (and checks what one option says of another).
const std::map<std::string, std::vector<StageOption>>& declarations() {
  static const std::map<std::string, std::vector<StageOption>> table = {
      {"segment",
       {
           option("seed-point", FIELD(segment().seed_point), "A point inside the head, X,Y,Z in LPS mm (skips the search)")
               .values(3)
               .unitIs("mm"),
           option("series-uid", FIELD(segment().series_uid),
                  "DICOM series to read when the folder holds several (empty: the series whose Series Instance UID "
                  "is empty)"),
           option("hu-min", FIELD(segment().head.hu_min), "Lower end of the bone window").in(-2000, 10000).unitIs("HU"),
           option("hu-max", FIELD(segment().head.hu_max), "Upper end of the bone window").in(-2000, 40000).unitIs("HU"),
           option("surface-hu", FIELD(segment().head.surface_hu), "Level of the head's final surface")
               .in(-2000, 40000)
               .unitIs("HU"),
           option("level-set", FIELD(segment().head.level_set_iterations),
                  "Refine the head's surface by a geodesic active contour of this many iterations (0: off)")
               .in(0, 10000),
           option("close-radius", FIELD(segment().head.close_radius_mm),
                  "Closing radius before hole filling (bridges speckled cancellous bone; 0: off)")
               .in(0, 20)
               .unitIs("mm"),
           option("midline-margin", FIELD(segment().head.midline_margin_mm),
                  "Least distance of an automatically found head from the volume's mid-sagittal plane "
                  "(-1: 40 mm when the field of view spans 250 mm or more left-right, else 0)")
               .in(-1, 500)
               .unitIs("mm"),
           option("min-coverage", FIELD(segment().head.min_coverage),
                  "Least share of an automatically found head's sphere that is bone surface")
               .in(0, 1),
           option("roi", FIELD(segment().roi), "Box xmin,ymin,zmin,xmax,ymax,zmax in LPS mm").values(6).unitIs("mm"),
           option("min-radius", FIELD(segment().head.min_head_radius_mm), "Smallest plausible head radius")
               .in(1, 60)
               .unitIs("mm"),
           option("max-radius", FIELD(segment().head.max_head_radius_mm), "Largest plausible head radius")
               .in(1, 60)
               .unitIs("mm"),
           option("label", FIELD(segment().label),
                  "A label map in the CT's grid (a femur or humerus mask from another tool): the head is cut from "
                  "its bone"),
           option("label-value", FIELD(segment().label_value),
                  "The label's value of the bone (0: every non-zero voxel)")
               .in(0, 65535),
       }},
      {"mesh",
       {
           option("smoothing", FIELD(mesh().smoothing), "laplacian, sinc (windowed sinc) or none")
               .oneOf({"laplacian", "sinc", "none"}),
           option("smooth-iterations", FIELD(mesh().surface.smooth_iterations), "Smoothing iterations").in(0, 10000),
           option("relaxation", FIELD(mesh().surface.relaxation), "Laplacian relaxation factor").above(0).in(0, 1),
           option("passband", FIELD(mesh().surface.passband), "Windowed sinc pass band").above(0).in(0, 2),
           option("decimate", FIELD(mesh().surface.decimate), "Fraction of triangles to remove (0 = none; below 1)")
               .in(0, 1),
           option("all-components", FIELD(mesh().all_components), "Keep every connected surface, not only the largest"),
           option("series-uid", FIELD(mesh().series_uid),
                  "With --ct: the DICOM series to read when the folder holds several (empty: the series whose UID is "
                  "empty)"),
           option("edge-search", FIELD(mesh().edges.search_mm),
                  "With --ct: edge search either side of a vertex (0: 1.5 voxels, at least 1.5 mm)")
               .in(0, 10)
               .unitIs("mm"),
           option("edge-model", FIELD(mesh().edge_model),
                  "With --ct: 'steepest' puts each edge on the steepest HU fall (a cortex thinner than about three "
                  "point-spreads pulls it outwards); 'cortex' on the outer surface of a blurred-cortex model fitted to "
                  "the voxels about the normal, with one point-spread for the CT; 'auto' the cortex model on CTs "
                  "whose voxels are at most 1.5 mm within the slices and 3 mm across them, the steepest fall beyond")
               .oneOf({"auto", "cortex", "steepest"}),
           option("point-spread", FIELD(mesh().edges.point_spread_mm),
                  "With --ct and the cortex model: the scanner's Gaussian point-spread (standard deviation) within "
                  "the slices (0: this and the slices' estimated from the CT's edges)")
               .in(0, 3)
               .unitIs("mm"),
           option("slice-point-spread", FIELD(mesh().edges.slice_point_spread_mm),
                  "With --point-spread: the point-spread across the slices (the slice profile's standard deviation; "
                  "0: as within the slices)")
               .in(0, 3)
               .unitIs("mm"),
           option("slice-thickness", FIELD(mesh().edges.slice_thickness_mm),
                  "With --ct: what a voxel averages over across the slices, where the CT does not say (a NIfTI file "
                  "holds no slice thickness; 0: a DICOM series' Slice Thickness, else the slices' spacing)")
               .in(0, 20)
               .unitIs("mm"),
       }},
      {"sample",
       {
           option("select", FIELD(sample().select),
                  "auto | sphere:X,Y,Z,R | box:XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX (LPS mm)"),
           option("ball-radius", FIELD(sample().downsampling.ball_radius_mm), "Open-ball radius of the down-sampling")
               .in(0, 1000)
               .unitIs("mm"),
           option("ratio", FIELD(sample().downsampling.ratio),
                  "Stop when kept/original reaches this fraction (1: until no point is left)")
               .above(0)
               .in(0, 1),
           // Ranges as the library checks them, one against the other (0 < min < max <= 200 mm).
           option("min-radius", FIELD(sample().selection.min_radius_mm), "auto: smallest head radius").unitIs("mm"),
           option("max-radius", FIELD(sample().selection.max_radius_mm), "auto: largest head radius").unitIs("mm"),
           option("band", FIELD(sample().selection.band_mm), "auto: distance band around the sphere")
               .above(0)
               .in(0, 50)
               .unitIs("mm"),
           option("min-points", FIELD(sample().selection.min_points), "Fewest selected points accepted")
               .in(1, 100000000),
       }},
      {"fit",
       {
           option("models", FIELD(fit().models), "Comma-separated models to report").oneOf(modelNames()),
           option("objective", FIELD(fit().objective), "geometric (orthogonal distances) or algebraic (thesis eq. 3.1)")
               .oneOf({"geometric", "algebraic"}),
           option("strategy", FIELD(fit().strategy),
                  "local (from the hierarchical start) or global-local (GN_CRS2_LM first)")
               .oneOf({"local", "global-local"}),
           option("local-algorithm", FIELD(fit().local_algorithm),
                  "Local method: LM (Levenberg-Marquardt on the residuals) or NLopt's LD_SLSQP, LN_BOBYQA, LD_LBFGS, "
                  "LD_MMA"),
           option("max-evaluations", FIELD(fit().max_evaluations), "Evaluation cap per local run").in(1, 100000000),
           option("sample-points", FIELD(fit().sample_points),
                  "More points than this: fit on a seeded random sample of this many, then finish on all (0 = always "
                  "all; else at least 1000)")
               .in(0, 100000000),
           option("bounds", FIELD(fit().bounds), "JSON of parameter bounds overrides, e.g. {\"gamma1\": [2, 3]}"),
       }},
      {"errors",
       {
           option("band", FIELD(errors().band_mm), "Half-width of the green band of the coloured points")
               .above(0)
               .in(0, 1000)
               .unitIs("mm")
               .runAs("errors-band"),
           option("resolution", FIELD(errors().resolution), "Surface mesh steps around the local z axis").in(8, 2048),
           option("map-points", FIELD(errors().map_points),
                  "Points drawn per model in error_map.svg (every k-th when more)")
               .in(1, 100000000),
       }},
      {"report",
       {
           option("series-uid", FIELD(report().series_uid),
                  "Series Instance UID of the CT in a DICOM folder holding several (for the slices of report.html)"),
           option("selection-alpha", FIELD(report().selection_alpha),
                  "Level of the nested tests that take a richer model (0: always the sphere)")
               .in(0, 0.5),
           option("selection-length", FIELD(report().selection_length_mm),
                  "Length over which the nested tests count the surface's errors as shared (0: each fit's own "
                  "residual correlation)")
               .in(0, 50)
               .unitIs("mm"),
       }},
  };
  return table;
}

#undef FIELD

std::string numberText(double v) {
  std::string text;
  appendNumber(text, v, 15);
  return text;
}

std::string joined(const std::vector<std::string>& items, const char* separator) {
  std::string s;
  for (const auto& item : items) s += (s.empty() ? "" : separator) + item;
  return s;
}

// The whole text as a number of type T ("" when it is one), else why not.
template <class T>
bool parseWhole(const std::string& text, T& value) {
  if constexpr (std::is_same_v<T, double>) {
    // strtod rather than from_chars: it takes "inf" and "nan" as CLI11 does,
    // so that the range check, not the parser, names them.
    if (text.empty()) return false;
    char* end = nullptr;
    errno = 0;
    value = std::strtod(text.c_str(), &end);
    return end == text.c_str() + text.size();
  } else {
    const auto [next, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    return error == std::errc() && next == text.data() + text.size();
  }
}

}  // namespace

StageOption stageOption(std::string name, OptionField (*field)(StageSettings&), std::string help) {
  StageOption o;
  o.name = std::move(name);
  o.field = field;
  o.help = std::move(help);
  return o;
}

std::string typeName(OptionType type) {
  switch (type) {
    case OptionType::Number: return "number";
    case OptionType::Integer: return "integer";
    case OptionType::Flag: return "flag";
    case OptionType::Text: return "text";
    case OptionType::File: return "file";
    case OptionType::Choice: return "choice";
    case OptionType::Numbers: return "numbers";
    case OptionType::Choices: return "choices";
  }
  return "text";
}

StageOption StageOption::in(double lo, double hi) const {
  StageOption o = *this;
  if (!o.above_min) o.min = lo;
  o.max = hi;
  return o;
}
StageOption StageOption::above(double lo) const {
  StageOption o = *this;
  o.min = lo;
  o.above_min = true;
  return o;
}
StageOption StageOption::oneOf(std::vector<std::string> names) const {
  StageOption o = *this;
  o.choices = std::move(names);
  return o;
}
StageOption StageOption::values(int n) const {
  StageOption o = *this;
  o.count = n;
  return o;
}
StageOption StageOption::unitIs(std::string u) const {
  StageOption o = *this;
  o.unit = std::move(u);
  return o;
}
StageOption StageOption::runAs(std::string name_in_run) const {
  StageOption o = *this;
  o.run_name = std::move(name_in_run);
  return o;
}

OptionType StageOption::type() const {
  StageSettings defaults;
  const OptionField f = field(defaults);
  if (std::holds_alternative<double*>(f)) return OptionType::Number;
  if (std::holds_alternative<int*>(f)) return OptionType::Integer;
  if (std::holds_alternative<bool*>(f)) return OptionType::Flag;
  if (std::holds_alternative<std::filesystem::path*>(f)) return OptionType::File;
  if (std::holds_alternative<std::vector<double>*>(f)) return OptionType::Numbers;
  if (std::holds_alternative<std::vector<std::string>*>(f)) return OptionType::Choices;
  return choices.empty() ? OptionType::Text : OptionType::Choice;
}

nlohmann::json StageOption::defaultValue() const {
  StageSettings defaults;
  return std::visit(
      [](auto* value) -> nlohmann::json {
        if constexpr (std::is_same_v<std::decay_t<decltype(*value)>, std::filesystem::path>)
          return value->string();
        else
          return *value;
      },
      field(defaults));
}

std::string StageOption::defaultText() const {
  const nlohmann::json value = defaultValue();
  if (value.is_string()) return value.get<std::string>();
  if (value.is_boolean()) return value.get<bool>() ? "true" : "false";
  if (value.is_number_integer()) return std::to_string(value.get<long long>());
  if (value.is_number()) return numberText(value.get<double>());
  std::vector<std::string> items;  // a list
  for (const auto& item : value) items.push_back(item.is_string() ? item.get<std::string>() : numberText(item.get<double>()));
  return joined(items, ",");
}

std::string StageOption::rangeText() const {
  if (!choices.empty()) return joined(choices, ", ");
  if (min && max) return (above_min ? "above " + numberText(*min) + ", up to " : numberText(*min) + " to ") + numberText(*max);
  if (min) return (above_min ? "above " : "at least ") + numberText(*min);
  if (max) return "at most " + numberText(*max);
  return "";
}

std::string StageOption::problem(const std::vector<std::string>& values) const {
  const OptionType t = type();
  const std::string what = "--" + name + (unit.empty() ? "" : " (" + unit + ")") + ": expected ";
  if (t == OptionType::Numbers && count > 0 && static_cast<int>(values.size()) != count)
    return what + std::to_string(count) + " numbers separated by commas, found " + std::to_string(values.size());
  for (const std::string& text : values) {
    if (t == OptionType::Choice || t == OptionType::Choices) {
      if (std::find(choices.begin(), choices.end(), text) == choices.end())
        return what + (t == OptionType::Choices ? "each of " : "") + rangeText() + ", found '" + excerpt(text) + "'";
      continue;
    }
    if (t != OptionType::Number && t != OptionType::Integer && t != OptionType::Numbers) continue;
    double value = 0;
    if (t == OptionType::Integer) {
      long long whole = 0;
      if (!parseWhole(text, whole)) return what + "a whole number, found '" + excerpt(text) + "'";
      value = static_cast<double>(whole);
    } else if (!parseWhole(text, value)) {
      return what + "a number, found '" + excerpt(text) + "'";
    }
    const bool low = min && (above_min ? !(value > *min) : !(value >= *min));
    const bool high = max && !(value <= *max);
    if (low || high) return what + rangeText() + ", found " + excerpt(text);
  }
  return "";
}

nlohmann::json StageOption::json() const {
  nlohmann::json j = {{"name", name}, {"run_name", runName()}, {"type", typeName(type())},
                      {"default", defaultValue()}, {"help", help}};
  if (!unit.empty()) j["unit"] = unit;
  if (min) j[above_min ? "above" : "min"] = *min;
  if (max) j["max"] = *max;
  if (!choices.empty()) j["choices"] = choices;
  if (count > 0) j["count"] = count;
  return j;
}

const std::vector<StageOption>& stageOptions(const std::string& stage) {
  const auto& table = declarations();
  const auto it = table.find(stage);
  return it != table.end() ? it->second : stageNamed(stage).options;  // a stage registered from its own file
}

std::vector<StageOptionOf> optionsRunAs(const std::string& run_name) {
  std::vector<StageOptionOf> found;
  for (const auto& stage : stages())
    for (const auto& declared : stage.options)
      if (declared.runName() == run_name) found.push_back({stage.name, &declared});
  return found;
}

std::vector<std::string> splitList(const std::string& text) {
  std::vector<std::string> items;
  size_t start = 0;
  for (size_t comma; (comma = text.find(',', start)) != std::string::npos; start = comma + 1)
    items.push_back(text.substr(start, comma - start));
  items.push_back(text.substr(start));
  return items;
}

}  // namespace articula::pipeline
