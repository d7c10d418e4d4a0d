#pragma once
// The stage options (stage_options.hpp) on a command line, CLI11's: a
// stage's command declares its options with addStageOptions, `articula run`
// every stage's with addRunOptions. --help shows each one's type, default,
// unit and range; the values given are checked once parsed
// (StageOption::problem), so that a value out of range is a usage error
// (exit 2) naming the option before any work. One call per CLI::App.
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "articula/pipeline/stage_options.hpp"

namespace articula::pipeline {

/// The named stage's options, bound to `settings`.
void addStageOptions(CLI::App& app, const std::string& stage, StageSettings& settings);

/// Every stage's options under their run names, bound to `settings`: an
/// option that several stages take (--series-uid, --min-radius) is one,
/// bound to the first stage's field and checked by every stage's
/// declaration. Returns them by run name, for forwardedArguments.
std::map<std::string, CLI::Option*> addRunOptions(CLI::App& app, StageSettings& settings);

/// What run passes the stage of the options given to it (on the command
/// line or in a --config file): "--name" and its values joined by ',' (a
/// flag alone), under the stage's own names; options given empty add nothing.
std::vector<std::string> forwardedArguments(const std::string& stage, const std::map<std::string, CLI::Option*>& run_options);

}  // namespace articula::pipeline
