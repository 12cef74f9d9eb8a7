// inhandscan-mesh: prints what a mesh file holds (counts, size, area, volume, watertightness) and
// converts between PLY (binary or ASCII), OBJ and STL.

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>

#include "core/command_line.h"
#include "core/exit_codes.h"
#include "core/logging.h"
#include "core/mesh_intersections.h"
#include "core/mesh_io.h"

namespace {

int PrintInfo(const std::string& path) {
  const ihs::TriangleMesh mesh = ihs::ReadMesh(path);
  const auto [lo, hi] = mesh.Bounds();
  const Eigen::Vector3f size = hi - lo;
  const bool closed = mesh.IsWatertight();
  const std::int64_t crossings = closed ? ihs::FindSelfIntersections(mesh, 0).pairs : 0;
  const bool watertight = closed && crossings == 0;
  std::printf("file: %s\n", path.c_str());
  std::printf("vertices: %zu\n", mesh.vertices.size());
  std::printf("faces: %zu\n", mesh.faces.size());
  std::printf("normals: %s\n", mesh.HasNormals() ? "yes" : "no");
  std::printf("colours: %s\n", mesh.HasColors() ? "yes" : "no");
  std::printf("bounds_min_mm: %.3f %.3f %.3f\n", lo.x(), lo.y(), lo.z());
  std::printf("bounds_max_mm: %.3f %.3f %.3f\n", hi.x(), hi.y(), hi.z());
  std::printf("size_mm: %.3f %.3f %.3f\n", size.x(), size.y(), size.z());
  std::printf("area_mm2: %.3f\n", mesh.SurfaceArea());
  std::printf("watertight: %s\n", watertight ? "yes" : "no");
  if (closed) std::printf("self_intersections: %lld\n", static_cast<long long>(crossings));
  if (closed) std::printf("volume_mm3: %.3f\n", mesh.Volume());
  return ihs::kExitOk;
}

int Convert(const std::string& input, const std::string& output, bool ascii) {
  const ihs::TriangleMesh mesh = ihs::ReadMesh(input);
  ihs::MeshFormat format = ihs::MeshFormatFromPath(output);
  if (ascii) {
    if (format != ihs::MeshFormat::kPlyBinary) {
      throw std::invalid_argument("--ascii applies to .ply output only");
    }
    format = ihs::MeshFormat::kPlyAscii;
  }
  ihs::WriteMesh(output, mesh, format);
  spdlog::info("wrote {} ({} vertices, {} faces)", output, mesh.vertices.size(), mesh.faces.size());
  return ihs::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Inspect and convert meshes (PLY, OBJ, STL), units mm.", "inhandscan-mesh"};
  app.footer(ihs::ExitCodesHelp());
  app.set_version_flag("--version", std::string("inhandscan-mesh ") + IHS_VERSION);
  app.require_subcommand(1);
  std::string log_level = "info";
  bool quiet = false;
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off");
  app.add_flag("-q,--quiet", quiet, "only warnings and errors");

  std::string input, output;
  bool ascii = false;
  CLI::App* info = app.add_subcommand("info", "print counts, size, area, watertightness, volume");
  info->add_option("mesh", input, "mesh file (.ply, .obj, .stl)")->required();
  CLI::App* convert = app.add_subcommand("convert", "convert a mesh to the format of OUTPUT");
  convert->add_option("input", input, "mesh file to read")->required();
  convert->add_option("output", output, "mesh file to write (.ply, .obj, .stl)")->required();
  convert->add_flag("--ascii", ascii, "write PLY as ASCII instead of binary");
  ihs::ShareOptionsWithSubcommands(app);

  if (const auto done = ihs::ParseCommandLine(app, argc, argv)) return *done;
  return ihs::RunReportingErrors("inhandscan-mesh", [&] {
    ihs::SetUpLogging(ihs::ParseLogLevel(log_level), quiet);
    return info->parsed() ? PrintInfo(input) : Convert(input, output, ascii);
  });
}
