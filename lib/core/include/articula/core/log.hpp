#pragma once
// Progress and diagnostics go to stderr; results go to files (and, with
// --json, to stdout). One process-wide verbosity set from -q / -v.
#include <string>

namespace articula::log {

enum class Level { Quiet = 0, Normal = 1, Verbose = 2 };

void setLevel(Level level);
Level level();

/// Always printed (errors): "articula: error: <message>".
void error(const std::string& message);
/// Printed unless --quiet.
void warn(const std::string& message);
void info(const std::string& message);
/// Printed only with --verbose.
void debug(const std::string& message);

/// Progress of work that takes more than a second (`fraction` of it done,
/// 0 to 1), unless --quiet: a bar redrawn in place when stderr is a
/// terminal, else a plain line at every tenth ("articula: <what>: 40 %").
void progress(const std::string& what, double fraction);

}  // namespace articula::log
