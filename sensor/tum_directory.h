#pragma once
// TUM RGB-D benchmark directories: `rgb/` and `depth/` images listed in `rgb.txt` and
// `depth.txt` ("timestamp path" lines, '#' comments), optionally `associations.txt`; depth is a
// 16-bit PNG scaled by `depth_scale_per_m` (5000 per metre, i.e. 0.2 mm per unit); colour is
// PNG or JPEG. We also read and write `intrinsics.txt` ("fx fy cx cy width height").
//
// Also read: the folders Open3D's tools write (its RealSense and Azure Kinect recorders, its
// reconstruction system's datasets): `depth/` and `color/` (or `image/`, `rgb/`) images paired
// by sorted file name, 30 frames per second, depth at `open3d_depth_scale_per_m` (1000: mm),
// intrinsics in `camera_intrinsic.json` (Open3D's PinholeCameraIntrinsic JSON).

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
  /// The same for a folder in Open3D's layout (its recorders write millimetres: 1000).
  double open3d_depth_scale_per_m = 1000.0;
  /// Largest depth/colour timestamp difference for a pair, seconds (TUM's associate.py: 0.02).
  double max_time_difference_s = 0.02;
  /// Intrinsics to use; when unset, `intrinsics.txt` or `camera_intrinsic.json` in the folder,
  /// else the Carmine 1.09's (with a warning).
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
  double depth_scale_per_m_ = 0;  // The folder's layout's (TUM's or Open3D's).
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

/// Whether `folder` is in Open3D's layout: no TUM lists, a `depth/` folder and a `color/`,
/// `image/` or `rgb/` one.
bool IsOpen3dFolder(const std::filesystem::path& folder);

/// Reads an intrinsics file: "fx fy cx cy width height" (an intrinsics.txt), or Open3D's
/// PinholeCameraIntrinsic JSON ({"width", "height", "intrinsic_matrix": the 3x3 matrix in
/// column-major order}); throws ihs::InputError naming the file if malformed.
CameraIntrinsics ReadIntrinsicsFile(const std::filesystem::path& path);
/// `intrinsics` as Open3D's PinholeCameraIntrinsic JSON (what ReadIntrinsicsFile reads back).
std::string Open3dIntrinsicsJson(const CameraIntrinsics& intrinsics);
/// Parses "fx,fy,cx,cy[,width,height]" (a command-line value); throws std::invalid_argument.
CameraIntrinsics ParseIntrinsics(const std::string& text);

}  // namespace ihs::sensor
