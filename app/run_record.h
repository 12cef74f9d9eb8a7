#pragma once
// What a scan's output folder says about the run that made it: the version and commit, the
// input read, its camera and the options in effect — `options.conf`, a file that `--config`
// reads back to run the same scan again, `camera_intrinsic.json` (Open3D's intrinsics JSON, which
// `--intrinsics` reads too), and a "run" entry in stats.json naming them.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "app/scanner_options.h"
#include "core/camera_intrinsics.h"

namespace ihs::app {

/// One run's record.
struct RunRecord {
  /// The record of a run reading `input` with `options`.
  static RunRecord Of(std::string input, const ScannerOptions& options);

  /// The file, folder or device read.
  std::string input;
  /// The options in effect as a config file (OptionRegistry::Describe()).
  std::string options;

  /// The files' names in the output folder.
  static constexpr const char* kOptionsFile = "options.conf";
  static constexpr const char* kIntrinsicsFile = "camera_intrinsic.json";

  /// Writes `kOptionsFile` (headed by the version, commit and input) and `kIntrinsicsFile` into
  /// `folder`, atomically.
  void Write(const std::filesystem::path& folder, const CameraIntrinsics& intrinsics) const;
  /// stats.json's "run": version, commit, input, the camera's intrinsics, the options file.
  nlohmann::json Json(const CameraIntrinsics& intrinsics) const;
};

}  // namespace ihs::app
