#pragma once
// Every option a user may give a stage, declared once: its name, type,
// default, range or choices, unit and help, bound to the field of the
// stage's settings it sets. The default is that field's initial value (in
// the library's options structs), so it is written nowhere else. From here:
// each stage's command line (stage_options_cli.hpp), `articula run` (every
// option of every stage, forwarded to the stages that take it), `articula
// stages --json`, the Snakemake workflow and the checks of manifest columns.
// The arguments that wire a stage into a subject's folder (-i, -o, --ct,
// --fits, --joint, --side, the sample's --format) are the stage table's
// (stages.hpp), not options a user gives through run.
#include <any>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "articula/imaging/segment.hpp"
#include "articula/mesh/mesh.hpp"
#include "articula/subject/subject_report.hpp"
#include "articula/sampling/downsample.hpp"
#include "articula/sampling/select.hpp"

namespace articula::pipeline {

// What each stage's command reads from its options: the library's options
// structs, and the values its command turns into them (a choice's name, a
// point's numbers).
struct SegmentSettings {
  imaging::SegmentOptions head;
  std::string series_uid;
  std::vector<double> seed_point, roi;  // X,Y,Z; xmin,ymin,zmin,xmax,ymax,zmax (LPS mm); empty: none
  std::filesystem::path label;
  int label_value = 0;  // 0: every non-zero voxel of the label
};
struct MeshSettings {
  mesh::MeshOptions surface;
  mesh::EdgeSnapOptions edges;
  std::string smoothing = "laplacian", edge_model = "auto", series_uid;
  bool all_components = false;
};
struct SampleSettings {
  std::string select = "auto";
  sampling::SelectOptions selection;
  sampling::DownsampleOptions downsampling;
};
struct FitSettings {
  FitSettings();  // the fit library's defaults (fit::Options), by name
  std::vector<std::string> models;
  std::string objective, strategy, local_algorithm;
  int max_evaluations = 0, sample_points = 0;
  std::filesystem::path bounds;
};
struct ErrorsSettings {
  double band_mm = 0.1;  // half-width of the coloured points' green band
  int resolution = 96;   // fitted surfaces' steps about their z axis
  int map_points = 2000; // points per model in error_map.svg
};
/// Every stage's settings, by stage name: each stage's own struct, made with
/// its defaults when first asked for, so that a stage registered from its
/// own file (stages.hpp) brings its settings along.
class StageSettings {
 public:
  template <class Settings>
  Settings& of(const std::string& stage) {
    std::any& settings = by_stage_[stage];
    if (!settings.has_value()) settings = Settings{};
    return std::any_cast<Settings&>(settings);
  }
  SegmentSettings& segment() { return of<SegmentSettings>("segment"); }
  MeshSettings& mesh() { return of<MeshSettings>("mesh"); }
  SampleSettings& sample() { return of<SampleSettings>("sample"); }
  FitSettings& fit() { return of<FitSettings>("fit"); }
  ErrorsSettings& errors() { return of<ErrorsSettings>("errors"); }
  subject::SubjectReportOptions& report() { return of<subject::SubjectReportOptions>("report"); }

 private:
  std::map<std::string, std::any> by_stage_;
};

/// The field an option sets; its type is the option's.
using OptionField = std::variant<double*, int*, bool*, std::string*, std::filesystem::path*, std::vector<double>*,
                                 std::vector<std::string>*>;

enum class OptionType { Number, Integer, Flag, Text, File, Choice, Numbers, Choices };

/// "number", "integer", "flag", "text", "file", "choice", "numbers", "choices".
std::string typeName(OptionType type);

struct StageOption {
  std::string name;  // --name on the stage's command line
  std::string help;
  OptionField (*field)(StageSettings&) = nullptr;
  std::string unit;                  // "mm", "HU", or none
  std::optional<double> min, max;    // of a number or integer, or each of numbers
  bool above_min = false;            // min itself excluded
  std::vector<std::string> choices;  // of a choice, or each of choices
  int count = 0;                     // numbers: how many (0: any)
  /// run's and a manifest's name for it, when another stage's option of the
  /// same name means something else (errors' --band: run's --errors-band).
  std::string run_name;

  // Declaration helpers: option("hu-min", ...).in(-2000, 10000).unitIs("HU").
  StageOption in(double lo, double hi) const;
  StageOption above(double lo) const;  // (lo, max]
  StageOption oneOf(std::vector<std::string> names) const;
  StageOption values(int n) const;
  StageOption unitIs(std::string u) const;
  StageOption runAs(std::string name_in_run) const;

  OptionType type() const;
  const std::string& runName() const { return run_name.empty() ? name : run_name; }
  /// The field's value in default settings, as JSON and as command-line text ("" for none).
  nlohmann::json defaultValue() const;
  std::string defaultText() const;
  /// "-2000 to 10000", "above 0", "laplacian, sinc, none"; "" when any value goes.
  std::string rangeText() const;
  /// What is wrong with the option's values as a command line gives them
  /// (one each, or a list's items): "--hu-min (HU): expected -2000 to
  /// 10000, found 99999"; "" when they are fine.
  std::string problem(const std::vector<std::string>& values) const;
  /// {"name", "run_name", "type", "default", "unit", "min", "max", "choices", "count", "help"}.
  nlohmann::json json() const;
};

/// A stage option bound to a settings field, to be narrowed with in(),
/// oneOf(), unitIs() ...: stageOption("hu-min", FIELD, "help").in(-2000, 10000).
StageOption stageOption(std::string name, OptionField (*field)(StageSettings&), std::string help);

/// The field of a stage's own settings struct an option binds, for stages
/// declared in a file of their own (stages.hpp):
/// ARTICULA_STAGE_FIELD(RadiiSettings, "radii", scale).
#define ARTICULA_STAGE_FIELD(Settings, stage, member) \
  [](::articula::pipeline::StageSettings& s) -> ::articula::pipeline::OptionField { return &s.of<Settings>(stage).member; }

/// The options of the named stage, in the order of its --help.
const std::vector<StageOption>& stageOptions(const std::string& stage);

/// A stage's option.
struct StageOptionOf {
  std::string stage;
  const StageOption* option;
};

/// Every option whose run name is `run_name`, over all stages in run order
/// (several when stages share it: --series-uid, --min-radius); empty when none.
std::vector<StageOptionOf> optionsRunAs(const std::string& run_name);

/// A comma-separated list ("1,2,3", "sphere,ovoid") as its items, for a
/// manifest's cell or a config file's value.
std::vector<std::string> splitList(const std::string& text);

}  // namespace articula::pipeline
