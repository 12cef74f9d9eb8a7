#include "sensor/openni_source.h"

#include <OpenNI.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <deque>
#include <mutex>
#include <thread>

#include "core/check.h"
#include "core/errors.h"
#include "sensor/usb_devices.h"

namespace ihs::sensor {
namespace {

// OpenNI2 is a process-wide library: initialised once for all sources, shut down with the last.
class OpenNiRuntime {
 public:
  static void Acquire() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (users_ == 0 && openni::OpenNI::initialize() != openni::STATUS_OK) {
      throw DeviceError(std::string("cannot initialise OpenNI2: ") +
                        openni::OpenNI::getExtendedError());
    }
    ++users_;
  }
  static void Release() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (users_ > 0 && --users_ == 0) openni::OpenNI::shutdown();
  }

 private:
  static inline std::mutex mutex_;
  static inline int users_ = 0;
};

// Longest pause of OpenNI2's player before a recording counts as ended (its own pacing never
// sleeps more than 2 s between frames).
constexpr auto kRecordingSilence = std::chrono::seconds(5);

std::string ExtendedError() {
  const char* text = openni::OpenNI::getExtendedError();
  return text && *text ? text : "OpenNI2 gave no reason";
}

// Finds a supported mode with the requested size, rate and pixel format.
std::optional<openni::VideoMode> FindMode(const openni::SensorInfo& info, int width, int height,
                                          int fps, openni::PixelFormat format) {
  const auto& modes = info.getSupportedVideoModes();
  for (int i = 0; i < modes.getSize(); ++i) {
    const openni::VideoMode& mode = modes[i];
    if (mode.getResolutionX() == width && mode.getResolutionY() == height && mode.getFps() == fps &&
        mode.getPixelFormat() == format) {
      return mode;
    }
  }
  return std::nullopt;
}

}  // namespace

bool OpenNiSource::IsOniPath(const std::string& uri) {
  if (uri.size() < 4) return false;
  std::string extension = uri.substr(uri.size() - 4);
  std::transform(extension.begin(), extension.end(), extension.begin(), ::tolower);
  return extension == ".oni";
}

void OpenNiOptions::Check() const {
  IHS_CHECK_ARG(width > 0 && height > 0, "openni.width/height must be positive");
  IHS_CHECK_ARG(fps > 0, "openni.fps must be positive, got " << fps);
  IHS_CHECK_ARG(max_color_offset_us >= 0, "openni.max_color_offset_us must not be negative");
}

struct OpenNiSource::Impl : public openni::OpenNI::DeviceDisconnectedListener {
  openni::Device device;
  openni::VideoStream depth;
  openni::VideoStream color;
  bool has_color = false;
  bool is_file = false;
  bool runtime_acquired = false;
  bool listening = false;
  bool depth_started = false;
  std::string uri;
  std::string description;
  CameraIntrinsics intrinsics;
  int depth_frame_count = -1;  // Recordings only; -1 when the file does not say.
  // When the player last delivered anything: a recording whose frame count is unknown or wrong
  // just stops delivering at its end (or at damage), so a long silence ends it.
  std::chrono::steady_clock::time_point last_activity;
  std::int64_t depth_frames_read = 0;
  std::int64_t delivered = 0;
  std::int64_t without_color = 0;
  // The live device's number of the last depth frame read, and the gaps seen; whether a
  // recording has ended.
  bool ended = false;
  std::int64_t last_device_index = -1;
  std::int64_t missed = 0;
  std::atomic<bool> disconnected{false};
  // Colour frames seen and not yet used, oldest first (a few at most).
  std::deque<std::shared_ptr<const Frame>> colors;
  // A depth frame waiting for a colour frame that may still come.
  std::shared_ptr<Frame> held_depth;

  void onDeviceDisconnected(const openni::DeviceInfo* info) override {
    if (info && uri == info->getUri()) disconnected = true;
  }

  ~Impl() override { Close(); }

