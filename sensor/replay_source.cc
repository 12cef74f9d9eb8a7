#include "sensor/replay_source.h"

#include <algorithm>
#include <thread>
#include <utility>

#include "core/check.h"

namespace ihs::sensor {

void FrameGate::Open() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    open_ = true;
  }
  opened_.notify_all();
}

bool FrameGate::WaitUntil(std::chrono::steady_clock::time_point deadline) {
  std::unique_lock<std::mutex> lock(mutex_);
  return opened_.wait_until(lock, deadline, [this] { return open_; });
}

ReplaySource::ReplaySource(std::vector<Frame> frames, const CameraIntrinsics& intrinsics,
                           FaultPlan faults, bool live)
    : frames_(std::move(frames)), intrinsics_(intrinsics), faults_(std::move(faults)), live_(live) {
  intrinsics_.Check();
}

ReplaySource::ReplaySource(std::unique_ptr<FrameSource> inner, FaultPlan faults)
    : inner_(std::move(inner)), faults_(std::move(faults)), live_(inner_ && inner_->IsLive()) {
  IHS_CHECK_ARG(inner_ != nullptr, "replay shim needs a source to wrap");
}

ReplaySource::~ReplaySource() { Stop(); }

void ReplaySource::Start() {
  if (started_) return;
  if (inner_) inner_->Start();
  started_ = true;
  next_index_ = 0;
  previous_.reset();
  stalled_.reset();
  stalled_gate_.reset();
}

void ReplaySource::Stop() {
  if (!started_) return;
  if (inner_) inner_->Stop();
  started_ = false;
}

SourceRead ReplaySource::ReadUnderlying(std::chrono::milliseconds timeout) {
  if (inner_) return inner_->Next(timeout);
  const auto index = static_cast<size_t>(next_index_);
  if (index >= frames_.size()) return {SourceStatus::kEndOfStream, nullptr, "end of replay"};
  return {SourceStatus::kFrame, std::make_shared<const Frame>(frames_[index]), ""};
}

SourceRead ReplaySource::Next(std::chrono::milliseconds timeout) {
  IHS_CHECK(started_, "ReplaySource::Next called before Start");
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (true) {
    if (stalled_ && stalled_gate_) {
      if (!stalled_gate_->WaitUntil(deadline)) return {SourceStatus::kTimeout, {}, ""};
      stalled_gate_.reset();
      return {SourceStatus::kFrame, std::exchange(stalled_, nullptr), ""};
    }
    if (stalled_) {
      const auto now = std::chrono::steady_clock::now();
      const auto release = std::min(stalled_until_, deadline);
      if (release > now) std::this_thread::sleep_until(release);
      if (std::chrono::steady_clock::now() < stalled_until_)
        return {SourceStatus::kTimeout, {}, ""};
      return {SourceStatus::kFrame, std::exchange(stalled_, nullptr), ""};
    }
    if (faults_.disconnect_after && next_index_ >= *faults_.disconnect_after) {
      return {SourceStatus::kDisconnected, nullptr,
              "device disconnected (injected after " + std::to_string(*faults_.disconnect_after) +
                  " frames)"};
    }
    const auto remaining = std::max(std::chrono::milliseconds(0),
                                    std::chrono::duration_cast<std::chrono::milliseconds>(
                                        deadline - std::chrono::steady_clock::now()));
    SourceRead read = ReadUnderlying(remaining);
    if (read.status != SourceStatus::kFrame) return read;
    const std::int64_t index = next_index_++;
    if (auto gate = faults_.blocked.find(index); gate != faults_.blocked.end() && gate->second) {
      while (!gate->second->WaitUntil(std::chrono::steady_clock::now() + std::chrono::hours(1))) {
      }
    }

    Frame frame = *read.frame;
    const bool dropped = faults_.drop.count(index) > 0;
    if (faults_.duplicate_timestamp.count(index) && previous_) {
      frame.depth_timestamp_us = previous_->depth_timestamp_us;
      frame.color_timestamp_us = previous_->color_timestamp_us;
    }
    previous_ = frame;
    if (dropped) {
      ++missed_;
      continue;
    }
    if (faults_.all_zero.count(index)) std::fill(frame.depth_mm.begin(), frame.depth_mm.end(), 0);
    if (faults_.wrong_size.count(index)) frame.depth_mm.resize(frame.depth_mm.size() / 2);

    auto shared = std::make_shared<const Frame>(std::move(frame));
    if (auto gate = faults_.held.find(index); gate != faults_.held.end() && gate->second) {
      stalled_ = std::move(shared);
      stalled_gate_ = gate->second;
      continue;
    }
    if (auto stall = faults_.stall_ms.find(index); stall != faults_.stall_ms.end()) {
      stalled_ = std::move(shared);
      stalled_until_ = std::chrono::steady_clock::now() + std::chrono::milliseconds(stall->second);
      continue;
    }
    return {SourceStatus::kFrame, std::move(shared), ""};
  }
}

CameraIntrinsics ReplaySource::Intrinsics() const {
  return inner_ ? inner_->Intrinsics() : intrinsics_;
}

std::string ReplaySource::Description() const {
  return inner_ ? "replay shim over " + inner_->Description()
                : "replay shim (" + std::to_string(frames_.size()) + " frames in memory)";
}

std::optional<std::int64_t> ReplaySource::FrameCount() const {
  if (inner_) return inner_->FrameCount();
  return static_cast<std::int64_t>(frames_.size());
}

}  // namespace ihs::sensor
