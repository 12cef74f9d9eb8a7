#pragma once
// The scanner's stages one after the other on one thread: every frame of an input read, put
// through the hand stage and handed on to the caller's step (the object stages, records and
// measures of inhandscan-scan, inhandscan-track and the benchmark). The application
// (pipeline.h) runs the same stage objects threaded; this is the one sequential loop.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "app/scan_record.h"
#include "app/scan_stages.h"
#include "core/camera_intrinsics.h"
#include "sensor/frame_source.h"

namespace ihs::app {

/// Options of a sequential run (defaults: every frame, the tracker starting on its own).
struct SequentialOptions {
  /// Frames read at most; 0: all the input has.
  std::int64_t max_frames = 0;
  /// When not empty, the hand's first pose is fitted to these joints (a generator's ground truth
  /// for the first frame, camera frame, mm) instead of the tracker searching for the hand.
  std::vector<Eigen::Vector3d> first_joints_mm;
};

/// One input played through the hand stage and a step per frame.
class SequentialScan {
 public:
  /// What happens to each frame after the hand stage: the packet holds the frame and the track.
  using Step = std::function<void(FramePacket& packet)>;

  /// Opens and starts `input` (a recording or a TUM folder, sensor/open_input.h).
  explicit SequentialScan(const std::string& input, SequentialOptions options = {});
  ~SequentialScan();

  /// The input's camera (for the stages).
  const CameraIntrinsics& intrinsics() const { return intrinsics_; }

  /// Reads the input to its end (or `max_frames`), each frame through `hand` and then `step`.
  /// Returns the frames read; throws InputError when the input has none.
  std::int64_t Run(HandStage& hand, const Step& step);

 private:
  const std::string input_;
  const SequentialOptions options_;
  std::unique_ptr<sensor::FrameSource> source_;
  CameraIntrinsics intrinsics_;
};

/// The object stage and the record of one scan for a packet the hand stage made.
void ScanObject(ObjectStage& stage, ScanRecord& record, FramePacket& packet);

}  // namespace ihs::app
