#pragma once
#include <string>

namespace articula {
/// Semantic version of this build, e.g. "0.1.0".
std::string version();
/// Short git commit the build was configured from ("unknown" outside a checkout).
std::string gitCommit();
/// "articula 0.1.0 (commit abcdef012345)".
std::string versionString();
}  // namespace articula