  void Close() {
    if (listening) {
      openni::OpenNI::removeDeviceDisconnectedListener(this);
      listening = false;
    }
    // OpenNI2's file player (at our speed, manual mode) delivers a frame after each one read.
    // Stopping a stream while the player thread delivers to it crashes; so does closing the
    // device before that thread first ran (it then loops until OpenNI2 cancels it). Both were
    // seen under load. A frame pending and unread means the thread runs and now waits for us:
    // wait for one (unless the whole recording was read), then stop, then close.
    if (is_file && depth_started &&
        !(depth_frame_count >= 0 && depth_frames_read >= depth_frame_count)) {
      openni::VideoStream* streams[] = {&depth};
      int ready = -1;
      if (openni::OpenNI::waitForAnyStream(streams, 1, &ready, 2000) == openni::STATUS_OK) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    }
    if (depth.isValid()) depth.stop();
    if (color.isValid()) color.stop();
    if (device.isValid()) device.close();
    if (depth.isValid()) depth.destroy();
    if (color.isValid()) color.destroy();
    if (runtime_acquired) {
      OpenNiRuntime::Release();
      runtime_acquired = false;
    }
  }
};

std::string DescribeOpenNiDevices() {
  try {
    OpenNiRuntime::Acquire();
  } catch (const DeviceError& error) {
    return std::string("OpenNI2: ") + error.what() + "\n";
  }
  openni::Array<openni::DeviceInfo> devices;
  openni::OpenNI::enumerateDevices(&devices);
  std::string text;
  if (devices.getSize() == 0) text = "OpenNI2: no device\n";
  for (int i = 0; i < devices.getSize(); ++i) {
    text += std::string("OpenNI2: ") + devices[i].getVendor() + " " + devices[i].getName() +
            " (URI " + devices[i].getUri() + ")\n";
  }
  OpenNiRuntime::Release();
  return text;
}

OpenNiSource::OpenNiSource(OpenNiOptions options) : options_(std::move(options)) {
  options_.Check();
}

OpenNiSource::~OpenNiSource() { Stop(); }

