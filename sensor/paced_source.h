#pragma once
// Real-time pacing for recordings: delivers each frame no earlier than its recorded timestamp
// says, relative to the first frame, as a live sensor would.

#include <chrono>
#include <memory>
#include <optional>

#include "sensor/frame_source.h"

namespace ihs::sensor {

/// Wraps a recording so that frames arrive at the pace of their depth timestamps (scaled by
/// 1/`speed`). A frame whose timestamp goes backwards or repeats is delivered at once.
class PacedSource : public FrameSource {
 public:
  explicit PacedSource(std::unique_ptr<FrameSource> inner, double speed = 1.0);

  void Start() override;
  void Stop() override { inner_->Stop(); }
  SourceRead Next(std::chrono::milliseconds timeout) override;
  CameraIntrinsics Intrinsics() const override { return inner_->Intrinsics(); }
  std::string Description() const override { return inner_->Description(); }
  std::optional<std::int64_t> FrameCount() const override { return inner_->FrameCount(); }
  /// Paced recordings behave like live devices: a slow consumer must drop frames.
  bool IsLive() const override { return true; }
  std::int64_t MissedFrames() const override { return inner_->MissedFrames(); }
  std::int64_t SkippedFrames() const override { return inner_->SkippedFrames(); }

 private:
  std::unique_ptr<FrameSource> inner_;
  const double speed_;
  std::optional<std::int64_t> first_timestamp_us_;
  std::chrono::steady_clock::time_point first_time_;
  std::shared_ptr<const Frame> pending_;  // Read but not yet due.
};

/// Wraps `source` in a PacedSource when `pacing` is kRealTime; returns it unchanged otherwise.
std::unique_ptr<FrameSource> WithPacing(std::unique_ptr<FrameSource> source, Pacing pacing);

}  // namespace ihs::sensor
