// `articula stages [--json]`: the pipeline's stages in run order, with the
// options each takes and the files it reads and writes (pipeline/stages.hpp).
// pipelines/Snakefile reads the --json form.
#include <iostream>

#include "articula/cli/command.hpp"
#include "articula/pipeline/stages.hpp"

namespace articula::apps {
namespace {

std::string joined(const std::vector<std::string>& items) {
  std::string s;
  for (const auto& i : items) s += (s.empty() ? "" : " ") + i;
  return s.empty() ? "-" : s;
}

class StagesCommand : public cli::Command {
 public:
  std::string name() const override { return "stages"; }
  std::string description() const override {
    return "List the pipeline's stages, their options, inputs and outputs";
  }
  std::string example() const override { return "articula stages --json"; }
  void declare(CLI::App&) override {}
  int run(const cli::CommonOptions& common) override {
    if (common.json) {
      cli::printJson(pipeline::stagesJson());
      return 0;
    }
    for (const auto& s : pipeline::stages()) {
      std::cout << s.name << ": " << s.description << "\n  reads: " << joined(s.inputs)
                << "\n  writes: " << joined(s.outputs) << "\n  options:" << (s.options.empty() ? " -" : "") << "\n";
      for (const auto& o : s.options) {
        const std::string range = o.rangeText(), fallback = o.defaultText();
        std::cout << "    --" << o.name << (o.runName() != o.name ? " (run: --" + o.runName() + ")" : "") << " "
                  << pipeline::typeName(o.type()) << (o.unit.empty() ? "" : ", " + o.unit)
                  << (range.empty() ? "" : ", " + range) << (fallback.empty() ? "" : ", default " + fallback) << "\n";
      }
    }
    return 0;
  }
};

ARTICULA_REGISTER_COMMAND(StagesCommand)

}  // namespace
}  // namespace articula::apps