void OpenNiSource::Start() {
  if (impl_) return;
  auto impl = std::make_unique<Impl>();
  const bool file = IsOniPath(options_.uri);
  OpenNiRuntime::Acquire();
  impl->runtime_acquired = true;

  if (file) {
    std::FILE* probe = std::fopen(options_.uri.c_str(), "rb");
    if (!probe) throw InputError(options_.uri + ": cannot open: " + std::strerror(errno));
    std::fclose(probe);
  }
  const char* uri = options_.uri.empty() ? openni::ANY_DEVICE : options_.uri.c_str();
  if (impl->device.open(uri) != openni::STATUS_OK) {
    if (file) throw InputError(options_.uri + ": OpenNI2 cannot play it: " + ExtendedError());
    bool ready = false;
    const std::string usb = DescribeUsbScan(ScanPrimeSenseDevices(), &ready);
    throw DeviceError("cannot open the depth camera" +
                      (options_.uri.empty() ? std::string() : " '" + options_.uri + "'") + ": " +
                      ExtendedError() + "\n" + usb);
  }
  impl->is_file = impl->device.isFile();
  impl->uri = impl->device.getDeviceInfo().getUri();
  impl->description = impl->is_file
                          ? "recording " + options_.uri
                          : std::string(impl->device.getDeviceInfo().getVendor()) + " " +
                                impl->device.getDeviceInfo().getName() + " (" + impl->uri + ")";

  if (!impl->device.hasSensor(openni::SENSOR_DEPTH) ||
      impl->depth.create(impl->device, openni::SENSOR_DEPTH) != openni::STATUS_OK) {
    const std::string reason = "has no depth stream (" + ExtendedError() + ")";
    if (file) throw InputError(options_.uri + ": " + reason);
    throw DeviceError(impl->description + ": " + reason);
  }
  impl->has_color = impl->device.hasSensor(openni::SENSOR_COLOR) &&
                    impl->color.create(impl->device, openni::SENSOR_COLOR) == openni::STATUS_OK;

  if (impl->is_file) {
    openni::PlaybackControl* playback = impl->device.getPlaybackControl();
    // Speed −1 makes OpenNI2's player deliver the next frame only when we wait for one, so no
    // frame is ever skipped. Never its own pacing (1.0): its thread then delivers on its own
    // clock, and stopping the streams while it does crashed OpenNI2 under load (a replay
    // stopped by Ctrl-C, about one in 20). The recorded pace is PacedSource's (WithPacing).
    playback->setSpeed(-1.0f);
    playback->setRepeatEnabled(false);
    impl->depth_frame_count = playback->getNumberOfFrames(impl->depth);
  } else {
    const auto depth_mode = FindMode(impl->depth.getSensorInfo(), options_.width, options_.height,
                                     options_.fps, openni::PIXEL_FORMAT_DEPTH_1_MM);
    if (!depth_mode || impl->depth.setVideoMode(*depth_mode) != openni::STATUS_OK) {
      throw DeviceError(impl->description + ": does not offer depth " +
                        std::to_string(options_.width) + "x" + std::to_string(options_.height) +
                        " @ " + std::to_string(options_.fps) + " Hz in 1 mm units");
    }
    if (impl->has_color) {
      const auto color_mode = FindMode(impl->color.getSensorInfo(), options_.width, options_.height,
                                       options_.fps, openni::PIXEL_FORMAT_RGB888);
      if (!color_mode || impl->color.setVideoMode(*color_mode) != openni::STATUS_OK) {
        throw DeviceError(impl->description + ": does not offer RGB colour " +
                          std::to_string(options_.width) + "x" + std::to_string(options_.height) +
                          " @ " + std::to_string(options_.fps) + " Hz");
      }
    }
    if (impl->has_color && options_.register_depth_to_color) {
      if (impl->device.isImageRegistrationModeSupported(
              openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR)) {
        impl->device.setImageRegistrationMode(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR);
      } else {
        spdlog::warn("{}: no hardware depth-to-colour registration; colour will be offset",
                     impl->description);
      }
      impl->device.setDepthColorSyncEnabled(true);
    }
    impl->depth.setMirroringEnabled(options_.mirror);
    if (impl->has_color) impl->color.setMirroringEnabled(options_.mirror);
    openni::OpenNI::addDeviceDisconnectedListener(impl.get());
    impl->listening = true;
  }

  if (impl->depth.start() != openni::STATUS_OK) {
    throw DeviceError(impl->description + ": cannot start the depth stream: " + ExtendedError());
  }
  impl->depth_started = true;
  if (impl->has_color && impl->color.start() != openni::STATUS_OK) {
    spdlog::warn("{}: cannot start the colour stream ({}); continuing with depth only",
                 impl->description, ExtendedError());
    impl->color.destroy();
    impl->has_color = false;
  }

  // With registration the depth image is in the colour camera's geometry; recordings may lack
  // the colour stream's fields of view, so the depth stream's serve next, then the defaults.
  const openni::VideoMode mode = impl->depth.getVideoMode();
  const int width = mode.getResolutionX(), height = mode.getResolutionY();
  std::optional<CameraIntrinsics> intrinsics;
  for (const openni::VideoStream* stream : {&impl->color, &impl->depth}) {
    if (!stream->isValid()) continue;
    const float horizontal = stream->getHorizontalFieldOfView();
    const float vertical = stream->getVerticalFieldOfView();
    if (horizontal > 0.1f && horizontal < 3.0f && vertical > 0.1f && vertical < 3.0f) {
      intrinsics = CameraIntrinsics::FromFieldOfView(width, height, horizontal, vertical);
      break;
    }
  }
  if (!intrinsics) {
    spdlog::warn("{}: no field of view reported; using the Carmine 1.09 intrinsics",
                 impl->description);
    intrinsics = CameraIntrinsics::Carmine109().Scaled(width, height);
  }
  impl->intrinsics = *intrinsics;
  impl->last_activity = std::chrono::steady_clock::now();
  impl_ = std::move(impl);
}

void OpenNiSource::Stop() {
  if (impl_) impl_->Close();
  impl_.reset();
}

