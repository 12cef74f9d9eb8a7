#include "sensor/paced_source.h"

#include <thread>
#include <utility>

#include "core/check.h"

namespace ihs::sensor {

PacedSource::PacedSource(std::unique_ptr<FrameSource> inner, double speed)
    : inner_(std::move(inner)), speed_(speed) {
  IHS_CHECK_ARG(inner_ != nullptr, "PacedSource needs a source");
  IHS_CHECK_ARG(speed_ > 0, "playback speed must be positive, got " << speed_);
}

void PacedSource::Start() {
  inner_->Start();
  first_timestamp_us_.reset();
  pending_.reset();
}

SourceRead PacedSource::Next(std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  if (!pending_) {
    SourceRead read = inner_->Next(timeout);
    if (read.status != SourceStatus::kFrame) return read;
    pending_ = std::move(read.frame);
  }
  const std::int64_t timestamp = pending_->depth_timestamp_us;
  if (!first_timestamp_us_) {
    first_timestamp_us_ = timestamp;
    first_time_ = std::chrono::steady_clock::now();
  }
  const auto offset = std::chrono::microseconds(
      static_cast<std::int64_t>((timestamp - *first_timestamp_us_) / speed_));
  const auto due = first_time_ + offset;
  if (due > deadline) {
    std::this_thread::sleep_until(deadline);
    return {SourceStatus::kTimeout, nullptr, ""};
  }
  std::this_thread::sleep_until(due);
  return {SourceStatus::kFrame, std::exchange(pending_, nullptr), ""};
}

std::unique_ptr<FrameSource> WithPacing(std::unique_ptr<FrameSource> source, Pacing pacing) {
  if (pacing == Pacing::kRealTime) return std::make_unique<PacedSource>(std::move(source));
  return source;
}

}  // namespace ihs::sensor
