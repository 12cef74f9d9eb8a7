// inhandscan-measure: measures a scanned mesh the way the paper does — a body of revolution's
// symmetry axis, height and section diameters (the paper's Table 1 measures when --object names
// what was scanned), its volume when watertight — and, given a generator's ground truth and the
// scan's trajectory, the pairwise registration error at the fingertips (Table 2), the object
// trajectory's drift, and the surface's Chamfer distance and completeness. A table for people on
// stdout; --json FILE for machines.

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "core/atomic_file.h"
#include "core/command_line.h"
#include "core/exit_codes.h"
#include "core/logging.h"
#include "core/mesh_intersections.h"
#include "core/mesh_io.h"
#include "core/trajectory_io.h"
#include "fusion/measure.h"
#include "tools/evaluation.h"

namespace {

namespace fs = std::filesystem;

int Run(const std::string& mesh_path, const std::string& seen_path, const std::string& object,
        const std::string& gt, std::string trajectory_path, const std::string& json_path) {
  const ihs::TriangleMesh mesh = ihs::ReadMesh(mesh_path);
  const ihs::TriangleMesh seen = seen_path.empty() ? ihs::TriangleMesh{} : ihs::ReadMesh(seen_path);
  const ihs::fusion::RevolutionMeasures measures = ihs::fusion::MeasureRevolution(mesh);
  nlohmann::json out = {{"mesh", mesh_path},
                        {"faces", mesh.faces.size()},
                        {"watertight", ihs::IsWatertightWithoutSelfIntersections(mesh)},
                        {"height_mm", measures.height_mm},
                        {"widest_diameter_mm", measures.widest_diameter_mm},
                        {"widest_at_mm", measures.widest_at_mm},
                        {"head_diameter_mm", measures.head_diameter_mm},
                        {"axis", {measures.axis.x(), measures.axis.y(), measures.axis.z()}}};
  std::printf("mesh: %s (%zu faces, %s)\n", mesh_path.c_str(), mesh.faces.size(),
              ihs::IsWatertightWithoutSelfIntersections(mesh) ? "watertight" : "not watertight");
  std::printf("axis: %.3f %.3f %.3f; height %.2f mm; widest section Ø%.2f mm at %.1f mm",
              measures.axis.x(), measures.axis.y(), measures.axis.z(), measures.height_mm,
              measures.widest_diameter_mm, measures.widest_at_mm);
  if (measures.head_diameter_mm > 0) std::printf("; head Ø%.2f mm", measures.head_diameter_mm);
  std::printf("\n");
  if (mesh.IsWatertight()) {
    out["mesh_volume_mm3"] = mesh.Volume();
    std::printf("volume: %.0f mm³\n", mesh.Volume());
  }
  std::vector<ihs::StampedPose> trajectory;
  if (!gt.empty()) {
    if (trajectory_path.empty()) {
      trajectory_path = (fs::path(mesh_path).parent_path() / "trajectory.txt").string();
    }
    trajectory = ihs::ReadTumTrajectory(trajectory_path);
  }
  if (seen_path.empty()) {
    out.update(ihs::eval::ReportScan(object, mesh, mesh, gt, trajectory, std::nullopt));
  } else {
    // The volume on the watertight mesh, with the share of it the seen surface does not cover.
    out.update(ihs::eval::ReportScan(object, seen, mesh, gt, trajectory,
                                     ihs::fusion::UnseenShare(mesh, seen)));
  }
  if (!json_path.empty()) ihs::WriteFileAtomically(json_path, out.dump(1) + "\n");
  return ihs::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Measure a scanned mesh: a body of revolution's dimensions, volume, and (with "
      "ground truth) the paper's registration and surface errors.",
      "inhandscan-measure"};
  app.footer(ihs::ExitCodesHelp());
  app.set_version_flag("--version", std::string("inhandscan-measure ") + IHS_VERSION);
  std::string mesh, seen, object, gt, trajectory, json, log_level = "info";
  bool quiet = false;
  app.add_option("mesh", mesh, "the scanned mesh (PLY, OBJ, STL)")->required();
  app.add_option("--object", object,
                 "what was scanned: sphere, water-bottle, bowling-pin, small-bottle or "
                 "lathe:FILE (the paper's measures against its true dimensions)");
  app.add_option("--seen", seen,
                 "the seen surface of a scan whose MESH is watertight (mesh_tsdf.ply beside "
                 "mesh.ply): the dimensions and the surface errors are measured on it, the volume "
                 "on MESH with the share of MESH that was never seen")
      ->check(CLI::ExistingFile);
  app.add_option("--gt", gt, "a generator's gt/ folder (needs the scan's trajectory)");
  app.add_option("--trajectory", trajectory,
                 "the scan's TUM trajectory (default: trajectory.txt beside the mesh)");
  app.add_option("--json", json, "also write the results as JSON to this file");
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off");
  app.add_flag("-q,--quiet", quiet, "only warnings and errors");
  if (const auto done = ihs::ParseCommandLine(app, argc, argv)) return *done;
  return ihs::RunReportingErrors("inhandscan-measure", [&] {
    ihs::SetUpLogging(ihs::ParseLogLevel(log_level), quiet);
    return Run(mesh, seen, object, gt, trajectory, json);
  });
}
