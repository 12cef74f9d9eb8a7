#pragma once
// Opens whatever a user names as input: an .oni recording or a TUM RGB-D folder.

#include <memory>
#include <string>

#include "sensor/frame_source.h"
#include "sensor/tum_directory.h"

namespace ihs::sensor {

/// Which reader plays .oni files.
enum class OniBackend {
  kAuto,       ///< The project's own reader; OpenNI2's player only for a file our reader indexed
               ///< undamaged whose depth codec only OpenNI2 decodes.
  kOpenNi,     ///< OpenNI2's player only.
  kOwnReader,  ///< The project's own reader only (recovers truncated recordings).
};

/// Options for opening an input.
struct InputOptions {
  /// As fast as possible (headless replay) or at the recorded pace.
  Pacing pacing = Pacing::kAsFastAsPossible;
  /// Reader for .oni files.
  OniBackend oni_backend = OniBackend::kAuto;
  /// Options for TUM folders (depth scale, association tolerance, intrinsics).
  TumOptions tum;
  /// Times the recording is played over (looping_source.h; >= 1).
  int loops = 1;
};

/// A source for `input` (not yet started): an .oni file or a TUM folder. Throws ihs::InputError
/// naming the input when it is neither.
std::unique_ptr<FrameSource> OpenInput(const std::string& input, const InputOptions& options = {});

}  // namespace ihs::sensor
