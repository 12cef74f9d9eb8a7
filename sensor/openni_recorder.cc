#include "sensor/openni_recorder.h"

#include <OpenNI.h>

#include "core/errors.h"

namespace ihs::sensor {

RecordingSummary RecordWithOpenNi(const OpenNiOptions& device, const std::filesystem::path& path,
                                  std::chrono::milliseconds max_duration,
                                  std::int64_t max_depth_frames, const std::atomic<bool>& stop) {
  const std::filesystem::path folder = path.has_parent_path() ? path.parent_path() : ".";
  if (!std::filesystem::is_directory(folder)) {
    throw OutputError("cannot write " + path.string() + ": folder " + folder.string() +
                      " does not exist");
  }
  // The source opens and configures the device (mode, registration, sync) exactly as a scan does.
  OpenNiSource source(device);
  source.Start();
  openni::Recorder recorder;
  if (recorder.create(path.string().c_str()) != openni::STATUS_OK) {
    throw OutputError("cannot write " + path.string() + ": " + openni::OpenNI::getExtendedError());
  }
  for (openni::VideoStream* stream : source.OpenNiStreams()) {
    if (recorder.attach(*stream, /*allowLossyCompression=*/false) != openni::STATUS_OK) {
      throw DeviceError("cannot record " + source.Description() + ": " +
                        openni::OpenNI::getExtendedError());
    }
  }
  if (recorder.start() != openni::STATUS_OK) {
    throw OutputError("cannot record to " + path.string() + ": " +
                      openni::OpenNI::getExtendedError());
  }
  RecordingSummary summary;
  const auto start = std::chrono::steady_clock::now();
  while (!stop && std::chrono::steady_clock::now() - start < max_duration &&
         (max_depth_frames <= 0 || summary.depth_frames < max_depth_frames)) {
    // Reading keeps the streams (and, for a recording, the player) moving; the recorder
    // receives every frame from OpenNI2 itself.
    const SourceRead read = source.Next(std::chrono::milliseconds(500));
    if (read.status == SourceStatus::kFrame) ++summary.depth_frames;
    if (read.status == SourceStatus::kEndOfStream || read.status == SourceStatus::kDisconnected) {
      break;
    }
  }
  recorder.stop();
  recorder.destroy();
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace ihs::sensor
