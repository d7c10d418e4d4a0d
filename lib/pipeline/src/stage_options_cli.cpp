#include "articula/pipeline/stage_options_cli.hpp"

#include <algorithm>
#include <cctype>
#include <memory>

#include "articula/pipeline/stages.hpp"

namespace articula::pipeline {

namespace {

// An option's values as given, a list's items one by one (a config file
// gives a list as one value).
std::vector<std::string> givenValues(const CLI::Option& option) {
  std::vector<std::string> values;
  for (const std::string& result : option.results())
    for (std::string& item : splitList(result)) values.push_back(std::move(item));
  return values;
}

std::string upper(std::string text) {
  for (char& c : text) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return text;
}

// One command-line option `--name` for the declaration `first` (of several
// stages that share it in run: the first stage's), bound to its field in
// `settings`, its help after `prefix`.
CLI::Option* addOption(CLI::App& app, const std::string& name, const StageOption& first, StageSettings& settings,
                       const std::string& prefix) {
  std::string help = prefix + first.help;
  const std::string range = first.rangeText();
  if (!first.unit.empty() || !range.empty())
    help += " (" + first.unit + (first.unit.empty() || range.empty() ? "" : "; ") + range + ")";
  CLI::Option* option = std::visit(
      [&](auto* field) -> CLI::Option* {
        if constexpr (std::is_same_v<decltype(field), bool*>)
          return app.add_flag("--" + name, *field, help);
        else
          return app.add_option("--" + name, *field, help);
      },
      first.field(settings));
  const OptionType type = first.type();
  if (type == OptionType::Flag) return option;
  option->type_name(upper(typeName(type)));
  if (type == OptionType::Numbers || type == OptionType::Choices) option->delimiter(',');
  if (first.count > 0) option->expected(first.count);
  if (const std::string text = first.defaultText(); !text.empty()) option->default_str(text);
  return option;
}

// An option on the command line and the declarations that check it; the
// stage is named in a complaint when `name_stage` (run's options).
struct Check {
  CLI::Option* option;
  std::vector<StageOptionOf> declared;
  bool name_stage;
};

// Checks every given option by its declarations once the line is parsed.
void checkWhenParsed(CLI::App& app, std::vector<Check> checks) {
  app.final_callback([checks = std::move(checks)] {
    for (const Check& check : checks) {
      if (check.option->count() == 0) continue;
      const std::vector<std::string> values = givenValues(*check.option);
      for (const StageOptionOf& declared : check.declared)
        if (const std::string problem = declared.option->problem(values); !problem.empty())
          throw CLI::ValidationError((check.name_stage ? "the " + declared.stage + " stage: " : "") + problem);
    }
  });
}

}  // namespace

void addStageOptions(CLI::App& app, const std::string& stage, StageSettings& settings) {
  std::vector<Check> checks;
  for (const StageOption& declared : stageOptions(stage))
    checks.push_back({addOption(app, declared.name, declared, settings, ""), {{stage, &declared}}, false});
  checkWhenParsed(app, std::move(checks));
}

std::map<std::string, CLI::Option*> addRunOptions(CLI::App& app, StageSettings& settings) {
  std::map<std::string, CLI::Option*> options;
  std::vector<Check> checks;
  for (const auto& stage : stages())
    for (const StageOption& declared : stage.options) {
      if (options.count(declared.runName())) continue;
      const std::vector<StageOptionOf> takers = optionsRunAs(declared.runName());
      std::string names;
      for (const StageOptionOf& taker : takers) names += (names.empty() ? "" : ", ") + taker.stage;
      CLI::Option* option = addOption(app, declared.runName(), declared, settings, "[" + names + "] ");
      option->group("Stage options (articula stages)");
      options[declared.runName()] = option;
      checks.push_back({option, takers, true});
    }
  checkWhenParsed(app, std::move(checks));
  return options;
}

std::vector<std::string> forwardedArguments(const std::string& stage,
                                            const std::map<std::string, CLI::Option*>& run_options) {
  std::vector<std::string> args;
  for (const StageOption& declared : stageNamed(stage).options) {
    const auto it = run_options.find(declared.runName());
    if (it == run_options.end() || it->second->count() == 0) continue;
    if (declared.type() == OptionType::Flag) {
      if (it->second->as<bool>()) args.push_back("--" + declared.name);
      continue;
    }
    std::string value;
    for (const std::string& item : givenValues(*it->second)) value += (value.empty() ? "" : ",") + item;
    if (!value.empty()) args.insert(args.end(), {"--" + declared.name, value});
  }
  return args;
}

}  // namespace articula::pipeline
