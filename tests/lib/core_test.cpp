// lib/core: atomic writes and the clean-up of temporaries a killed run leaves;
// the output folder's lock; the encoding check of text tables.
#include <atomic>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <csignal>
#include <fstream>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <sys/file.h>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include "articula/core/atomic_file.hpp"
#include "articula/core/csv.hpp"
#include "articula/core/error.hpp"
#include "articula/core/output_lock.hpp"
#include "articula/core/parallel.hpp"
#include "articula/testsupport/scratch_dir.hpp"

namespace articula {
namespace {
namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  return articula::testsupport::scratchDir(name);
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
  EXPECT_EQ(articula::testsupport::readText(dir / "out.json"), "whole\n");
  EXPECT_THROW(writeFileAtomically(dir / "out.json", "again\n", false), UsageError);
  EXPECT_EQ(articula::testsupport::readText(dir / "out.json"), "whole\n");
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


TEST(OutputLock, ASecondHolderIsRefusedNamingTheFirst) {
  const fs::path dir = scratch("lock") / "out";
  {
    OutputLock first(dir, "articula run");
    EXPECT_TRUE(fs::exists(dir / ".articula" / "lock"));
    EXPECT_NE(articula::testsupport::readText(dir / ".articula" / "lock").find("(pid " + std::to_string(::getpid()) + ")"), std::string::npos);
    // Another open file description, as another process has: refused.
    try {
      OutputLock second(dir, "articula run");
      FAIL() << "a second lock on the same folder was granted";
    } catch (const ProcessingError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("'" + dir.string() + "' is in use by articula run (pid "), std::string::npos) << message;
    }
  }
  OutputLock again(dir, "articula run");  // released with its holder
}

TEST(OutputLock, AKilledHolderLeavesNoLock) {
  const fs::path dir = scratch("lock-killed");
  const pid_t child = ::fork();
  if (child == 0) {
    OutputLock held(dir, "child");
    ::pause();
    ::_exit(0);
  }
  for (int i = 0; i < 500 && articula::testsupport::readText(dir / ".articula" / "lock").empty(); ++i) ::usleep(2000);
  EXPECT_THROW(OutputLock(dir, "parent"), ProcessingError);
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  EXPECT_NO_THROW(OutputLock(dir, "parent"));
}

TEST(OutputLock, RemovesOnlyWhatItMade) {
  const fs::path base = scratch("lock-made");
  {
    OutputLock lock(base / "new", "run");
    lock.removeIfUnused();
  }
  EXPECT_FALSE(fs::exists(base / "new"));
  fs::create_directories(base / "mine");
  {
    OutputLock lock(base / "mine", "run");
    lock.removeIfUnused();
  }
  EXPECT_TRUE(fs::is_directory(base / "mine"));
  EXPECT_TRUE(fs::is_empty(base / "mine"));
  {
    OutputLock lock(base / "written", "run");
    std::ofstream(base / "written" / ".articula" / "segment.json") << "{}\n";
    lock.removeIfUnused();
  }
  EXPECT_TRUE(fs::exists(base / "written" / ".articula" / "segment.json"));
  EXPECT_FALSE(fs::exists(base / "written" / ".articula" / "lock"));
}

TEST(CsvEncoding, Utf16AndNulBytesAreRefusedAUtf8MarkIsAccepted) {
  const fs::path dir = scratch("csv");
  const auto write = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(dir / name, std::ios::binary) << bytes;
    return dir / name;
  };
  const CsvTable table = readCsv(write("bom8.csv", "\xEF\xBB\xBFsubject,input\ns1,a.nii\n"));
  EXPECT_EQ(table.header.at(0), "subject");
  ASSERT_EQ(table.rows.size(), 1u);
  const std::string le("\xFF\xFEs\0,\0i\0\n\0", 10), be("\xFE\xFF\0s\0,\0i\0\n", 10);
  const std::string nul("subject,input\ns1,a\0b\n", 21);
  for (const auto& [name, bytes, line] : {std::tuple<std::string, std::string, int>{"le.csv", le, 1},
                                          {"be.csv", be, 1},
                                          {"nul.csv", nul, 2}}) {
    try {
      readCsv(write(name, bytes));
      ADD_FAILURE() << name << " was read";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), (dir / name).string() + ":" + std::to_string(line) +
                                           ": the file is UTF-16 (or has NUL bytes); save it as UTF-8 CSV "
                                           "(in Excel: Save As, 'CSV UTF-8')");
    }
  }
}

// Every index once, in ranges of at least min_chunk (but the last), on
// several threads where asked; a throw from any range reaches the caller
// after every thread has stopped.
TEST(ParallelFor, EachIndexOnceInRangesOfAtLeastTheMinimum) {
  for (const auto& [n, min_chunk, threads] :
       std::vector<std::tuple<std::ptrdiff_t, std::ptrdiff_t, int>>{{1, 1, 4}, {7, 1, 3}, {1000, 8, 2}, {1000, 64, 4},
                                                                   {100003, 2048, 3}, {50, 100, 4}}) {
    std::vector<std::atomic<int>> seen(static_cast<size_t>(n));
    std::mutex ranges_mutex;
    std::vector<std::pair<std::ptrdiff_t, std::ptrdiff_t>> ranges;
    parallelFor(n, min_chunk, threads, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
      for (std::ptrdiff_t i = begin; i < end; ++i) ++seen[static_cast<size_t>(i)];
      std::lock_guard<std::mutex> lock(ranges_mutex);
      ranges.emplace_back(begin, end);
    });
    for (std::ptrdiff_t i = 0; i < n; ++i) ASSERT_EQ(seen[static_cast<size_t>(i)], 1) << "n " << n << " index " << i;
    for (const auto& [begin, end] : ranges) {
      if (end != n) {
        EXPECT_GE(end - begin, min_chunk) << "n " << n;
      }
    }
    if (n / min_chunk >= threads) {
      EXPECT_GE(ranges.size(), static_cast<size_t>(threads)) << "n " << n;
    }
    if (n < 2 * min_chunk) {
      EXPECT_EQ(ranges.size(), 1u) << "n " << n;
    }
  }
  EXPECT_THROW(parallelFor(10000, 10, 4,
                                     [&](std::ptrdiff_t begin, std::ptrdiff_t) {
                                       if (begin == 0) throw std::runtime_error("range 0");
                                     }),
               std::runtime_error);
}

}  // namespace
}  // namespace articula
