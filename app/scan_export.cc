#include "app/scan_export.h"

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

}  // namespace ihs::app
