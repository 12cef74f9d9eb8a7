// This build has no Open3D (libopen3d-dev was not found): the benchmark leaves the Open3D
// baselines (frame to frame and frame to model) out, and constructing one says why.
#include <stdexcept>

#include "tools/bench/open3d_baseline.h"

namespace ihs::bench {

bool Open3dAvailable() { return false; }

struct Open3dBaseline::State {};

Open3dBaseline::Open3dBaseline(const CameraIntrinsics&, Open3dBaselineOptions) {
  throw std::runtime_error("this build has no Open3D (install libopen3d-dev and rebuild)");
}
Open3dBaseline::~Open3dBaseline() = default;
void Open3dBaseline::Process(const Frame&, const std::vector<std::uint8_t>&) {}
Open3dBaselineResult Open3dBaseline::Finish() { return {}; }

}  // namespace ihs::bench
