// lib/core: atomic writes and the clean-up of temporaries a killed run leaves.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"

namespace articula {
namespace {
namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("articula-core-test-" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(AtomicFile, AnUncommittedWriteLeavesNothing) {
  const fs::path dir = scratch("uncommitted");
  {
    AtomicFile file(dir / "out.json");
    file.stream() << "half";
    EXPECT_TRUE(fs::exists(temporaryPathFor(dir / "out.json")));
    EXPECT_FALSE(fs::exists(dir / "out.json"));
  }  // destroyed without commit, as when an exception unwinds
  EXPECT_TRUE(fs::is_empty(dir));
  writeFileAtomically(dir / "out.json", "whole\n");
  EXPECT_EQ(slurp(dir / "out.json"), "whole\n");
  EXPECT_THROW(writeFileAtomically(dir / "out.json", "again\n", false), UsageError);
  EXPECT_EQ(slurp(dir / "out.json"), "whole\n");
}

TEST(AtomicFile, TemporariesKeepTheExtensionAndAreHidden) {
  const fs::path t = temporaryPathFor(fs::path("a/b/label.nii.gz"));
  EXPECT_EQ(t.parent_path(), fs::path("a/b"));
  EXPECT_EQ(t.filename().string(), ".articula-tmp-" + std::to_string(::getpid()) + "-label.nii.gz");
}

TEST(AtomicFile, OnlyTheTemporariesOfDeadWritersAreRemoved) {
  const fs::path dir = scratch("stale");
  // A process that has exited: its pid names no running process.
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  const std::string dead = std::to_string(child), alive = std::to_string(::getpid());
  fs::create_directories(dir / "errors");
  fs::create_directories(dir / "notes");
  const std::string ours = ".articula-tmp-";
  // A user's files that look like temporaries, but not articula's: kept,
  // as is everything in a subfolder not asked for; a pid beyond any
  // integer type is no pid (it once threw from std::stoll).
  const std::vector<fs::path> kept = {dir / (ours + alive + "-points.ply"),  // still being written
                                      dir / (".tmp-" + dead + "-draft.txt"), dir / ".tmp-4000000-draft.txt",
                                      dir / (ours + "99999999999999999999-x"), dir / (ours + "notapid-x"),
                                      dir / (ours + dead), dir / "notes" / (ours + dead + "-n.txt"), dir / "results.json"};
  for (const fs::path& p : kept) std::ofstream(p) << "x";
  for (const fs::path& p : {dir / (ours + dead + "-bone.vtp"), dir / "errors" / (ours + dead + "-summary.csv")})
    std::ofstream(p) << "x";
  EXPECT_EQ(removeStaleTemporaries(dir), 1);
  EXPECT_EQ(removeStaleTemporaries(dir / "errors"), 1);
  EXPECT_FALSE(fs::exists(dir / (ours + dead + "-bone.vtp")));
  EXPECT_FALSE(fs::exists(dir / "errors" / (ours + dead + "-summary.csv")));
  for (const fs::path& p : kept) EXPECT_TRUE(fs::exists(p)) << p;
  EXPECT_EQ(removeStaleTemporaries(dir / "nowhere"), 0);
}

}  // namespace
}  // namespace articula
