#pragma once
// A one-slot mailbox: writers replace the value, readers take the newest. Used for previews,
// where only the latest snapshot matters and a slow reader must never hold up the writer.

#include <cstdint>
#include <mutex>
#include <optional>
#include <utility>

namespace ihs {

/// Holds at most one `T`; Put overwrites, Take empties. Safe from any number of threads.
template <typename T>
class LatestValue {
 public:
  /// Stores `value`, replacing (and discarding) one not yet taken.
  void Put(T value) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (value_) ++overwritten_;
    value_ = std::move(value);
    ++version_;
  }

  /// Removes and returns the value, or nullopt when empty.
  std::optional<T> Take() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::optional<T> taken = std::move(value_);
    value_.reset();
    return taken;
  }

  /// A copy of the value without removing it, or nullopt when empty.
  std::optional<T> Peek() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return value_;
  }

  /// Number of Put calls so far.
  std::uint64_t version() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return version_;
  }

  /// Number of values replaced before anyone took them.
  std::uint64_t overwritten() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return overwritten_;
  }

 private:
  mutable std::mutex mutex_;
  std::optional<T> value_;
  std::uint64_t version_ = 0;
  std::uint64_t overwritten_ = 0;
};

}  // namespace ihs
