// The driver: `articula <command> ...` for every registered command.
#include "articula/cli/command.hpp"

int main(int argc, char** argv) {
  return articula::cli::runDriverMain(argc, argv, articula::cli::createAllCommands());
}
