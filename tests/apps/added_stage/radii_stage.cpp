// A stage added in one file, as a developer adds one: its settings, its row
// in the stage table, its command and the registration line. The test
// app_added_stage links it into the driver and checks that `articula run`,
// `articula stages --json`, a manifest column and the Snakemake workflow
// take it without any other edit. It writes every fitted model's semi-axes,
// times a factor, to radii.csv.
#include "articula/cli/command.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/json_file.hpp"
#include "articula/core/number_text.hpp"
#include "articula/core/output_paths.hpp"
#include "articula/pipeline/stage_options_cli.hpp"
#include "articula/pipeline/stages.hpp"

namespace articula::tests {
namespace {

struct RadiiSettings {
  double scale = 1.0;
};

pipeline::StageDescription describeRadii() {
  return {"radii",
          "Every fitted model's semi-axes, times a factor",
          {pipeline::stageOption("radii-scale", ARTICULA_STAGE_FIELD(RadiiSettings, "radii", scale),
                                 "Factor on every semi-axis")
               .above(0)
               .in(0, 1000)},
          {"fits.json"},
          {"radii.csv"},
          {"-i", "{folder}/fits.json", "-o", "{folder}/radii.csv"},
          {},
          1, 100};
}

class RadiiCommand : public cli::Command {
 public:
  std::string name() const override { return "radii"; }
  std::string description() const override { return describeRadii().description; }
  std::string example() const override { return "articula-radii -i fits.json -o radii.csv --radii-scale 2"; }
  void declare(CLI::App& app) override {
    app.add_option("-i,--input", input_, "fits.json")->required();
    app.add_option("-o,--output", output_, "radii.csv")->required();
    pipeline::addStageOptions(app, name(), settings_);
  }
  int run(const cli::CommonOptions& common) override {
    const double scale = settings_.of<RadiiSettings>("radii").scale;
    refuseOutputsOverInputs({output_}, {input_});
    cli::refuseExistingOutputs({output_}, common.force);
    const nlohmann::json fits = readJsonFile(input_, "fits.json");
    std::string csv = "model,a_mm,b_mm,c_mm\n";
    for (const auto& model : fits.at("models")) {
      csv += model.at("model").get<std::string>();
      for (const auto& radius : model.at("radii_mm")) {
        csv += ",";
        appendNumber(csv, scale * radius.get<double>(), 15);
      }
      csv += "\n";
    }
    writeFileAtomically(output_, csv, true);
    return 0;
  }

 private:
  std::filesystem::path input_, output_;
  pipeline::StageSettings settings_;
};

ARTICULA_REGISTER_STAGE(RadiiCommand, describeRadii)

}  // namespace
}  // namespace articula::tests
