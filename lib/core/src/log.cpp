#include "articula/core/log.hpp"

#include <atomic>
#include <iostream>
#include <mutex>

namespace articula::log {

namespace {
std::atomic<Level> g_level{Level::Normal};
std::mutex g_mutex;  // batch subjects log from several threads
void print(const char* tag, const std::string& message) {
  std::lock_guard<std::mutex> lock(g_mutex);
  std::cerr << "articula: " << tag << message << '\n';
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

}  // namespace articula::log
