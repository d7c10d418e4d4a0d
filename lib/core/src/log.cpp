#include "articula/core/log.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <mutex>

namespace articula::log {

namespace {
std::atomic<Level> g_level{Level::Normal};
std::mutex g_mutex;  // batch subjects log from several threads
// The message with control characters shown as \xNN (line breaks and tabs
// kept): a message quoting a file's bytes must not drive the terminal.
std::string printable(const std::string& message) {
  std::string out;
  out.reserve(message.size());
  for (const char ch : message) {
    const auto c = static_cast<unsigned char>(ch);
    if ((c < 0x20 && c != '\n' && c != '\t') || c == 0x7f) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", c);
      out += escaped;
    } else {
      out += ch;
    }
  }
  return out;
}

void print(const char* tag, const std::string& message) {
  const std::string shown = printable(message);
  std::lock_guard<std::mutex> lock(g_mutex);
  std::cerr << "articula: " << tag << shown << '\n';
}
}  // namespace

void setLevel(Level l) { g_level = l; }
Level level() { return g_level; }
void error(const std::string& m) { print("error: ", m); }
void warn(const std::string& m) {
  if (g_level >= Level::Normal) print("warning: ", m);
}
void info(const std::string& m) {
  if (g_level >= Level::Normal) print("", m);
}
void debug(const std::string& m) {
  if (g_level >= Level::Verbose) print("debug: ", m);
}

void progress(const std::string& what, double fraction) {
  if (g_level < Level::Normal) return;
  const int percent = static_cast<int>(std::floor(100 * std::clamp(fraction, 0.0, 1.0)));
  static const bool terminal = isatty(STDERR_FILENO) != 0;
  static std::string current;
  static int shown = -1;  // percent on a terminal, tenths otherwise
  std::lock_guard<std::mutex> lock(g_mutex);
  if (what != current) current = what, shown = -1;
  if (terminal) {
    if (percent == shown) return;
    shown = percent;
    const int filled = percent / 5;
    std::cerr << "\rarticula: " << what << " [" << std::string(static_cast<size_t>(filled), '#')
              << std::string(static_cast<size_t>(20 - filled), ' ') << "] " << percent << " %" << (percent == 100 ? "\n" : "")
              << std::flush;
  } else if (percent / 10 > shown) {
    shown = percent / 10;
    std::cerr << "articula: " << what << ": " << 10 * shown << " %\n";
  }
}

}  // namespace articula::log
