#pragma once
// Live capture to an .oni file with OpenNI2's own recorder (openni::Recorder): depth 16zT and
// lossless colour, as OpenNI2's tools write them.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>

#include "sensor/openni_source.h"

namespace ihs::sensor {

/// What a recording session captured.
struct RecordingSummary {
  /// Depth frames that reached the file.
  std::int64_t depth_frames = 0;
  /// Wall-clock length of the recording, seconds.
  double seconds = 0;
};

/// Records the device named by `device.uri` (empty: the first device) to `path` until
/// `max_duration` has passed, `max_depth_frames` depth frames have been recorded (0: no limit),
/// or `stop` becomes true. Throws ihs::DeviceError (with the USB diagnosis) when the device
/// cannot be opened, ihs::OutputError when the file cannot be created.
RecordingSummary RecordWithOpenNi(const OpenNiOptions& device, const std::filesystem::path& path,
                                  std::chrono::milliseconds max_duration,
                                  std::int64_t max_depth_frames, const std::atomic<bool>& stop);

}  // namespace ihs::sensor
