#pragma once
// Bounded single-producer / single-consumer queue between two pipeline threads, built on
// moodycamel's lock-free BlockingReaderWriterCircularBuffer.
//
// Thread contract: exactly one producer thread calls TryPush, Push and Close; exactly one consumer
// thread calls Pop, PopLatest and Abandon. Shutdown never polls:
//  - the producer's Close() ends the stream: the consumer still gets every queued item, then
//    kClosed;
//  - the consumer's Abandon() refuses further items: a producer blocked in Push returns false at
//    once, and so does every later push.

#include <readerwriterqueue/readerwritercircularbuffer.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>

#include "core/check.h"

namespace ihs {

/// What a pop returned.
enum class PopStatus {
  kItem,     ///< An item was stored in the output argument.
  kTimeout,  ///< Nothing arrived within the timeout; the queue is still open.
  kClosed,   ///< The queue is closed and drained (or abandoned): nothing will ever arrive.
};

/// Bounded SPSC queue of `T` (movable). See the file comment for the thread contract.
template <typename T>
class SpscQueue {
 public:
  /// A queue holding at most `capacity` (≥ 1) items.
  explicit SpscQueue(std::size_t capacity) : capacity_(capacity), buffer_(CheckedSlots(capacity)) {}

  SpscQueue(const SpscQueue&) = delete;
  SpscQueue& operator=(const SpscQueue&) = delete;

  /// Producer: enqueues without blocking. Returns false, dropping the item, when the queue is
  /// full or closed; the caller counts the drop.
  bool TryPush(T item) {
    if (closed_.load(std::memory_order_acquire)) return false;
    return buffer_.try_enqueue(Slot(std::move(item)));
  }

  /// Producer: enqueues, blocking while the queue is full. Returns false, dropping the item, when
  /// the queue is closed or the consumer abandons it.
  bool Push(T item) {
    if (closed_.load(std::memory_order_acquire)) return false;
    buffer_.wait_enqueue(Slot(std::move(item)));
    return !abandoned_.load(std::memory_order_acquire);
  }

  /// Producer: no more items. The consumer drains what is queued, then pops return kClosed.
  void Close() {
    if (closed_.exchange(true, std::memory_order_acq_rel)) return;
    // Wakes a consumer blocked on an empty queue. If the queue is full this fails, which is
    // harmless: the consumer is not blocked and will see closed_ once it has drained the items.
    buffer_.try_enqueue(Slot());
  }

  /// Consumer: waits for an item without limit. Returns kItem or kClosed.
  PopStatus Pop(T& out) { return PopImpl(out, -1); }

  /// Consumer: waits at most `timeout` for an item.
  PopStatus Pop(T& out, std::chrono::microseconds timeout) {
    return PopImpl(out, std::max<std::int64_t>(0, timeout.count()));
  }

  /// Consumer: convenience form of Pop(out) — an item, or nullopt once closed and drained.
  std::optional<T> Pop() {
    T item;
    if (Pop(item) == PopStatus::kItem) return std::optional<T>(std::move(item));
    return std::nullopt;
  }

  /// Consumer: waits at most `timeout` for an item, then skips to the newest one queued.
  /// `*skipped` (if given) is set to the number of older items discarded.
  PopStatus PopLatest(T& out, std::chrono::microseconds timeout, std::size_t* skipped = nullptr) {
    if (skipped) *skipped = 0;
    const PopStatus status = Pop(out, timeout);
    if (status != PopStatus::kItem) return status;
    Slot newer;
    while (!drained_ && buffer_.try_dequeue(newer)) {
      if (!newer) {  // End-of-stream marker: `out` is the last item.
        drained_ = true;
        break;
      }
      out = std::move(*newer);
      if (skipped) ++*skipped;
    }
    return PopStatus::kItem;
  }

  /// Consumer: stops consuming. Queued items are discarded, a blocked producer is released, and
  /// every later push and pop fails.
  void Abandon() {
    abandoned_.store(true, std::memory_order_release);
    closed_.store(true, std::memory_order_release);
    while (true) {
      Slot discarded = std::nullopt;
      if (!buffer_.try_dequeue(discarded)) break;
    }
    drained_ = true;
  }

  /// Whether Close() or Abandon() has been called.
  bool closed() const { return closed_.load(std::memory_order_acquire); }
  /// Approximate number of queued items (exact when neither side is active).
  std::size_t SizeApprox() const { return buffer_.size_approx(); }
  /// Maximum number of items.
  std::size_t capacity() const { return capacity_; }

 private:
  // An item, or nullopt for the end-of-stream marker that Close() enqueues.
  using Slot = std::optional<T>;

  static std::size_t CheckedSlots(std::size_t capacity) {
    IHS_CHECK_ARG(capacity >= 1, "queue capacity must be at least 1");
    return capacity;
  }

  // timeout_us < 0 waits without limit.
  PopStatus PopImpl(T& out, std::int64_t timeout_us) {
    if (drained_) return PopStatus::kClosed;
    Slot slot;
    bool got = false;
    if (closed_.load(std::memory_order_acquire)) {
      got = buffer_.try_dequeue(slot);
    } else if (timeout_us < 0) {
      buffer_.wait_dequeue(slot);
      got = true;
    } else {
      got = buffer_.wait_dequeue_timed(slot, timeout_us);
    }
    if (!got) {
      if (!closed_.load(std::memory_order_acquire)) return PopStatus::kTimeout;
      // Closed while we waited: items pushed before Close() are visible now.
      if (!buffer_.try_dequeue(slot)) {
        drained_ = true;
        return PopStatus::kClosed;
      }
    }
    if (!slot) {
      drained_ = true;
      return PopStatus::kClosed;
    }
    out = std::move(*slot);
    return PopStatus::kItem;
  }

  const std::size_t capacity_;
  moodycamel::BlockingReaderWriterCircularBuffer<Slot> buffer_;
  std::atomic<bool> closed_{false};
  std::atomic<bool> abandoned_{false};
  bool drained_ = false;  // Consumer-side only: nothing more will be delivered.
};

}  // namespace ihs
