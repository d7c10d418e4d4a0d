#include "articula/cli/command.hpp"

#include <charconv>
#include <iostream>
#include <limits>
#include <map>
#include <new>
#include <thread>

#include "articula/core/error.hpp"
#include "articula/core/excerpt.hpp"
#include "articula/core/log.hpp"
#include "articula/core/parallel.hpp"
#include "articula/core/provenance.hpp"
#include "articula/core/version.hpp"
#include "huge_pages.hpp"

namespace articula::cli {

int CommonOptions::threadCount() const { return resolveThreads(threads); }

namespace {

// CLI11 2.1 reads a 64-bit integer with strtoll and keeps its clamped value
// (and takes 0x.. and a leading 0 as hexadecimal and octal): check the text.
CLI::Validator integerIn(long long lo, long long hi) {
  const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        long long value = 0;
        const char* end = text.data() + text.size();
        const auto [next, error] = std::from_chars(text.data(), end, value);
        if (error == std::errc() && next == end && value >= lo && value <= hi) {
          text = std::to_string(value);  // "010" is ten, not CLI11's octal eight
          return "";
        }
        return "expected a whole number in " + range + ", found '" + excerpt(text, 40) + "'";
      },
      range);
}

}  // namespace

void addCommonOptions(CLI::App& app, CommonOptions& common) {
  app.set_version_flag("--version", versionString());
  app.set_config("--config", "", "Read option values from a TOML/INI file (CLI11 format)");
  auto* quiet = app.add_flag_callback("-q,--quiet", [&common] { common.verbosity = 0; }, "Print errors only");
  app.add_flag_callback("-v,--verbose", [&common] { common.verbosity = 2; }, "Print debug messages")
      ->excludes(quiet);
  app.add_option("--seed", common.seed, "Seed of every random choice (same seed, same output)")
      ->transform(integerIn(0, std::numeric_limits<long long>::max()))
      ->capture_default_str();
  app.add_option("--threads", common.threads, "Worker threads (0 = all cores)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  app.add_flag("--json", common.json, "Print a machine-readable summary on stdout");
  app.add_flag("--force", common.force, "Overwrite existing outputs");
}

namespace {
std::map<std::string, CommandFactory>& registry() {
  static std::map<std::string, CommandFactory> commands;
  return commands;
}
}  // namespace

bool registerCommand(const std::string& name, CommandFactory factory) {
  registry()[name] = factory;
  return true;
}

std::unique_ptr<Command> createCommand(const std::string& name) {
  auto it = registry().find(name);
  if (it == registry().end()) throw UsageError("unknown command '" + name + "'");
  return it->second();
}

bool hasCommand(const std::string& name) { return registry().count(name) > 0; }

std::vector<std::unique_ptr<Command>> createAllCommands() {
  std::vector<std::unique_ptr<Command>> all;
  for (const auto& [name, factory] : registry()) all.push_back(factory());
  return all;
}

namespace {

// Maps every exception to the documented exit codes (0/1/2/3).
template <class Body>
int guarded(Body&& body) {
  try {
    return body();
  } catch (const Error& e) {
    log::error(e.what());
    return static_cast<int>(e.code());
  } catch (const std::bad_alloc&) {
    log::error("out of memory");
    return static_cast<int>(ExitCode::ProcessingFailed);
  } catch (const std::exception& e) {
    log::error(std::string("unexpected failure: ") + e.what());
    return static_cast<int>(ExitCode::ProcessingFailed);
  }
}

void applyCommon(const CommonOptions& common) {
  log::setLevel(static_cast<log::Level>(common.verbosity));
}

// CLI11 reports usage errors itself; normalise its exit codes to ours.
int parseFailure(CLI::App& app, const CLI::ParseError& e) {
  int rc = app.exit(e);
  return rc == 0 ? 0 : static_cast<int>(ExitCode::UsageError);
}

void describe(CLI::App& app, const Command& command) {
  app.description(command.description());
  app.footer("Example:\n  " + command.example() +
             "\n\nExit codes: 0 success, 1 processing failed, 2 usage error, 3 invalid input.");
}

}  // namespace

namespace {
int runSingle(int argc, char** argv, const std::string& program, std::unique_ptr<Command> command,
              RunMemory* memory = nullptr) {
  CLI::App app;
  app.name(program);
  describe(app, *command);
  CommonOptions common;
  common.memory = memory;
  addCommonOptions(app, common);
  command->declare(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return parseFailure(app, e);
  }
  return guarded([&] {
    applyCommon(common);
    return command->run(common);
  });
}
}  // namespace

int runCommandMain(int argc, char** argv, std::unique_ptr<Command> command) {
  if (command->holdsVolumes()) restartWithHugePages(argv);
  setCommandLine(argc, argv);
  const std::string program = "articula-" + command->name();
  return runSingle(argc, argv, program, std::move(command));
}

int runDriverMain(int argc, char** argv, std::vector<std::unique_ptr<Command>> commands) {
  setCommandLine(argc, argv);
  // `articula <command> ...` parses exactly as `articula-<command> ...` does
  // (CLI11 reads --config files on the root app only, so each command gets its own).
  if (argc >= 2) {
    for (auto& command : commands)
      if (command->name() == argv[1]) {
        if (command->holdsVolumes()) restartWithHugePages(argv);
        return runSingle(argc - 1, argv + 1, std::string("articula ") + argv[1], std::move(command));
      }
    // A first word that is no option and no command: say so, whatever follows
    // (`articula nosuch --help` must not print the top-level help with exit 0).
    if (argv[1][0] != '-') {
      std::cerr << "articula: error: unknown command '" << excerpt(argv[1]) << "' (run 'articula --help' for the list)\n";
      return static_cast<int>(ExitCode::UsageError);
    }
  }
  CLI::App app{"articula: shape analysis of spheroidal joints from CT, and exact contact detection "
               "between smooth convex surfaces. Coordinates are LPS millimetres."};
  app.name("articula");
  app.require_subcommand(1);
  app.set_version_flag("--version", versionString());
  app.footer("Run 'articula <command> --help' for a command's options.\n"
             "Exit codes: 0 success, 1 processing failed, 2 usage error, 3 invalid input.");
  for (const auto& command : commands) app.add_subcommand(command->name(), command->description());
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return parseFailure(app, e);
  }
  return static_cast<int>(ExitCode::UsageError);
}

