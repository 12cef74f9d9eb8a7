#pragma once
// Turning the model into the files a user keeps: the raw marching-cubes mesh cleaned, smoothed
// and closed (fusion/surface_mesh.h), written as mesh_tsdf.ply (the surface that was seen) and
// mesh.ply (watertight), plus the same watertight mesh in any extra formats asked for.

#include <filesystem>
#include <string>
#include <vector>

#include "core/triangle_mesh.h"
#include "fusion/object_fusion.h"
#include "fusion/surface_mesh.h"

namespace ihs::app {

/// What an export wrote.
struct ExportedMeshes {
  fusion::MeshingResult meshes;
  /// Files written, in order.
  std::vector<std::filesystem::path> files;
  /// Meshing and writing, ms.
  double milliseconds = 0;
};

/// Meshes `model` (its raw mesh, the closure bounded by its free space) with `options` and
/// writes into `folder`: mesh_tsdf.ply (the smoothed surface), mesh.ply (the watertight mesh;
/// the smoothed one when Poisson is off or gave nothing) and mesh.<ext> of the same for each of
/// `extra_formats` ("obj", "stl"; "ply" adds nothing). Nothing is written when the raw mesh has
/// no faces. Throws ihs::OutputError when a file cannot be written.
ExportedMeshes ExportMeshes(const fusion::ModelSnapshot& model,
                            const fusion::MeshingOptions& options,
                            const std::filesystem::path& folder,
                            const std::vector<std::string>& extra_formats = {});

/// The files a scan writes that are in `folder` now (see RemovePreviousScan for the names;
/// previews not included), in that order.
std::vector<std::filesystem::path> ScanFilesIn(const std::filesystem::path& folder);
/// Their names as one line ("mesh.ply, mesh_tsdf.ply, …"); empty when there are none.
std::string ScanFileNamesIn(const std::filesystem::path& folder);

/// Removes from `folder` the files an earlier scan wrote there (mesh.ply, mesh_tsdf.ply,
/// mesh.obj, mesh.stl, trajectory.txt, hand_joints.csv, hand_poses.csv, stats.json,
/// options.conf, camera_intrinsic.json and the PNGs
/// in preview/), so that a new scan into the same folder never leaves an old mesh beside its own
/// stats.json; other files stay. Returns how many were removed. Throws ihs::OutputError when one
/// cannot be removed.
int RemovePreviousScan(const std::filesystem::path& folder);

}  // namespace ihs::app
