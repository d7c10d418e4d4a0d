#pragma once
// The project's exit codes and the exceptions that map to them. Every
// executable shares one main (lib/cli) that catches these and exits with the
// code below, printing the message: what was expected, what was found, where.
#include <stdexcept>
#include <string>

namespace articula {

enum class ExitCode : int {
  Success = 0,
  ProcessingFailed = 1,  // e.g. no femoral head found, optimiser failed
  UsageError = 2,        // bad command line or option values
  InvalidInput = 3,      // missing, unreadable or malformed input
};

class Error : public std::runtime_error {
 public:
  Error(ExitCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ExitCode code() const { return code_; }

 private:
  ExitCode code_;
};

/// Processing failed on valid input (exit code 1).
struct ProcessingError : Error {
  explicit ProcessingError(const std::string& m) : Error(ExitCode::ProcessingFailed, m) {}
};
/// The command line or an option value is wrong (exit code 2).
struct UsageError : Error {
  explicit UsageError(const std::string& m) : Error(ExitCode::UsageError, m) {}
};
/// An input file or value is missing, unreadable or malformed (exit code 3).
struct InputError : Error {
  explicit InputError(const std::string& m) : Error(ExitCode::InvalidInput, m) {}
};
/// A model parameter is out of its valid range; names the parameter (exit code 3).
struct InvalidParameter : InputError {
  InvalidParameter(const std::string& parameter, const std::string& expected, double found);
  std::string parameter;
};

}  // namespace articula
