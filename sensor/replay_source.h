#pragma once
// The replay-device shim: a FrameSource that serves frames from memory or from another source,
// with faults injected on purpose, so that pipeline tests can exercise every way a real sensor
// or recording misbehaves.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "sensor/frame_source.h"

namespace ihs::sensor {

/// A gate a test opens: a frame held at it is delivered only once it is open, so that a test can
/// act while the scan is known to wait (no sleeps that decide the order). Thread-safe.
class FrameGate {
 public:
  void Open();
  /// Waits until the gate is open or `deadline` passes; whether it is open.
  bool WaitUntil(std::chrono::steady_clock::time_point deadline);

 private:
  std::mutex mutex_;
  std::condition_variable opened_;
  bool open_ = false;
};

/// Faults to inject, keyed by the 0-based index of the frame in the underlying stream.
struct FaultPlan {
  /// Frames never delivered (as a sensor that drops frames).
  std::set<std::int64_t> drop;
  /// Frames delivered with the timestamps of the frame before them.
  std::set<std::int64_t> duplicate_timestamp;
  /// Frames delivered only after a stall of this many milliseconds.
  std::map<std::int64_t, int> stall_ms;
  /// Frames delivered only once their gate is open (Next() meanwhile times out as a stalled
  /// sensor does, so a stop is still noticed).
  std::map<std::int64_t, std::shared_ptr<FrameGate>> held;
  /// Reads that do not return until their gate opens, whatever the timeout (a device read
  /// stuck in its driver): the frame's read blocks.
  std::map<std::int64_t, std::shared_ptr<FrameGate>> blocked;
  /// After this many frames have been read from the underlying stream, report kDisconnected.
  std::optional<std::int64_t> disconnect_after;
  /// Frames delivered with a depth image of the wrong size (fails Frame::Check).
  std::set<std::int64_t> wrong_size;
  /// Frames delivered with no valid depth at all.
  std::set<std::int64_t> all_zero;
};

/// Serves frames from a list or another source, applying a FaultPlan.
class ReplaySource : public FrameSource {
 public:
  /// Serves `frames` (indices and timestamps as given) with `intrinsics`. `live` makes it
  /// report IsLive(), for tests of the live code path.
  ReplaySource(std::vector<Frame> frames, const CameraIntrinsics& intrinsics, FaultPlan faults = {},
               bool live = false);
  /// Serves the frames of `inner` (started and stopped with this source).
  ReplaySource(std::unique_ptr<FrameSource> inner, FaultPlan faults);
  ~ReplaySource() override;

  void Start() override;
  void Stop() override;
  SourceRead Next(std::chrono::milliseconds timeout) override;
  CameraIntrinsics Intrinsics() const override;
  std::string Description() const override;
  std::optional<std::int64_t> FrameCount() const override;
  bool IsLive() const override { return live_; }
  /// Frames dropped by the fault plan, plus those the underlying source missed.
  std::int64_t MissedFrames() const override {
    return missed_ + (inner_ ? inner_->MissedFrames() : 0);
  }

 private:
  // The next frame of the underlying stream, before faults.
  SourceRead ReadUnderlying(std::chrono::milliseconds timeout);

  std::vector<Frame> frames_;
  CameraIntrinsics intrinsics_;
  std::unique_ptr<FrameSource> inner_;
  const FaultPlan faults_;
  const bool live_;
  bool started_ = false;
  std::int64_t next_index_ = 0;  // Index of the next underlying frame.
  std::int64_t missed_ = 0;      // Frames dropped by the fault plan.
  std::optional<Frame> previous_;
  // A frame held back by a stall or a gate, and when it may be delivered.
  std::shared_ptr<const Frame> stalled_;
  std::chrono::steady_clock::time_point stalled_until_;
  std::shared_ptr<FrameGate> stalled_gate_;
};

}  // namespace ihs::sensor
