#include "sensor/intrinsics_override.h"

#include <string>

#include "core/errors.h"

namespace ihs::sensor {

IntrinsicsOverride::IntrinsicsOverride(std::unique_ptr<FrameSource> inner,
                                       const CameraIntrinsics& intrinsics)
    : inner_(std::move(inner)), intrinsics_(intrinsics) {
  intrinsics_.Check();
}

void IntrinsicsOverride::Start() {
  inner_->Start();
  const CameraIntrinsics own = inner_->Intrinsics();
  if (own.width != intrinsics_.width || own.height != intrinsics_.height) {
    throw InputError("the given intrinsics are for " + std::to_string(intrinsics_.width) + "x" +
                     std::to_string(intrinsics_.height) + " images, " + inner_->Description() +
                     "'s are " + std::to_string(own.width) + "x" + std::to_string(own.height));
  }
}

}  // namespace ihs::sensor
