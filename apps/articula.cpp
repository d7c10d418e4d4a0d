// The driver: `articula <command> ...` for every registered command. The
// stage programs (articula-segment, ...) are links to this program, and the
// name it was started by picks the stage: one executable to link instead of
// seven, each of which held the whole library.
#include <string>

#include "articula/cli/command.hpp"

int main(int argc, char** argv) {
  const std::string called = argc > 0 ? argv[0] : "articula";
  const std::string name = called.substr(called.find_last_of('/') + 1);
  const std::string prefix = "articula-";
  if (name.compare(0, prefix.size(), prefix) == 0 && articula::cli::hasCommand(name.substr(prefix.size())))
    return articula::cli::runCommandMain(argc, argv, articula::cli::createCommand(name.substr(prefix.size())));
  return articula::cli::runDriverMain(argc, argv, articula::cli::createAllCommands());
}
