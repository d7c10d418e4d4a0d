// The driver: `articula <command> ...`, one subcommand per command file.
#include <vector>

#include "commands.hpp"

int main(int argc, char** argv) {
  std::vector<std::unique_ptr<articula::cli::Command>> commands;
  commands.push_back(articula::apps::makeSurfaceCommand());
  return articula::cli::runDriverMain(argc, argv, std::move(commands));
}