int runCommandInProcess(const std::string& name, const std::vector<std::string>& args, RunMemory* memory) {
  std::vector<std::string> full = {"articula " + name};
  full.insert(full.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : full) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string outer = commandLine();
  std::vector<const char*> shown = {"articula", name.c_str()};
  for (const auto& a : args) shown.push_back(a.c_str());
  setCommandLine(static_cast<int>(shown.size()), shown.data());
  const std::string outer_invoker = invokingCommand();
  setInvokingCommand(outer_invoker.empty() ? outer : outer_invoker);
  const int rc = runSingle(static_cast<int>(full.size()), argv.data(), full[0], createCommand(name), memory);
  setInvokingCommand(outer_invoker);
  setCommandLineString(outer);
  return rc;
}

void refuseToOverwrite(const std::vector<std::string>& existing, const std::string& advice) {
  if (existing.empty()) return;
  std::string list;
  for (const auto& file : existing) list += (list.empty() ? "" : ", ") + file;
  throw UsageError("refusing to overwrite " + list + advice);
}

void refuseExistingOutputs(const std::vector<std::filesystem::path>& files, bool force) {
  if (force) return;
  std::vector<std::string> existing;
  for (const auto& file : files)
    if (std::filesystem::exists(file)) existing.push_back(file.string());
  refuseToOverwrite(existing, " (use --force)");
}

std::string argumentProblem(const std::string& name, const std::vector<std::string>& args) {
  auto command = createCommand(name);
  CLI::App app;
  app.name("articula " + name);
  CommonOptions common;
  addCommonOptions(app, common);
  command->declare(app);
  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 takes them last first
  try {
    app.parse(reversed);
  } catch (const CLI::ParseError& e) {
    return e.get_exit_code() == 0 ? "asks for help or the version and would run nothing" : e.what();
  }
  return command->argumentsProblem(common);
}

void printJson(const nlohmann::json& summary) { std::cout << summary.dump(2) << std::endl; }

}  // namespace articula::cli