namespace {

std::shared_ptr<Frame> ToDepthFrame(const openni::VideoFrameRef& ref) {
  const int width = ref.getWidth(), height = ref.getHeight();
  auto frame = std::make_shared<Frame>(Frame::Blank(width, height, false));
  const auto* bytes = static_cast<const std::uint8_t*>(ref.getData());
  const int stride = ref.getStrideInBytes();
  const bool tenths = ref.getVideoMode().getPixelFormat() == openni::PIXEL_FORMAT_DEPTH_100_UM;
  for (int v = 0; v < height; ++v) {
    const auto* row = reinterpret_cast<const std::uint16_t*>(bytes + v * stride);
    std::uint16_t* out = frame->depth_mm.data() + v * width;
    if (tenths) {
      for (int u = 0; u < width; ++u) out[u] = static_cast<std::uint16_t>((row[u] + 5) / 10);
    } else {
      std::memcpy(out, row, width * sizeof(std::uint16_t));
    }
  }
  frame->depth_timestamp_us = static_cast<std::int64_t>(ref.getTimestamp());
  return frame;
}

std::shared_ptr<const Frame> ToColorFrame(const openni::VideoFrameRef& ref) {
  if (ref.getVideoMode().getPixelFormat() != openni::PIXEL_FORMAT_RGB888) return nullptr;
  const int width = ref.getWidth(), height = ref.getHeight();
  auto frame = std::make_shared<Frame>();
  frame->width = width;
  frame->height = height;
  frame->rgb.resize(static_cast<size_t>(width) * height * 3);
  const auto* bytes = static_cast<const std::uint8_t*>(ref.getData());
  for (int v = 0; v < height; ++v) {
    std::memcpy(frame->rgb.data() + static_cast<size_t>(v) * width * 3,
                bytes + static_cast<size_t>(v) * ref.getStrideInBytes(), width * 3);
  }
  frame->color_timestamp_us = static_cast<std::int64_t>(ref.getTimestamp());
  return frame;
}

}  // namespace

SourceRead OpenNiSource::Next(std::chrono::milliseconds timeout) {
  IHS_CHECK(impl_ != nullptr, "OpenNiSource::Next called before Start");
  Impl& s = *impl_;
  const auto deadline = std::chrono::steady_clock::now() + timeout;

  // Pairs the held depth frame with the nearest colour frame within the tolerance.
  auto deliver = [&]() -> SourceRead {
    std::shared_ptr<Frame> frame = std::move(s.held_depth);
    std::shared_ptr<const Frame> best;
    std::int64_t best_offset = options_.max_color_offset_us + 1;
    for (const auto& color : s.colors) {
      const std::int64_t offset = std::abs(color->color_timestamp_us - frame->depth_timestamp_us);
      if (offset < best_offset && color->width == frame->width && color->height == frame->height) {
        best = color;
        best_offset = offset;
      }
    }
    if (best) {
      frame->rgb = best->rgb;
      frame->color_timestamp_us = best->color_timestamp_us;
      // Colour frames older than the one used can never serve a later depth frame.
      while (!s.colors.empty() && s.colors.front() != best) s.colors.pop_front();
    } else {
      ++s.without_color;
    }
    frame->index = s.delivered++;
    return {SourceStatus::kFrame, std::move(frame), ""};
  };

  while (true) {
    if (s.disconnected) {
      if (s.held_depth) return deliver();
      return {SourceStatus::kDisconnected, nullptr, s.description + " was disconnected"};
    }
    // The held depth frame goes out once a colour frame at or after its time has arrived.
    if (s.held_depth &&
        (!s.has_color || (!s.colors.empty() && s.colors.back()->color_timestamp_us >=
                                                   s.held_depth->depth_timestamp_us))) {
      return deliver();
    }
    const bool depth_exhausted =
        s.is_file && s.depth_frame_count >= 0 && s.depth_frames_read >= s.depth_frame_count;
    openni::VideoStream* streams[2] = {&s.depth, &s.color};
    const int stream_count = s.has_color ? 2 : 1;
    const auto now = std::chrono::steady_clock::now();
    const int wait_ms = static_cast<int>(std::max<std::int64_t>(
        0, std::chrono::duration_cast<std::chrono::milliseconds>(deadline - now).count()));
    int ready = -1;
    // At the end of a recording OpenNI2 simply stops delivering: a short wait tells.
    const openni::Status status = openni::OpenNI::waitForAnyStream(
        streams, stream_count, &ready, depth_exhausted ? std::min(wait_ms, 100) : wait_ms);
    if (status != openni::STATUS_OK) {
      if (depth_exhausted) {
        if (s.held_depth) return deliver();
        s.ended = true;
        return {SourceStatus::kEndOfStream, nullptr, "end of " + options_.uri};
      }
      if (status == openni::STATUS_TIME_OUT) {
        if (s.is_file && std::chrono::steady_clock::now() - s.last_activity > kRecordingSilence) {
          if (s.held_depth) return deliver();
          s.ended = true;
          return {SourceStatus::kEndOfStream, nullptr,
                  "end of " + options_.uri + ": the player stopped delivering frames after " +
                      std::to_string(s.depth_frames_read) + " (damaged or unfinished recording?)"};
        }
        if (std::chrono::steady_clock::now() < deadline) continue;
        return {SourceStatus::kTimeout, nullptr, ""};
      }
      if (!s.is_file) {
        return {SourceStatus::kDisconnected, nullptr,
                s.description + " stopped delivering frames: " + ExtendedError()};
      }
      s.ended = true;
      return {SourceStatus::kEndOfStream, nullptr,
              "end of " + options_.uri + ": " + ExtendedError()};
    }
    openni::VideoFrameRef ref;
    s.last_activity = std::chrono::steady_clock::now();
    if (streams[ready]->readFrame(&ref) != openni::STATUS_OK || !ref.isValid()) {
      if (!s.is_file) {
        return {SourceStatus::kDisconnected, nullptr,
                s.description + " failed to deliver a frame: " + ExtendedError()};
      }
      continue;
    }
    if (ready == 1) {
      if (auto color = ToColorFrame(ref)) {
        s.colors.push_back(std::move(color));
        if (s.colors.size() > 8) s.colors.pop_front();
      }
      continue;
    }
    ++s.depth_frames_read;
    const std::int64_t device_index = ref.getFrameIndex();
    if (!s.is_file && s.last_device_index >= 0 && device_index > s.last_device_index + 1) {
      s.missed += device_index - s.last_device_index - 1;
    }
    s.last_device_index = device_index;
    std::shared_ptr<Frame> depth = ToDepthFrame(ref);
    if (s.held_depth) {
      // A newer depth frame came first: the held one gets the best colour seen so far.
      SourceRead read = deliver();
      s.held_depth = std::move(depth);
      return read;
    }
    s.held_depth = std::move(depth);
  }
}

