#include "articula/pipeline/batch.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cerrno>
#include <cstring>
#include <chrono>
#include <fstream>
#include <mutex>
#include <thread>

#include <nlohmann/json.hpp>

#include "articula/core/json_file.hpp"
#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/log.hpp"

extern char** environ;

namespace articula::pipeline {

namespace fs = std::filesystem;

fs::path subjectDir(const fs::path& study_dir, const std::string& id) { return study_dir / "subjects" / id; }

namespace {

// Runs argv with stdout and stderr appended to `log`; returns the exit code
// (128 + signal when killed by a signal).
int runProcess(const std::vector<std::string>& args, const fs::path& log) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw ProcessingError("cannot start '" + args[0] + "': " + std::strerror(rc));
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw ProcessingError("waiting for '" + args[0] + "' failed");
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

// The subject's own error message: the last "articula: error:" line of its log.
std::string errorMessage(const fs::path& log, int exit_code) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line))
    if (line.rfind("articula: error: ", 0) == 0) last = line.substr(17);
  if (!last.empty()) return last;
  if (exit_code > 128) return "killed by signal " + std::to_string(exit_code - 128);
  return "exited with code " + std::to_string(exit_code) + " (see " + log.string() + ")";
}

bool finishedEarlier(const fs::path& dir) {
  if (!fs::exists(dir / "results.json")) return false;
  const auto status = readJsonFileIfValid(dir / "status.json");
  return status && status->is_object() && status->value("status", "") == "ok";
}

}  // namespace

std::vector<std::string> runArguments(const Subject& s, const BatchOptions& options) {
  std::vector<std::string> args = {"-i",     s.input.string(), "-o",     subjectDir(options.study_dir, s.id).string(),
                                   "--joint", s.joint,         "--side", s.side,
                                   "--seed",  std::to_string(options.seed), "--threads", "1"};
  args.insert(args.end(), s.options.begin(), s.options.end());
  args.insert(args.end(), options.extra_args.begin(), options.extra_args.end());
  return args;
}

std::vector<std::string> subjectFilesNotOurs(const std::vector<Subject>& subjects, const fs::path& study_dir) {
  std::vector<std::string> others;
  for (const auto& s : subjects) {
    const fs::path dir = subjectDir(study_dir, s.id);
    const auto status = readJsonFileIfValid(dir / "status.json");
    const bool record = status && status->is_object() && status->value("subject", "") == s.id && status->contains("command");
    if (fs::exists(dir / "status.json") && !record) others.push_back((dir / "status.json").string());
    if (fs::exists(dir / "run.log") && !record && !fs::is_directory(dir / ".articula"))
      others.push_back((dir / "run.log").string());
  }
  return others;
}

BatchSummary runBatch(const std::vector<Subject>& subjects, const BatchOptions& options) {
  if (options.jobs < 1) throw UsageError("-j: expected at least 1 job, found " + std::to_string(options.jobs));
  const auto batch_start = std::chrono::steady_clock::now();
  BatchSummary summary;
  summary.outcomes.resize(subjects.size());
  std::atomic<size_t> next{0};
  std::mutex log_mutex;
  // Progress on stderr, a line per subject: done, failed, remaining, and the
  // time left from the subjects run so far (resumed ones took no time).
  int done = 0, failed = 0, timed = 0;
  double busy_seconds = 0;
  const int n_workers = std::min<int>(options.jobs, static_cast<int>(std::max<size_t>(subjects.size(), 1)));
  const auto progress = [&](const SubjectOutcome& out) {
    std::lock_guard<std::mutex> lock(log_mutex);
    ++done;
    failed += out.status != "ok";
    if (!out.resumed) busy_seconds += out.seconds, ++timed;
    if (options.quiet || out.resumed) return;
    const int remaining = static_cast<int>(subjects.size()) - done;
    std::string line = "subject " + out.id + ": " + out.status +
                       (out.status == "ok" ? "" : " (exit " + std::to_string(out.exit_code) + "): " + out.message) + " [" +
                       std::to_string(done) + " of " + std::to_string(subjects.size()) + " done, " +
                       std::to_string(failed) + " failed, " + std::to_string(remaining) + " remaining";
    if (remaining > 0 && timed > 0)
      line += ", about " + std::to_string(static_cast<long long>(std::ceil(busy_seconds / timed * remaining / n_workers))) +
              " s left";
    log::info(line + "]");
  };

  auto work = [&] {
    for (size_t i = next++; i < subjects.size(); i = next++) {
      const Subject& s = subjects[i];
      SubjectOutcome& out = summary.outcomes[i];
      out.id = s.id;
      const fs::path dir = subjectDir(options.study_dir, s.id);
      if (!options.rerun_finished && finishedEarlier(dir)) {
        out.status = "ok";
        out.resumed = true;
        progress(out);
        continue;
      }
      fs::create_directories(dir);
      std::vector<std::string> args = {options.executable.string(), "run"};
      for (auto& a : runArguments(s, options)) args.push_back(std::move(a));
      const auto start = std::chrono::steady_clock::now();
      try {
        out.exit_code = runProcess(args, dir / "run.log");
      } catch (const Error& e) {
        out.exit_code = static_cast<int>(e.code());
        out.message = e.what();
      }
      out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      out.status = out.exit_code == 0 ? "ok" : "failed";
      if (out.exit_code != 0 && out.message.empty()) out.message = errorMessage(dir / "run.log", out.exit_code);
      std::string command;
      for (const auto& a : args) command += (command.empty() ? "" : " ") + a;
      const nlohmann::json status = {{"subject", s.id},         {"status", out.status},
                                     {"exit_code", out.exit_code}, {"message", out.message},
                                     {"seconds", out.seconds},  {"command", command},
                                     {"input", s.input.string()}};
      writeFileAtomically(dir / "status.json", status.dump(2) + "\n");
      progress(out);
    }
  };
  std::vector<std::thread> workers;
  for (int w = 0; w < n_workers; ++w) workers.emplace_back(work);
  for (auto& t : workers) t.join();

  for (const auto& o : summary.outcomes) {
    if (o.status == "ok") ++summary.succeeded;
    else ++summary.failed;
    if (o.resumed) ++summary.resumed;
  }
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - batch_start).count();
  return summary;
}

BatchSummary gatherOutcomes(const std::vector<Subject>& subjects, const fs::path& study_dir) {
  BatchSummary summary;
  for (const auto& s : subjects) {
    SubjectOutcome out;
    out.id = s.id;
    out.resumed = true;
    const fs::path dir = subjectDir(study_dir, s.id);
    const nlohmann::json status = readJsonFileIfValid(dir / "status.json").value_or(nullptr);
    if (status.is_object()) {
      out.status = status.value("status", "failed");
      out.exit_code = status.value("exit_code", 1);
      out.message = status.value("message", "");
      out.seconds = status.value("seconds", 0.0);
    } else {
      const bool done = fs::exists(dir / "results.json");
      out.status = done ? "ok" : "failed";
      out.exit_code = done ? 0 : 1;
      if (!done) out.message = "no results in " + dir.string();
    }
    if (out.status == "ok" && !fs::exists(dir / "results.json")) {
      out.status = "failed";
      out.message = "status ok but no results.json in " + dir.string();
    }
    (out.status == "ok" ? summary.succeeded : summary.failed)++;
    summary.outcomes.push_back(out);
  }
  summary.resumed = static_cast<int>(subjects.size());
  return summary;
}

}  // namespace articula::pipeline
