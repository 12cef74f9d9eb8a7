#pragma once
// A camera's intrinsics given by the user (`--intrinsics FILE`) in place of what a recording or
// a device reports: the frames pass unchanged, only Intrinsics() differs.

#include <memory>

#include "sensor/frame_source.h"

namespace ihs::sensor {

/// `inner` with `intrinsics`. Start() throws ihs::InputError when their image size differs
/// from the frames' (the source's own intrinsics).
class IntrinsicsOverride : public FrameSource {
 public:
  IntrinsicsOverride(std::unique_ptr<FrameSource> inner, const CameraIntrinsics& intrinsics);

  void Start() override;
  void Stop() override { inner_->Stop(); }
  SourceRead Next(std::chrono::milliseconds timeout) override { return inner_->Next(timeout); }
  CameraIntrinsics Intrinsics() const override { return intrinsics_; }
  std::string Description() const override { return inner_->Description(); }
  std::optional<std::int64_t> FrameCount() const override { return inner_->FrameCount(); }
  bool IsLive() const override { return inner_->IsLive(); }
  std::int64_t SkippedFrames() const override { return inner_->SkippedFrames(); }
  std::int64_t MissedFrames() const override { return inner_->MissedFrames(); }
  bool Recovered() const override { return inner_->Recovered(); }

 private:
  std::unique_ptr<FrameSource> inner_;
  const CameraIntrinsics intrinsics_;
};

}  // namespace ihs::sensor
