#pragma once
// Every articula command has the same shape (as in MRtrix3): it declares its
// options in one place (declare), then does its work (run). One shared main
// adds the standard options, parses, and maps exceptions to exit codes, so
// `articula-fit ...` and `articula fit ...` behave identically.
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

namespace articula::cli {

/// Options every command has (../shared/GUIDE.md conventions).
struct CommonOptions {
  int verbosity = 1;          // 0 = --quiet, 1 = normal, 2 = --verbose
  long long seed = 42;        // --seed: all randomness is seeded from it
  int threads = 0;            // --threads: 0 = all hardware threads
  bool json = false;          // --json: machine-readable summary on stdout
  bool force = false;         // --force: overwrite existing outputs
  std::string config_file;    // --config: CLI11 TOML/INI file with option values

  /// Resolved thread count (>= 1).
  int threadCount() const;
};

class Command {
 public:
  virtual ~Command() = default;
  /// Subcommand name: `articula <name>` and executable `articula-<name>`.
  virtual std::string name() const = 0;
  /// One line for --help and the command list.
  virtual std::string description() const = 0;
  /// An example invocation shown in --help.
  virtual std::string example() const = 0;
  /// Declares the command's own options on `app` (bound to members).
  virtual void declare(CLI::App& app) = 0;
  /// Does the work; returns an exit code. Throws articula::Error subclasses.
  virtual int run(const CommonOptions& common) = 0;
};

/// Adds the standard options to `app`, bound to `common`.
void addCommonOptions(CLI::App& app, CommonOptions& common);

/// Main of a single-command executable (articula-fit, ...).
int runCommandMain(int argc, char** argv, std::unique_ptr<Command> command);

/// Main of the driver: dispatches `articula <command> ...`.
int runDriverMain(int argc, char** argv, std::vector<std::unique_ptr<Command>> commands);

/// Prints a JSON summary on stdout (for --json).
void printJson(const nlohmann::json& summary);

}  // namespace articula::cli
