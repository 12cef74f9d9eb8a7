#include "app/scan_export.h"

#include "core/errors.h"
#include "core/mesh_io.h"
#include "core/stopwatch.h"

namespace ihs::app {

ExportedMeshes ExportMeshes(const fusion::ModelSnapshot& model,
                            const fusion::MeshingOptions& options,
                            const std::filesystem::path& folder,
                            const std::vector<std::string>& extra_formats) {
  const auto start = SteadyClock::now();
  ExportedMeshes exported;
  if (model.raw.faces.empty()) return exported;
  exported.meshes = fusion::MakeMeshes(model.raw, options, &model.free_space);
  if (exported.meshes.smoothed.Empty()) return exported;
  WriteMesh(folder / "mesh_tsdf.ply", exported.meshes.smoothed);
  exported.files.push_back(folder / "mesh_tsdf.ply");
  const TriangleMesh& final_mesh =
      exported.meshes.watertight.Empty() ? exported.meshes.smoothed : exported.meshes.watertight;
  WriteMesh(folder / "mesh.ply", final_mesh);
  exported.files.push_back(folder / "mesh.ply");
  for (const std::string& format : extra_formats) {
    if (format == "ply") continue;
    const std::filesystem::path path = folder / ("mesh." + format);
    WriteMesh(path, final_mesh);
    exported.files.push_back(path);
  }
  exported.milliseconds = MillisecondsSince(start);
  return exported;
}

namespace {

constexpr const char* kScanFiles[] = {
    "mesh.ply",        "mesh_tsdf.ply",  "mesh.obj",   "mesh.stl",     "trajectory.txt",
    "hand_joints.csv", "hand_poses.csv", "stats.json", "options.conf", "camera_intrinsic.json"};

}  // namespace

std::vector<std::filesystem::path> ScanFilesIn(const std::filesystem::path& folder) {
  std::vector<std::filesystem::path> found;
  std::error_code error;
  for (const char* name : kScanFiles) {
    if (std::filesystem::is_regular_file(folder / name, error)) found.push_back(folder / name);
  }
  return found;
}

std::string ScanFileNamesIn(const std::filesystem::path& folder) {
  std::string names;
  for (const std::filesystem::path& file : ScanFilesIn(folder))
    names += (names.empty() ? "" : ", ") + file.filename().string();
  return names;
}

int RemovePreviousScan(const std::filesystem::path& folder) {
  namespace fs = std::filesystem;
  std::vector<fs::path> stale = ScanFilesIn(folder);
  std::error_code error;
  if (fs::is_directory(folder / "preview", error)) {
    for (const fs::directory_entry& entry : fs::directory_iterator(folder / "preview", error)) {
      if (entry.path().extension() == ".png") stale.push_back(entry.path());
    }
  }
  int removed = 0;
  for (const fs::path& path : stale) {
    if (!fs::remove(path, error) || error) {
      throw OutputError(path.string() + ": cannot remove the earlier scan's file (" +
                        error.message() + ")");
    }
    ++removed;
  }
  return removed;
}

}  // namespace ihs::app
