#pragma once
// The benchmark's report: the full turns first (rotation followed, rotation error at the end,
// drift, surface, volume per turn and method), the paper's Table 1 (dimensions) and Table 2
// (pairwise registration error at the fingertips) per method, the hand tracker's joint error,
// surface and trajectory errors, speed and memory, ratios to the baselines, the γt sweep; as
// Markdown (printed and written), CSV and PNG plots and mesh pictures.

#include <filesystem>
#include <string>
#include <vector>

#include "tools/bench/bench_run.h"

namespace ihs::bench {

struct ReportOptions {
  /// Writes OUT/benchmarks.md and OUT/benchmarks/*.csv, *.png.
  std::filesystem::path out;
  /// The command that made it, quoted in the report.
  std::string command;
  /// The γt values of the sweep (Method::gamma_t of the results).
  std::vector<double> sweep;
  /// Draw the meshes (needs OSMesa).
  bool mesh_pictures = true;
};

/// Writes the report and returns its Markdown. Throws ihs::OutputError when writing fails.
std::string WriteReport(const std::vector<CaseResult>& results, const std::vector<Method>& methods,
                        const ReportOptions& options);

}  // namespace ihs::bench
