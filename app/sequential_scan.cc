#include "app/sequential_scan.h"

#include <chrono>

#include "core/errors.h"
#include "sensor/open_input.h"
#include "tracker/hand_fit.h"

namespace ihs::app {

SequentialScan::SequentialScan(const std::string& input, SequentialOptions options)
    : input_(input), options_(std::move(options)), source_(sensor::OpenInput(input)) {
  source_->Start();
  intrinsics_ = source_->Intrinsics();
}

SequentialScan::~SequentialScan() = default;

std::int64_t SequentialScan::Run(HandStage& hand, const Step& step) {
  std::int64_t frames = 0;
  while (options_.max_frames <= 0 || frames < options_.max_frames) {
    const sensor::SourceRead read = source_->Next(std::chrono::seconds(5));
    if (read.status == sensor::SourceStatus::kTimeout) continue;
    if (read.status != sensor::SourceStatus::kFrame) break;
    if (frames == 0 && !options_.first_joints_mm.empty()) {
      hand.Initialise(tracker::FitPoseToJoints(hand.model(), options_.first_joints_mm));
    }
    FramePacket packet;
    packet.frame = read.frame;
    hand.Process(packet);
    step(packet);
    ++frames;
  }
  if (frames == 0) throw InputError(input_ + ": no frames");
  return frames;
}

void ScanObject(ObjectStage& stage, ScanRecord& record, FramePacket& packet) {
  stage.Process(packet);
  record.Add(packet);
}

}  // namespace ihs::app
