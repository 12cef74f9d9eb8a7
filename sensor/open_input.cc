#include "sensor/open_input.h"

#include <spdlog/spdlog.h>

#include <filesystem>
#include <utility>

#include "core/errors.h"
#include "sensor/oni_reader.h"
#include "sensor/openni_source.h"
#include "sensor/paced_source.h"

namespace ihs::sensor {
namespace {

// Plays an .oni file with OpenNI2's player and falls back to the project's own reader when
// OpenNI2 refuses the file (OpenNI2 rejects truncated recordings outright).
class AutoOniSource : public FrameSource {
 public:
  AutoOniSource(std::string path, Pacing pacing) : path_(std::move(path)), pacing_(pacing) {}

  void Start() override {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path_, ec)) {
      throw InputError(path_ + ": no such file");
    }
    OpenNiOptions options;
    options.uri = path_;
    auto openni = std::make_unique<OpenNiSource>(options);
    try {
      openni->Start();
    } catch (const InputError& openni_error) {
      spdlog::debug("{}; trying the built-in .oni reader", openni_error.what());
      openni.reset();
    }
    if (openni && openni->FrameCount()) {
      active_ = WithPacing(std::move(openni), pacing_);
      return;
    }
    if (openni) {
      // No frame count: an unfinished recording, whose complete frames our reader knows exactly.
      spdlog::debug("{}: OpenNI2 reports no frame count; using the built-in .oni reader", path_);
      openni->Stop();
    }
    active_ = WithPacing(std::make_unique<OniFileSource>(path_), pacing_);
    active_->Start();  // Throws its own InputError when nothing can be recovered.
  }
  void Stop() override {
    if (active_) active_->Stop();
  }
  SourceRead Next(std::chrono::milliseconds timeout) override { return active_->Next(timeout); }
  CameraIntrinsics Intrinsics() const override { return active_->Intrinsics(); }
  std::string Description() const override {
    return active_ ? active_->Description() : "recording " + path_;
  }
  std::optional<std::int64_t> FrameCount() const override {
    return active_ ? active_->FrameCount() : std::nullopt;
  }
  bool IsLive() const override { return pacing_ == Pacing::kRealTime; }
  std::int64_t SkippedFrames() const override { return active_ ? active_->SkippedFrames() : 0; }
  std::int64_t MissedFrames() const override { return active_ ? active_->MissedFrames() : 0; }
  bool Recovered() const override { return active_ && active_->Recovered(); }

 private:
  const std::string path_;
  const Pacing pacing_;
  std::unique_ptr<FrameSource> active_;
};

}  // namespace

std::unique_ptr<FrameSource> OpenInput(const std::string& input, const InputOptions& options) {
  std::error_code ec;
  if (std::filesystem::is_directory(input, ec)) {
    return WithPacing(std::make_unique<TumDirectorySource>(input, options.tum), options.pacing);
  }
  if (!OpenNiSource::IsOniPath(input)) {
    throw InputError(input + ": not an .oni file or a TUM RGB-D folder" +
                     (std::filesystem::exists(input, ec) ? "" : " (it does not exist)"));
  }
  switch (options.oni_backend) {
    case OniBackend::kOpenNi: {
      OpenNiOptions openni;
      openni.uri = input;
      return WithPacing(std::make_unique<OpenNiSource>(openni), options.pacing);
    }
    case OniBackend::kOwnReader:
      return WithPacing(std::make_unique<OniFileSource>(input), options.pacing);
    case OniBackend::kAuto:
      break;
  }
  return std::make_unique<AutoOniSource>(input, options.pacing);
}

}  // namespace ihs::sensor
