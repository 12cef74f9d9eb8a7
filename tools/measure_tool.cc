// inhandscan-measure: measures a scanned mesh the way the paper does — a body of revolution's
// symmetry axis, height and section diameters (the paper's Table 1 measures when --object names
// what was scanned), its volume when watertight — and, given a generator's ground truth and the
// scan's trajectory, the pairwise registration error at the fingertips (Table 2), the object
// trajectory's drift and how much of the true turn it followed, the surface's Chamfer distance and
// completeness (and, with no --object, the volume against the true mesh's). A table for people on
// stdout, or two lines of it with --summary (tools/demo.sh); --json FILE for machines.

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
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

// What the command line asks for.
struct MeasureArgs {
  std::string mesh, seen, object, gt, trajectory, json;
  /// Print PrintSummary's two lines (needs `gt`) instead of the table.
  bool summary = false;
};

// The scan against the truth in two lines, from ReportScan's JSON with a gt/ folder: how much of
// the true turn the scan followed, and the surface's (and a watertight mesh's volume's) error.
void PrintSummary(const nlohmann::json& report) {
  std::printf(
      "the scan followed %.0f° of the true %.0f° turn (rotation error at the end %.1f°; the "
      "object %.1f mm off on average)\n",
      report["turned_deg"]["scan"].get<double>(), report["turned_deg"]["truth"].get<double>(),
      report["rotation_error_deg"]["final"].get<double>(),
      report["trajectory_error_mm"]["mean"].get<double>());
  std::printf(
      "against the truth: surface Chamfer %.2f mm, %.0f %% of the true surface within %.0f mm",
      report["chamfer_mm"].get<double>(), 100 * report["completeness"].get<double>(),
      report["completeness_within_mm"].get<double>());
  if (report.contains("volume_error")) {
    std::printf("; volume %+.1f %%", 100 * report["volume_error"].get<double>());
    if (report.contains("volume_unseen_share")) {
      std::printf(" (%.0f %% of the mesh never seen)",
                  100 * report["volume_unseen_share"].get<double>());
    }
  }
  std::printf("\n");
}

// The mesh's own measures (symmetry axis, height, sections, a watertight mesh's volume), printed
// to `table` unless it is null.
nlohmann::json MeasureMesh(const ihs::TriangleMesh& mesh, const std::string& mesh_path,
                           std::FILE* table) {
  const ihs::fusion::RevolutionMeasures measures = ihs::fusion::MeasureRevolution(mesh);
  const bool watertight = ihs::IsWatertightWithoutSelfIntersections(mesh);
  nlohmann::json out = {{"mesh", mesh_path},
                        {"faces", mesh.faces.size()},
                        {"watertight", watertight},
                        {"height_mm", measures.height_mm},
                        {"widest_diameter_mm", measures.widest_diameter_mm},
                        {"widest_at_mm", measures.widest_at_mm},
                        {"head_diameter_mm", measures.head_diameter_mm},
                        {"axis", {measures.axis.x(), measures.axis.y(), measures.axis.z()}}};
  if (mesh.IsWatertight()) out["mesh_volume_mm3"] = mesh.Volume();
  if (!table) return out;
  std::fprintf(table, "mesh: %s (%zu faces, %s)\n", mesh_path.c_str(), mesh.faces.size(),
               watertight ? "watertight" : "not watertight");
  std::fprintf(table, "axis: %.3f %.3f %.3f; height %.2f mm; widest section Ø%.2f mm at %.1f mm",
               measures.axis.x(), measures.axis.y(), measures.axis.z(), measures.height_mm,
               measures.widest_diameter_mm, measures.widest_at_mm);
  if (measures.head_diameter_mm > 0) {
    std::fprintf(table, "; head Ø%.2f mm", measures.head_diameter_mm);
  }
  std::fprintf(table, "\n");
  if (mesh.IsWatertight()) std::fprintf(table, "volume: %.0f mm³\n", mesh.Volume());
  return out;
}

int Run(const MeasureArgs& args) {
  std::FILE* table = args.summary ? nullptr : stdout;
  const ihs::TriangleMesh mesh = ihs::ReadMesh(args.mesh);
  const ihs::TriangleMesh seen = args.seen.empty() ? ihs::TriangleMesh{} : ihs::ReadMesh(args.seen);
  nlohmann::json out = MeasureMesh(mesh, args.mesh, table);
  std::vector<ihs::StampedPose> trajectory;
  if (!args.gt.empty()) {
    trajectory = ihs::ReadTumTrajectory(args.trajectory.empty()
                                            ? fs::path(args.mesh).parent_path() / "trajectory.txt"
                                            : fs::path(args.trajectory));
  }
  // The volume on the watertight mesh, with the share of it the seen surface does not cover.
  const std::optional<double> unseen_share =
      args.seen.empty() ? std::nullopt : std::optional(ihs::fusion::UnseenShare(mesh, seen));
  out.update(ihs::eval::ReportScan(args.object, args.seen.empty() ? mesh : seen, mesh, args.gt,
                                   trajectory, unseen_share, table));
  if (args.summary) PrintSummary(out);
  if (!args.json.empty()) ihs::WriteFileAtomically(args.json, out.dump(1) + "\n");
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
  MeasureArgs args;
  std::string log_level = "info";
  bool quiet = false;
  app.add_option("mesh", args.mesh, "the scanned mesh (PLY, OBJ, STL)")->required();
  app.add_option("--object", args.object,
                 "what was scanned: sphere, water-bottle, bowling-pin, small-bottle or "
                 "lathe:FILE (the paper's measures against its true dimensions)")
      ->check(ihs::eval::NotABodyOfRevolution);
  app.add_option("--seen", args.seen,
                 "the seen surface of a scan whose MESH is watertight (mesh_tsdf.ply beside "
                 "mesh.ply): the dimensions and the surface errors are measured on it, the volume "
                 "on MESH with the share of MESH that was never seen")
      ->check(CLI::ExistingFile);
  CLI::Option* gt = app.add_option(
      "--gt", args.gt,
      "a generator's gt/ folder (needs the scan's trajectory; without --object, a watertight "
      "MESH's volume is compared with gt/object.ply's)");
  app.add_option("--trajectory", args.trajectory,
                 "the scan's TUM trajectory (default: trajectory.txt beside the mesh)");
  app.add_flag("--summary", args.summary,
               "print two lines instead of the table: how much of the true turn the scan "
               "followed, and the surface's and volume's errors against the truth")
      ->needs(gt);
  app.add_option("--json", args.json, "also write the results as JSON to this file");
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off");
  app.add_flag("-q,--quiet", quiet, "only warnings and errors");
  if (const auto done = ihs::ParseCommandLine(app, argc, argv)) return *done;
  return ihs::RunReportingErrors("inhandscan-measure", [&] {
    ihs::SetUpLogging(ihs::ParseLogLevel(log_level), quiet);
    return Run(args);
  });
}
