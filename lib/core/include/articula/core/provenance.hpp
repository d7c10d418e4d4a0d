#pragma once
// Provenance that every result file carries: version, commit, command line,
// parameters, seed and the SHA-256 of every input.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace articula {

/// Lower-case hex SHA-256 of a file's bytes; throws InputError if unreadable.
std::string sha256File(const std::filesystem::path& path);
/// Lower-case hex SHA-256 of a string.
std::string sha256String(const std::string& bytes);

/// The command line of this process, as one shell-like string.
std::string commandLine();
void setCommandLine(int argc, const char* const* argv);
void setCommandLineString(const std::string& command);
/// The command a user typed when this one runs inside it (`articula run`
/// running its stages in its process; "" otherwise): provenance records it
/// as "invoked_by" beside the stage's own command line.
std::string invokingCommand();
void setInvokingCommand(const std::string& command);

struct Provenance {
  nlohmann::json parameters = nlohmann::json::object();
  std::vector<std::filesystem::path> inputs;  // hashed into "inputs"
  long long seed = -1;                        // -1: no randomness involved
  int threads = 1;                            // worker threads the command used
};

/// {"articula_version", "git_commit", "command", ["invoked_by",] "seed", "parameters",
///  "inputs": [{"path","sha256"}], "threads", ["glibc_tunables",] "coordinate_system": "LPS",
///  "units": "mm"}
nlohmann::json provenanceJson(const Provenance& p);

}  // namespace articula
