#pragma once
// Reading whole streams from a FrameSource in tests.

#include <chrono>
#include <memory>
#include <vector>

#include "sensor/frame_source.h"

namespace ihs::test {

/// Starts `source` and reads frames until it ends (end of stream, disconnect, or 20 timeouts of
/// 2 s in a row); `*end` (if given) receives the status that ended it.
inline std::vector<std::shared_ptr<const Frame>> ReadAllFrames(
    sensor::FrameSource& source, sensor::SourceStatus* end = nullptr) {
  std::vector<std::shared_ptr<const Frame>> frames;
  source.Start();
  for (int timeouts = 0; timeouts < 20;) {
    sensor::SourceRead read = source.Next(std::chrono::seconds(2));
    if (read.status == sensor::SourceStatus::kTimeout) {
      ++timeouts;
      continue;
    }
    if (read.status != sensor::SourceStatus::kFrame) {
      if (end) *end = read.status;
      break;
    }
    timeouts = 0;
    frames.push_back(std::move(read.frame));
  }
  return frames;
}

}  // namespace ihs::test
