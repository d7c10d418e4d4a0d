#pragma once
// Factories of every command the driver offers; each lives in its own file.
#include <memory>

#include "articula/cli/command.hpp"

namespace articula::apps {

/// `articula surface`: a shape model of the hierarchy as a triangulated mesh.
std::unique_ptr<cli::Command> makeSurfaceCommand();

}  // namespace articula::apps
