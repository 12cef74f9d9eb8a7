#pragma once
// Synthetic RGB-D frames with known content for sensor tests.

#include <cstdint>
#include <vector>

#include "core/frame.h"

namespace ihs::test {

/// A frame whose depth and colour are deterministic functions of (u, v, index): depth varies
/// smoothly over 400–2000 mm with a few invalid (0) pixels; timestamps 33 333 µs apart.
Frame MakePatternFrame(std::int64_t index, int width = 640, int height = 480);

/// `count` pattern frames with indices 0..count-1.
std::vector<Frame> MakePatternFrames(int count, int width = 640, int height = 480);

}  // namespace ihs::test
