#pragma once
// TUM RGB-D benchmark directories: `rgb/` and `depth/` images listed in `rgb.txt` and
// `depth.txt` ("timestamp path" lines, '#' comments), optionally `associations.txt`; depth is a
// 16-bit PNG scaled by `depth_scale_per_m` (5000 per metre, i.e. 0.2 mm per unit); colour is
// PNG or JPEG. We also read and write `intrinsics.txt` ("fx fy cx cy width height").

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "sensor/frame_source.h"

namespace ihs::sensor {

/// Options for reading and writing TUM directories.
struct TumOptions {
  /// Depth PNG units per metre (TUM: 5000, so 1 unit = 0.2 mm).
  double depth_scale_per_m = 5000.0;
  /// Largest depth/colour timestamp difference for a pair, seconds (TUM's associate.py: 0.02).
  double max_time_difference_s = 0.02;
  /// Intrinsics to use; when unset, `intrinsics.txt` in the folder, else the Carmine defaults.
  std::optional<CameraIntrinsics> intrinsics;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// One depth/colour pair of a TUM directory.
struct TumEntry {
  double depth_time_s = 0;
  std::string depth_path;  ///< Relative to the folder.
  double color_time_s = 0;
  std::string color_path;  ///< Relative to the folder.
};

/// Lists the associated depth/colour pairs of a TUM folder: associations.txt when present, else
/// rgb.txt and depth.txt matched one-to-one by nearest timestamp within the tolerance. Depth
/// images without a partner are left out (`*unmatched` counts them). Throws ihs::InputError
/// naming the folder and file when the lists are missing or malformed.
std::vector<TumEntry> ListTumDirectory(const std::filesystem::path& folder,
                                       const TumOptions& options, int* unmatched = nullptr);

/// Reads a TUM directory as a recording. Images that cannot be read are skipped with a warning
/// and counted (SkippedFrames()).
class TumDirectorySource : public FrameSource {
 public:
  TumDirectorySource(std::filesystem::path folder, TumOptions options = {});

  void Start() override;
  void Stop() override {}
  SourceRead Next(std::chrono::milliseconds timeout) override;
  CameraIntrinsics Intrinsics() const override { return intrinsics_; }
  std::string Description() const override { return "TUM directory " + folder_.string(); }
  std::optional<std::int64_t> FrameCount() const override;
  bool IsLive() const override { return false; }

  /// Listed frames whose images could not be decoded.
  std::int64_t SkippedFrames() const override { return skipped_; }
  /// Depth images without a colour partner (left out).
  int UnmatchedDepth() const { return unmatched_; }

 private:
  const std::filesystem::path folder_;
  const TumOptions options_;
  std::vector<TumEntry> entries_;
  CameraIntrinsics intrinsics_;
  size_t next_ = 0;
  std::int64_t delivered_ = 0;
  std::int64_t skipped_ = 0;
  int unmatched_ = 0;
};

/// Writes frames as a TUM directory (depth PNG, colour PNG, the three lists, intrinsics.txt).
/// Every file is written atomically; `Finish()` writes the lists.
class TumWriter {
 public:
  /// Creates `folder` (and rgb/, depth/) if needed. Throws ihs::OutputError if it cannot.
  TumWriter(std::filesystem::path folder, const CameraIntrinsics& intrinsics,
            TumOptions options = {});
  ~TumWriter();

  /// Adds one frame. Depth beyond what the PNG scale can hold becomes 0 (invalid).
  void Write(const Frame& frame);
  /// Writes rgb.txt, depth.txt, associations.txt and intrinsics.txt. Called by the destructor
  /// if not called before (errors are then only logged).
  void Finish();

 private:
  const std::filesystem::path folder_;
  const CameraIntrinsics intrinsics_;
  const TumOptions options_;
  std::vector<TumEntry> entries_;
  bool finished_ = false;
};

/// Reads "fx fy cx cy width height" (an intrinsics.txt); throws ihs::InputError if malformed.
CameraIntrinsics ReadIntrinsicsFile(const std::filesystem::path& path);
/// Parses "fx,fy,cx,cy[,width,height]" (a command-line value); throws std::invalid_argument.
CameraIntrinsics ParseIntrinsics(const std::string& text);

}  // namespace ihs::sensor
