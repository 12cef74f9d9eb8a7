#pragma once
// A recording played over and over: a long input from a short one, for runs that look at what
// thousands of frames do to memory and time per frame (tools/soak.sh, `inhandscan replay
// --loop`).

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "sensor/frame_source.h"

namespace ihs::sensor {

/// Plays `inner` `times` times (restarting it at each end of stream). Frames are numbered on
/// across the rounds, and their timestamps go on from the last frame's by one frame interval, so
/// that the consumer sees one long recording. A round that ends in an error ends the playback.
class LoopingSource : public FrameSource {
 public:
  /// `times` >= 1; throws std::invalid_argument otherwise.
  LoopingSource(std::unique_ptr<FrameSource> inner, int times);

  void Start() override;
  void Stop() override { inner_->Stop(); }
  SourceRead Next(std::chrono::milliseconds timeout) override;
  CameraIntrinsics Intrinsics() const override { return inner_->Intrinsics(); }
  std::string Description() const override;
  std::optional<std::int64_t> FrameCount() const override;
  bool IsLive() const override { return inner_->IsLive(); }
  std::int64_t MissedFrames() const override { return missed_before_ + inner_->MissedFrames(); }
  std::int64_t SkippedFrames() const override { return skipped_before_ + inner_->SkippedFrames(); }
  bool Recovered() const override { return inner_->Recovered(); }

 private:
  std::unique_ptr<FrameSource> inner_;
  const int times_;
  int round_ = 0;
  std::int64_t delivered_ = 0;
  // Added to a round's timestamps; whether the next frame starts a round; the last delivered.
  std::int64_t offset_us_ = 0;
  bool round_starts_ = true;
  std::optional<std::int64_t> last_us_;
  std::int64_t interval_us_ = 33'333;
  std::int64_t missed_before_ = 0;
  std::int64_t skipped_before_ = 0;
};

/// `source` played `times` times (unchanged when `times` is 1).
std::unique_ptr<FrameSource> Looped(std::unique_ptr<FrameSource> source, int times);

}  // namespace ihs::sensor
