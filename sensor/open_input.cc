#include "sensor/open_input.h"

#include <spdlog/spdlog.h>

#include <filesystem>
#include <utility>

#include "core/errors.h"
#include "sensor/looping_source.h"
#include "sensor/oni_reader.h"
#include "sensor/openni_source.h"
#include "sensor/paced_source.h"

namespace ihs::sensor {
namespace {

// Plays an .oni file with the project's own reader. OpenNI2's player gets a file only when our
// reader has indexed it end to end (every record's header and size checked, nothing damaged)
// and it holds a depth codec only OpenNI2 decodes: OpenNI2's file driver trusts the sizes and
// names in the file, and one changed byte crashes it (a heap overflow) in our process.
class AutoOniSource : public FrameSource {
 public:
  AutoOniSource(std::string path, Pacing pacing) : path_(std::move(path)), pacing_(pacing) {}

  void Start() override {
    auto own = std::make_unique<OniFileSource>(path_);
    own->Start();  // Throws its own InputError when nothing can be recovered.
    if (own->DecodesDepthCodec()) {
      active_ = WithPacing(std::move(own), pacing_);
      active_->Start();  // Our reader again (indexing is quick), under the pacing's own Start.
      return;
    }
    if (!own->index().complete) {
      throw InputError(
          path_ + ": damaged recording (" + own->index().damage +
          ") in a depth codec only OpenNI2 decodes; OpenNI2 is not given damaged files");
    }
    own->Stop();
    spdlog::info("{}: a depth codec the built-in reader lacks; playing it with OpenNI2", path_);
    OpenNiOptions options;
    options.uri = path_;
    active_ = WithPacing(std::make_unique<OpenNiSource>(options), pacing_);
    active_->Start();
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

std::unique_ptr<FrameSource> OpenOnce(const std::string& input, const InputOptions& options) {
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

}  // namespace

std::unique_ptr<FrameSource> OpenInput(const std::string& input, const InputOptions& options) {
  return Looped(OpenOnce(input, options), options.loops);
}

}  // namespace ihs::sensor
