#pragma once
// Every articula command has the same shape (as in MRtrix3): it declares its
// options in one place (declare), then does its work (run). One shared main
// adds the standard options, parses, and maps exceptions to exit codes, so
// `articula-fit ...` and `articula fit ...` behave identically.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "articula/core/run_memory.hpp"

namespace articula::cli {

/// Options every command has (../shared/GUIDE.md conventions).
struct CommonOptions {
  int verbosity = 1;          // 0 = --quiet, 1 = normal, 2 = --verbose
  long long seed = 42;        // --seed: all randomness is seeded from it
  int threads = 0;            // --threads: 0 = all hardware threads
  bool json = false;          // --json: machine-readable summary on stdout
  bool force = false;         // --force: overwrite existing outputs
  std::string config_file;    // --config: CLI11 TOML/INI file with option values
  /// The memory of the run that runs this command in its process (the CT
  /// read once for every stage); null when the command runs on its own.
  RunMemory* memory = nullptr;

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
  /// What is wrong with the parsed arguments beyond the parser's own checks
  /// (empty: nothing); argumentProblem() asks it, so that a caller can refuse
  /// a command line before any work.
  virtual std::string argumentsProblem(const CommonOptions&) const { return ""; }
  /// Whether the command holds CT-sized volumes in memory: its process then
  /// asks for transparent huge pages (lib/cli/src/huge_pages.hpp).
  virtual bool holdsVolumes() const { return false; }
};

/// Registry of commands (PDAL-style): each apps/<name>.cpp registers its
/// command once with ARTICULA_REGISTER_COMMAND(Class); the driver lists them.
using CommandFactory = std::unique_ptr<Command> (*)();
bool registerCommand(const std::string& name, CommandFactory factory);
/// A fresh instance of the named command; throws UsageError if unknown.
std::unique_ptr<Command> createCommand(const std::string& name);
/// Whether a command of that name is registered.
bool hasCommand(const std::string& name);
/// One fresh instance of every registered command, sorted by name.
std::vector<std::unique_ptr<Command>> createAllCommands();

#define ARTICULA_REGISTER_COMMAND(Class)                                                          \
  [[maybe_unused]] const bool articula_registered_##Class = ::articula::cli::registerCommand(     \
      Class().name(), []() -> std::unique_ptr<::articula::cli::Command> { return std::make_unique<Class>(); });

/// Adds the standard options to `app`, bound to `common`.
void addCommonOptions(CLI::App& app, CommonOptions& common);

/// Main of a single-command executable (articula-fit, ...).
int runCommandMain(int argc, char** argv, std::unique_ptr<Command> command);

/// Main of the driver: dispatches `articula <command> ...`.
int runDriverMain(int argc, char** argv, std::vector<std::unique_ptr<Command>> commands);

/// Runs the registered command `name` in this process with `args` (without
/// the program name), exactly as `articula <name> args...` would, returning
/// its exit code; errors are reported on stderr as usual. Provenance written
/// by the command records `articula <name> args...` as its command line.
/// `memory`: the caller's run memory, which the command may read from and add to.
int runCommandInProcess(const std::string& name, const std::vector<std::string>& args, RunMemory* memory = nullptr);

/// Parses `args` as `articula <name> args...` would, without running the
/// command: the parser's complaint (an unknown option, a value of the wrong
/// type or out of its declared range), or an empty string when they parse.
std::string argumentProblem(const std::string& name, const std::vector<std::string>& args);

/// Throws UsageError "refusing to overwrite A, B<advice>" when `existing`
/// (outputs found before any work) is not empty: every one named at once.
void refuseToOverwrite(const std::vector<std::string>& existing, const std::string& advice);

/// Unless `force`, refuses (as refuseToOverwrite, advising --force) those of
/// `files` that exist: a command's outputs and what it writes beside them
/// (a provenance .json, a table), named together before any work.
void refuseExistingOutputs(const std::vector<std::filesystem::path>& files, bool force);

/// Prints a JSON summary on stdout (for --json).
void printJson(const nlohmann::json& summary);

}  // namespace articula::cli