CameraIntrinsics OpenNiSource::Intrinsics() const {
  IHS_CHECK(impl_ != nullptr, "OpenNiSource::Intrinsics called before Start");
  return impl_->intrinsics;
}

std::string OpenNiSource::Description() const {
  return impl_ ? impl_->description
               : (options_.uri.empty() ? std::string("first OpenNI2 device") : options_.uri);
}

std::optional<std::int64_t> OpenNiSource::FrameCount() const {
  if (!impl_ || !impl_->is_file || impl_->depth_frame_count < 0) return std::nullopt;
  return impl_->depth_frame_count;
}

bool OpenNiSource::IsLive() const { return impl_ ? !impl_->is_file : !IsOniPath(options_.uri); }

std::vector<openni::VideoStream*> OpenNiSource::OpenNiStreams() {
  IHS_CHECK(impl_ != nullptr, "OpenNiSource::OpenNiStreams called before Start");
  std::vector<openni::VideoStream*> streams = {&impl_->depth};
  if (impl_->has_color) streams.push_back(&impl_->color);
  return streams;
}

std::int64_t OpenNiSource::MissedFrames() const {
  if (!impl_) return 0;
  // A recording played at its pace: what the player had but we never read, once it has ended
  // (its frame numbers are not consecutive per stream, so gaps in them do not tell).
  if (impl_->is_file) {
    return impl_->ended && impl_->depth_frame_count >= 0
               ? std::max<std::int64_t>(0, impl_->depth_frame_count - impl_->depth_frames_read)
               : 0;
  }
  return impl_->missed;
}

std::int64_t OpenNiSource::FramesWithoutColor() const { return impl_ ? impl_->without_color : 0; }

}  // namespace ihs::sensor
