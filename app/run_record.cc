#include "app/run_record.h"

#include "app/build_info.h"
#include "core/atomic_file.h"
#include "sensor/tum_directory.h"

namespace ihs::app {

RunRecord RunRecord::Of(std::string input, const ScannerOptions& options) {
  ScannerOptions described = options;  // The registry points into what it describes.
  return {std::move(input), RegisterScannerOptions(&described).Describe()};
}

void RunRecord::Write(const std::filesystem::path& folder,
                      const CameraIntrinsics& intrinsics) const {
  const std::string header = std::string("# The options in effect (inhandscan ") + BuildVersion() +
                             ", commit " + BuildCommit() + ") for " + input +
                             "; run the same scan again with --config " + kOptionsFile + "\n";
  WriteFileAtomically(folder / kOptionsFile, header + options);
  WriteFileAtomically(folder / kIntrinsicsFile, sensor::Open3dIntrinsicsJson(intrinsics));
}

nlohmann::json RunRecord::Json(const CameraIntrinsics& intrinsics) const {
  return {{"version", BuildVersion()},
          {"commit", BuildCommit()},
          {"input", input},
          {"intrinsics",
           {{"fx", intrinsics.fx},
            {"fy", intrinsics.fy},
            {"cx", intrinsics.cx},
            {"cy", intrinsics.cy},
            {"width", intrinsics.width},
            {"height", intrinsics.height}}},
          {"options_file", kOptionsFile},
          {"intrinsics_file", kIntrinsicsFile}};
}

}  // namespace ihs::app
