#include "sensor/looping_source.h"

#include <utility>

#include "core/check.h"

namespace ihs::sensor {

LoopingSource::LoopingSource(std::unique_ptr<FrameSource> inner, int times)
    : inner_(std::move(inner)), times_(times) {
  IHS_CHECK_ARG(inner_ != nullptr, "LoopingSource needs a source");
  IHS_CHECK_ARG(times_ >= 1, "a recording is played at least once, got " << times_);
}

void LoopingSource::Start() {
  inner_->Start();
  round_ = 0;
  delivered_ = 0;
  offset_us_ = 0;
  round_starts_ = true;
  last_us_.reset();
  missed_before_ = skipped_before_ = 0;
}

std::string LoopingSource::Description() const {
  return inner_->Description() +
         (times_ > 1 ? ", played " + std::to_string(times_) + " times" : "");
}

std::optional<std::int64_t> LoopingSource::FrameCount() const {
  const auto count = inner_->FrameCount();
  if (!count) return std::nullopt;
  return *count * times_;
}

SourceRead LoopingSource::Next(std::chrono::milliseconds timeout) {
  SourceRead read = inner_->Next(timeout);
  if (read.status == SourceStatus::kEndOfStream && round_ + 1 < times_ && delivered_ > 0) {
    // The next round starts one frame interval after this one's last frame.
    missed_before_ += inner_->MissedFrames();
    skipped_before_ += inner_->SkippedFrames();
    inner_->Stop();
    inner_->Start();
    ++round_;
    round_starts_ = true;
    read = inner_->Next(timeout);
  }
  if (read.status != SourceStatus::kFrame) return read;
  const std::int64_t recorded = read.frame->depth_timestamp_us;
  if (round_starts_) {
    if (last_us_) offset_us_ = *last_us_ + interval_us_ - recorded;
    round_starts_ = false;
  } else if (last_us_ && recorded + offset_us_ > *last_us_) {
    interval_us_ = recorded + offset_us_ - *last_us_;  // The recording's own frame interval.
  }
  const std::int64_t timestamp = recorded + offset_us_;
  last_us_ = timestamp;
  if (round_ > 0 || read.frame->index != delivered_) {
    auto frame = std::make_shared<Frame>(*read.frame);
    frame->index = delivered_;
    frame->depth_timestamp_us = timestamp;
    if (frame->color_timestamp_us != 0) frame->color_timestamp_us += offset_us_;
    read.frame = std::move(frame);
  }
  ++delivered_;
  return read;
}

std::unique_ptr<FrameSource> Looped(std::unique_ptr<FrameSource> source, int times) {
  if (times == 1) return source;
  return std::make_unique<LoopingSource>(std::move(source), times);
}

}  // namespace ihs::sensor
