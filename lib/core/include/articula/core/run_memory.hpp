#pragma once
// What a run keeps in memory for the commands it runs in its own process
// (`articula run` chaining its stages): data too costly to make twice, such
// as the CT every imaging stage reads. The runner owns one and hands it to
// each command it runs (cli::CommonOptions::memory); a command run on its
// own has none and makes everything itself. No process-wide state: two runs
// in one process keep their own.
#include <functional>
#include <map>
#include <memory>
#include <string>

namespace articula {

class RunMemory {
 public:
  /// The value kept in `slot` if it was made for `key`, else `make()`'s,
  /// which then replaces the slot's (one value per slot: a run's stages read
  /// one CT, and a CT is hundreds of megabytes). A slot holds one type: the
  /// caller's T for that slot name. A failing make() leaves the slot empty.
  template <typename T>
  std::shared_ptr<const T> kept(const std::string& slot, const std::string& key, const std::function<T()>& make) {
    Entry& entry = slots_[slot];
    if (entry.value && entry.key == key) {
      ++hits_;
      return std::static_pointer_cast<const T>(entry.value);
    }
    entry = Entry{};
    auto value = std::make_shared<const T>(make());
    entry = Entry{key, value};
    return value;
  }

  /// The requests answered from memory.
  long long hits() const { return hits_; }

 private:
  struct Entry {
    std::string key;
    std::shared_ptr<const void> value;
  };
  std::map<std::string, Entry> slots_;
  long long hits_ = 0;
};

}  // namespace articula
