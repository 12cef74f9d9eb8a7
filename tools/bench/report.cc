#include "tools/bench/report.h"

#include <sys/utsname.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <thread>

#include "core/errors.h"
#include "core/mesh_io.h"
#include "tools/bench/mesh_view.h"
#include "tools/bench/plot.h"
#include "tools/evaluation.h"

namespace ihs::bench {
namespace fs = std::filesystem;
namespace {

using nlohmann::json;

std::string Format(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

// A table kept as text cells, written as Markdown and as CSV.
struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;

  std::string Markdown() const {
    std::string text = "|";
    for (const auto& h : header) text += " " + h + " |";
    text += "\n|";
    for (size_t i = 0; i < header.size(); ++i) text += i < 2 ? "---|" : "---:|";
    text += "\n";
    for (const auto& row : rows) {
      text += "|";
      for (const auto& cell : row) text += " " + cell + " |";
      text += "\n";
    }
    return text;
  }
};

// CSV rows as they are collected.
struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;

  void Write(const fs::path& path) const {
    std::ofstream out(path);
    auto line = [&](const std::vector<std::string>& cells) {
      for (size_t i = 0; i < cells.size(); ++i) out << (i ? "," : "") << cells[i];
      out << "\n";
    };
    line(header);
    for (const auto& row : rows) line(row);
    if (!out) throw OutputError(path.string() + ": cannot write");
  }
};

const MethodResult* Find(const CaseResult& result, const std::string& method) {
  for (const MethodResult& m : result.methods)
    if (m.method == method) return &m;
  return nullptr;
}

double Number(const json& j, const char* key, const char* sub = nullptr) {
  if (!j.contains(key)) return NAN;
  const json& v = j[key];
  if (sub) return v.contains(sub) && v[sub].is_number() ? v[sub].get<double>() : NAN;
  return v.is_number() ? v.get<double>() : NAN;
}

std::string Cell(double value, const char* format = "%.2f") {
  return std::isfinite(value) ? Format(format, value) : "–";
}

/// The mean of `values`; NaN when there are none.
double Mean(const std::vector<double>& values) {
  double sum = 0;
  for (double v : values) sum += v;
  return values.empty() ? NAN : sum / values.size();
}

// Pooled mean and standard deviation of several (mean, std, count) groups.
struct Pooled {
  double sum = 0, sum_squares = 0;
  double n = 0;
  void Add(double mean, double std, double count) {
    if (!(count > 0) || !std::isfinite(mean)) return;
    sum += mean * count;
    sum_squares += (std * std + mean * mean) * count;
    n += count;
  }
  double Mean() const { return n > 0 ? sum / n : NAN; }
  double Std() const {
    return n > 0 ? std::sqrt(std::max(0.0, sum_squares / n - Mean() * Mean())) : NAN;
  }
};

std::string Machine() {
  std::string cpu = "unknown CPU";
  std::ifstream info("/proc/cpuinfo");
  for (std::string line; std::getline(info, line);) {
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  }
  struct utsname name {};
  uname(&name);
  std::ostringstream text;
  text << cpu << ", " << std::thread::hardware_concurrency() << " cores, " << name.sysname << " "
       << name.release;
  return text.str();
}

double AngleSinceFirst(const Rigid3& first, const Rigid3& pose) {
  const Eigen::AngleAxisd delta(pose.rotation() * first.rotation().transpose());
  return delta.angle() * 180 / M_PI;
}

/// A table header: the `lead` columns, then one per compared method (its name + `suffix`).
std::vector<std::string> MethodHeader(std::vector<std::string> lead,
                                      const std::vector<std::string>& compared,
                                      const std::string& suffix = "") {
  for (const auto& name : compared) lead.push_back(name + suffix);
  return lead;
}

/// Appends to `row` one cell per compared method: `cell_of` its result, or `missing` where the
/// method failed or did not run on the case.
template <typename CellOf>
void AppendMethodCells(std::vector<std::string>& row, const CaseResult& r,
                       const std::vector<std::string>& compared, CellOf cell_of,
                       const char* missing = "failed") {
  for (const auto& name : compared) {
    const MethodResult* m = Find(r, name);
    row.push_back(m && m->ok ? cell_of(*m) : missing);
  }
}

/// Why `m` counts as having lost the object in its case, or nothing: its mean drift is larger
/// than the object (its largest true dimension; 100 mm where the case has none), or a dimension
/// it measured is off by more than the dimension itself (it meshed the scene, not the object).
/// Its numbers then say nothing about the object: the tables print "lost" instead.
std::optional<std::string> LostReason(const MethodResult& m) {
  double size = 0, worst = 0;
  for (const auto& row : m.measures.value("dimensions", json::array())) {
    const double truth = row.value("truth_mm", 0.0);
    size = std::max(size, truth);
    const double error = std::abs(row.value("scan_mm", 0.0) - truth);
    if (truth > 0 && !(error <= truth)) worst = std::max(worst, error / truth);
  }
  const double drift = Number(m.measures, "trajectory_error_mm", "mean");
  if (std::isfinite(drift) && drift > (size > 0 ? size : 100.0))
    return "lost (drift " + Format("%.0f", drift) + " mm)";
  if (worst > 0) return "lost (a dimension " + Format("%.0f", worst) + "× off)";
  return std::nullopt;
}

/// AppendMethodCells for the object's measures: "lost" where the method lost the object.
template <typename CellOf>
void AppendObjectCells(std::vector<std::string>& row, const CaseResult& r,
                       const std::vector<std::string>& compared, CellOf cell_of,
                       const char* missing = "failed") {
  AppendMethodCells(
      row, r, compared,
      [&](const MethodResult& m) -> std::string {
        if (const auto lost = LostReason(m)) return *lost;
        return cell_of(m);
      },
      missing);
}

/// The method's time per frame in its object stage (SIFT + fusion), ms.
double ObjectStageMs(const json& measures) {
  const json& ms = measures.value("ms_per_frame", json::object());
  return ms.value("features", 0.0) + ms.value("fusion", 0.0);
}

/// Table 2's cell: pairwise error mean ± std, and how many frames the method kept.
std::string PairwiseCell(const MethodResult& m) {
  const json& j = m.measures;
  const double samples = Number(j, "pairwise_error_mm", "samples");
  std::string cell = samples > 0 ? Cell(Number(j, "pairwise_error_mm", "mean")) + " ± " +
                                       Cell(Number(j, "pairwise_error_mm", "std"))
                                 : "no pairs";
  // Frames the method could not register are not in its error: say how many it kept.
  if (m.registered < m.frames)
    cell += " (" + std::to_string(m.registered) + "/" + std::to_string(m.frames) + ")";
  return cell;
}

/// A sphere's volume cell: the volume error and the share of the watertight surface Poisson
/// made up, "–" where it was not measured.
std::string VolumeCell(const MethodResult& m) {
  const double v = Number(m.measures, "volume_error");
  const double unseen = Number(m.measures, "volume_unseen_share");
  return !std::isfinite(v) ? "–"
         : std::isfinite(unseen)
             ? Format("%+.1f %%", 100 * v) + Format(" (%.0f %% unseen)", 100 * unseen)
             : Format("%+.1f %%", 100 * v);
}

/// results.csv: every case × method with every measure.
Csv ResultsCsv(const std::vector<CaseResult>& results) {
  Csv csv{{"case",
           "method",
           "ok",
           "frames",
           "registered",
           "pairwise_mean_mm",
           "pairwise_std_mm",
           "pairwise_samples",
           "drift_mean_mm",
           "chamfer_mm",
           "completeness",
           "dimension_error_mean_mm",
           "dimension_error_mean_mm_watertight",
           "volume_error",
           "volume_unseen_share",
           "self_intersections",
           "fusion_ms",
           "export_ms",
           "joint_error_mm",
           "track_ms",
           "app_fps",
           "app_peak_mib",
           "error"},
          {}};
  for (const CaseResult& r : results) {
    for (const MethodResult& m : r.methods) {
      const json& j = m.measures;
      std::string why = m.error;
      std::replace(why.begin(), why.end(), ',', ';');
      csv.rows.push_back({r.bench_case.name,
                          m.method,
                          m.ok ? "1" : "0",
                          std::to_string(m.frames),
                          std::to_string(m.registered),
                          Cell(Number(j, "pairwise_error_mm", "mean"), "%.3f"),
                          Cell(Number(j, "pairwise_error_mm", "std"), "%.3f"),
                          Cell(Number(j, "pairwise_error_mm", "samples"), "%.0f"),
                          Cell(Number(j, "trajectory_error_mm", "mean"), "%.3f"),
                          Cell(Number(j, "chamfer_mm"), "%.3f"),
                          Cell(Number(j, "completeness"), "%.4f"),
                          Cell(Number(j, "dimension_error_mm_mean"), "%.3f"),
                          Cell(Number(j, "dimension_error_mm_mean_watertight"), "%.3f"),
                          Cell(Number(j, "volume_error"), "%.4f"),
                          Cell(Number(j, "volume_unseen_share"), "%.4f"),
                          Cell(Number(j, "self_intersections"), "%.0f"),
                          Format("%.2f", ObjectStageMs(j)),
                          Cell(Number(j, "export_ms"), "%.0f"),
                          Format("%.2f", r.joint_error_mm),
                          Format("%.2f", r.track_ms + r.mask_ms),
                          Format("%.1f", r.app_fps),
                          Format("%.0f", r.app_peak_mib),
                          why});
    }
  }
  return csv;
}

/// The truth's rotation since its first pose, over time since then.
Series TruthRotation(const std::vector<StampedPose>& truth) {
  Series series{"truth", {}, {}, {0, 0, 0}, false, true};
  for (const StampedPose& p : truth) {
    series.x.push_back(p.time_s - truth.front().time_s);
    series.y.push_back(AngleSinceFirst(truth.front().transform, p.transform));
  }
  return series;
}

/// Adds to `rotation` and `drift` the method's rotation since the truth's first pose and its
/// drift over time (the caller checked that both trajectories have poses).
void AddMethodTrajectory(const CaseResult& r, const MethodResult& m, Series& rotation,
                         Series& drift) {
  // The method's first pose stands for the truth's at that time.
  const StampedPose* first_truth = eval::FindPose(r.truth, m.trajectory.front().time_s);
  const Rigid3 offset =
      first_truth ? m.trajectory.front().transform.Inverse() * first_truth->transform : Rigid3();
  for (const StampedPose& p : m.trajectory) {
    rotation.x.push_back(p.time_s - r.truth.front().time_s);
    rotation.y.push_back(AngleSinceFirst(r.truth.front().transform, p.transform * offset));
  }
  const eval::TrajectoryError e = eval::CompareTrajectory(r.gt_dir, m.trajectory);
  for (size_t i = 0; i < e.times_s.size(); ++i) {
    drift.x.push_back(e.times_s[i] - r.truth.front().time_s);
    drift.y.push_back(std::max(e.errors_mm[i], 0.01));
  }
}

// The state of one WriteReport call: its inputs, the Markdown so far, and what later sections
// take from earlier ones (Table 1's errors and CSV, Table 2's pooled errors, the sweep's CSV).
struct ReportWriter {
  const std::vector<CaseResult>& results;
  const std::vector<Method>& methods;
  const ReportOptions& options;
  fs::path assets;
  /// Methods compared in the tables.
  std::vector<std::string> compared;
  std::ostringstream md;
  Csv table1_csv{{"case", "measure", "truth_mm", "method", "scan_mm", "error_mm", "surface"}, {}};
  Csv sweep_csv{{"case", "gamma_t", "pairwise_mean_mm", "pairwise_std_mm", "drift_mean_mm"}, {}};
  Csv turns_csv{
      {"case", "method", "truth_turned_deg", "scan_turned_deg", "rotation_error_final_deg",
       "drift_mean_mm", "chamfer_mm", "completeness", "shown", "volume_error", "lost"},
      {}};
  /// Table 1's absolute dimension errors over the paper sessions, per method: on the seen
  /// surface, and on the watertight mesh (mesh.ply).
  std::map<std::string, std::vector<double>> abs_errors, abs_errors_watertight;
  /// Table 2's pairwise errors pooled over the paper sessions, per method.
  std::map<std::string, Pooled> pooled;

  ReportWriter(const std::vector<CaseResult>& results, const std::vector<Method>& methods,
               const ReportOptions& options);
  void Introduction();
  void FullTurnsTable();
  void Table1();
  void Watertight();
  void DimensionRows(const CaseResult& r, const std::string& key, Table& table);
  Table DimensionTable(const std::string& key);
  void Table2();
  void Ratios();
  void SurfaceDriftSpeed();
  void Stages();
  void Sweep();
  void TrajectoriesAndMeshes();
  void CaseCharts(const CaseResult& r);
  void CaseMeshes(const CaseResult& r, MeshView& view);
  std::string Files();
};

/// Creates the assets folder and picks the compared methods.
ReportWriter::ReportWriter(const std::vector<CaseResult>& results,
                           const std::vector<Method>& methods, const ReportOptions& options)
    : results(results), methods(methods), options(options), assets(options.out / "benchmarks") {
  std::error_code error;
  fs::create_directories(assets, error);
  if (error) throw OutputError(assets.string() + ": cannot create (" + error.message() + ")");

  // Methods compared in the tables: all but the sweep's extra γt values, Open3D's last if run.
  for (const Method& m : methods)
    if (!m.sweep_only) compared.push_back(m.name);
  for (const char* open3d : {"open3d", "open3d-f2m"}) {
    if (std::any_of(results.begin(), results.end(),
                    [&](const CaseResult& r) { return Find(r, open3d) != nullptr; }))
      compared.push_back(open3d);
  }
}

/// The title, how the report was made, what the methods are, and the table of cases.
void ReportWriter::Introduction() {
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%d", std::gmtime(&now));
  md << "# Benchmarks\n\n"
     << "Generated by `" << options.command << "` on " << date << " (inhandscan " << IHS_VERSION
     << "), on " << Machine() << ".\n\n"
     << "Every case is a generator sequence with full sensor noise: scripted full turns "
        "(the headline cases: a scan must follow the whole turn), and the paper's four "
        "objects turned by the paper's recorded hand motions. The tracker uses the procedural "
        "hand template and initialises itself on every case (on the scripted ones the hand holds "
        "the object from the first frame). Methods: **ours** (γt = 15), **visual-only** (γt = 0), "
        "**contacts-only** (no "
        "SIFT), **no-icp**, **open3d** (Open3D's RGB-D odometry + scalable TSDF, frame to frame) "
        "and **open3d-f2m** (Open3D's dense SLAM: frame to model, point-to-plane ICP against its "
        "own TSDF's raycast at the last pose), both Open3D methods on the same frames with the "
        "hand's pixels removed by the ground truth. Every method's mesh goes through "
        "the same smoothing and Poisson. Dimensions are measured on the seen surface and again on "
        "the watertight mesh a user takes away (mesh.ply), the volume on the watertight mesh. A "
        "method whose mean drift is larger than the object, or that measures a dimension off by "
        "more than the dimension itself, lost the object: its cells say \"lost\" and the paper "
        "sessions' means leave it out (and say how many).\n\n";
  md << "| case | object | motion | frames |\n|---|---|---|---:|\n";
  for (const CaseResult& r : results) {
    const BenchCase& c = r.bench_case;
    const std::string motion = c.motion.rfind("recorded:", 0) != 0 ? "scripted full turn"
                               : c.frames == 0 ? "recorded (whole paper session)"
                                               : "recorded (paper session)";
    md << "| " << c.name << " | " << c.object << (c.textured ? " (textured)" : "") << " | "
       << motion << " | " << (r.methods.empty() ? 0 : r.methods.front().frames) << " |\n";
  }
  md << "\n";
}

/// One method's row of the full-turns table: how much of the truth's turn it followed, its
/// rotation error at the end, its drift, its surface and volume ("lost" where it lost the object).
std::vector<std::string> FullTurnRow(const CaseResult& r, const MethodResult& m, Csv& csv) {
  const json& j = m.measures;
  const double truth = Number(j, "turned_deg", "truth"), scan = Number(j, "turned_deg", "scan");
  const auto lost = LostReason(m);
  const std::string drift = Cell(Number(j, "trajectory_error_mm", "mean"), "%.1f");
  const std::string surface = Cell(Number(j, "chamfer_mm")) + " / " +
                              Cell(100 * Number(j, "completeness"), "%.0f %%") + " of " +
                              Cell(100 * r.shown_share, "%.0f %%");
  csv.rows.push_back({r.bench_case.name, m.method, Cell(truth, "%.1f"), Cell(scan, "%.1f"),
                      Cell(Number(j, "rotation_error_deg", "final"), "%.2f"),
                      Cell(Number(j, "trajectory_error_mm", "mean"), "%.3f"),
                      Cell(Number(j, "chamfer_mm"), "%.3f"),
                      Cell(Number(j, "completeness"), "%.4f"), Cell(r.shown_share, "%.4f"),
                      Cell(Number(j, "volume_error"), "%.4f"), lost ? "1" : "0"});
  return {r.bench_case.name,
          m.method,
          Cell(scan, "%.0f°") + " of " + Cell(truth, "%.0f°") +
              (truth > 0 ? Format(" (%.0f %%)", 100 * scan / truth) : ""),
          Cell(Number(j, "rotation_error_deg", "final"), "%.1f°"),
          lost ? drift + " (lost)" : drift,
          lost ? *lost : surface,
          lost ? *lost : VolumeCell(m)};
}

/// The full turns first: per turn and method the rotation followed of the truth's, the rotation
/// error at the end, drift, surface and volume; with each turn's rotation chart.
void ReportWriter::FullTurnsTable() {
  Table table;
  table.header = {"turn",
                  "method",
                  "turned (of the truth's)",
                  "rot. err. at end",
                  "drift mm",
                  "Chamfer mm / compl. of shown",
                  "volume (watertight)"};
  std::string charts;
  for (const CaseResult& r : results) {
    if (!IsFullTurn(r.bench_case)) continue;
    for (const auto& name : compared) {
      const MethodResult* m = Find(r, name);
      if (!m) continue;
      if (m->ok) {
        table.rows.push_back(FullTurnRow(r, *m, turns_csv));
      } else {
        table.rows.push_back({r.bench_case.name, name, "failed: " + m->error, "", "", "", ""});
      }
    }
    charts += "![rotation](benchmarks/rotation-" + r.bench_case.name + ".png) ";
  }
  if (table.rows.empty()) return;
  md << "## Full turns\n\n"
     << "The object turned a full turn in the hand, re-grasped every 90°: a scan must follow "
        "the turn from the hand, where a round object's shape cannot show it. Turned: the "
        "rotation the method followed along the truth's axes, of the truth's. Rotation error: "
        "between the method's object and the truth's at the last frame (a full turn ends where "
        "it began, so a method that followed none of it ends near 0° too: read it beside "
        "turned). Drift: the mean distance "
        "of the true object's points from where the method puts them. Chamfer and completeness "
        "(true surface within 2 mm) on the seen surface, of the share of the true surface the "
        "recording showed at all (every frame's object pixels placed by the truth's pose: what "
        "perfect registration would reach); the volume of the watertight mesh "
        "against the true object's (in brackets the share Poisson made up).\n\n"
     << table.Markdown() << "\n"
     << charts << "\n\n";
}

/// Table 1's rows of one case from the measures' `key` ("dimensions": the seen surface,
/// "dimensions_watertight": mesh.ply): each dimension ours measured, every method's scan and
/// error; collects the CSV rows and the paper sessions' absolute errors.
void ReportWriter::DimensionRows(const CaseResult& r, const std::string& key, Table& table) {
  const bool seen = key == "dimensions";
  auto& errors = seen ? abs_errors : abs_errors_watertight;
  const MethodResult* reference = Find(r, "ours");
  if (!reference || !reference->measures.contains(key)) return;
  for (size_t d = 0; d < reference->measures[key].size(); ++d) {
    const json& row = reference->measures[key][d];
    const double truth = row["truth_mm"].get<double>();
    std::vector<std::string> cells = {r.bench_case.name, row["measure"].get<std::string>(),
                                      Format("%.1f", truth)};
    AppendObjectCells(cells, r, compared, [&](const MethodResult& m) -> std::string {
      if (!m.measures.contains(key) || m.measures[key].size() <= d) return "failed";
      const double scan = m.measures[key][d]["scan_mm"].get<double>();
      if (r.bench_case.paper) errors[m.method].push_back(std::abs(scan - truth));
      table1_csv.rows.push_back({r.bench_case.name, row["measure"].get<std::string>(),
                                 Format("%.2f", truth), m.method, Format("%.2f", scan),
                                 Format("%.2f", scan - truth), seen ? "seen" : "mesh.ply"});
      return Format("%.1f", scan) + " (" + Format("%+.1f", scan - truth) + ")";
    });
    table.rows.push_back(cells);
  }
}

/// Table 1's dimensions per case from the measures' `key`, with the paper sessions' mean
/// absolute error.
Table ReportWriter::DimensionTable(const std::string& key) {
  Table table;
  table.header = MethodHeader({"case", "measure", "truth"}, compared);
  for (const CaseResult& r : results) DimensionRows(r, key, table);
  auto& errors = key == "dimensions" ? abs_errors : abs_errors_watertight;
  std::vector<std::string> mean_row = {"**paper sessions**", "**mean abs. error**", ""};
  for (const auto& name : compared) {
    const auto& e = errors[name];
    int lost = 0;  // Paper sessions left out of the mean: the method lost the object there.
    for (const CaseResult& r : results) {
      const MethodResult* m = Find(r, name);
      lost += r.bench_case.paper && m && m->ok && LostReason(*m);
    }
    mean_row.push_back((e.empty() ? "–" : "**" + Format("%.2f", Mean(e)) + "**") +
                       (lost ? " (" + std::to_string(lost) + " lost)" : ""));
  }
  if (!errors.empty()) table.rows.push_back(mean_row);
  return table;
}

/// Table 1: dimensions per case on the seen surface and on mesh.ply, the paper sessions' mean
/// absolute errors, sphere volumes.
void ReportWriter::Table1() {
  Table table1 = DimensionTable("dimensions");
  bool sphere_volume = false;
  for (const CaseResult& r : results) {
    if (r.bench_case.object != "sphere") continue;
    std::vector<std::string> cells = {r.bench_case.name, "volume error", ""};
    AppendObjectCells(cells, r, compared, VolumeCell, "–");
    table1.rows.push_back(cells);
    sphere_volume = true;
  }
  md << "## Table 1: dimensions (mm; scan and its error)\n\n" << table1.Markdown() << "\n";
  if (sphere_volume) {
    md << "Sphere volume: the watertight mesh against the true sphere's; in brackets the share "
          "of the watertight surface farther than 2 mm from the seen one, which Poisson made up. "
          "Where that share is large the volume is a guess (docs/fusion.md: on half-seen spheres "
          "it moves from +26 % to −20 % with the size of Poisson's cube alone); a scan that saw "
          "the whole sphere (004-sphere-whole, when it is run) is where the volume is "
          "measured.\n\n";
  }
  const Table delivered = DimensionTable("dimensions_watertight");
  if (delivered.rows.empty()) return;
  md << "### Table 1 on the delivered mesh (mesh.ply)\n\nThe same dimensions measured on the "
        "watertight mesh a user takes away, where Poisson closed what no frame saw (a base "
        "under the hand, the far side of a half-seen object).\n\n"
     << delivered.Markdown() << "\n";
}

/// Whether every method's mesh.ply passed the application's own watertight check, and which
/// did not (with how many pairs of its faces cross).
void ReportWriter::Watertight() {
  int checked = 0;
  std::vector<std::string> failed;
  for (const CaseResult& r : results) {
    for (const MethodResult& m : r.methods) {
      const auto found = m.measures.find("watertight");
      if (found == m.measures.end() || !found->is_boolean()) continue;
      ++checked;
      if (found->get<bool>()) continue;
      const double pairs = Number(m.measures, "self_intersections");
      const std::string why = Number(m.measures, "watertight_faces") == 0 ? "no closed mesh"
                              : pairs > 0 ? Format("%.0f crossing face pairs", pairs)
                                          : "open or not manifold";
      failed.push_back(r.bench_case.name + " (" + m.method + ", " + why + ")");
    }
  }
  if (checked == 0) return;
  md << "Every mesh.ply of this report was checked as the application checks each export: "
        "closed, edge-manifold, oriented and without faces that cross (`core/mesh_intersections.h`"
        "). ";
  if (failed.empty()) {
    md << "All " << checked << " passed.\n\n";
    return;
  }
  md << failed.size() << " of " << checked << " did not:";
  for (size_t k = 0; k < failed.size(); ++k) md << (k == 0 ? " " : "; ") << failed[k];
  md << ".\n\n";
}

/// Table 2: pairwise registration error per case and method, pooled over the paper sessions.
void ReportWriter::Table2() {
  Table table2;
  table2.header = MethodHeader({"case", "joint err."}, compared);
  for (const CaseResult& r : results) {
    std::vector<std::string> row = {r.bench_case.name, Cell(r.joint_error_mm, "%.1f mm")};
    AppendMethodCells(row, r, compared, [&](const MethodResult& m) {
      const json& j = m.measures;
      if (r.bench_case.paper)
        pooled[m.method].Add(Number(j, "pairwise_error_mm", "mean"),
                             Number(j, "pairwise_error_mm", "std"),
                             Number(j, "pairwise_error_mm", "samples"));
      return PairwiseCell(m);
    });
    table2.rows.push_back(row);
  }
  if (!pooled.empty()) {
    std::vector<std::string> row = {"**paper sessions**", ""};
    for (const auto& name : compared) {
      const Pooled& p = pooled[name];
      row.push_back(p.n > 0 ? "**" + Cell(p.Mean()) + " ± " + Cell(p.Std()) + "**" : "–");
    }
    table2.rows.push_back(row);
  }
  md << "## Table 2: pairwise registration error at the fingertip contacts (mm, mean ± std)\n\n"
     << "For consecutive frames both registered, the object point under each touching fingertip "
        "carried by the scan's relative motion and by the true one (the paper's definition). "
        "(r/f): only r of the f frames registered. Joint err.: the hand tracker's mean 3D joint "
        "error (the same for every method). An error larger than the object means the method "
        "lost it.\n\n"
     << table2.Markdown() << "\n";
}

/// Ratios to the baselines over the paper sessions (when ours has pooled pairwise errors).
void ReportWriter::Ratios() {
  if (pooled.empty() || !(pooled["ours"].n > 0)) return;
  md << "Ratios over the paper sessions (baseline ÷ ours):\n\n| baseline | Table 1 mean abs. "
        "error | Table 2 pairwise error |\n|---|---:|---:|\n";
  const double ours_dim = Mean(abs_errors["ours"]), ours_pair = pooled["ours"].Mean();
  for (const auto& name : compared) {
    if (name == "ours") continue;
    md << "| " << name << " | " << Cell(Mean(abs_errors[name]) / ours_dim, "%.1f×") << " | "
       << Cell(pooled[name].Mean() / ours_pair, "%.1f×") << " |\n";
  }
  md << "\n";
}

/// The surface (Chamfer, completeness), trajectory drift, and speed and memory tables.
void ReportWriter::SurfaceDriftSpeed() {
  Table surface, drift, speed;
  surface.header = drift.header = MethodHeader({"case", "joint err."}, compared);
  speed.header = MethodHeader({"case", "track+mask ms"}, compared, " ms");
  speed.header.push_back("export s (ours)");
  speed.header.push_back("app fps");
  speed.header.push_back("app peak MiB");
  for (const CaseResult& r : results) {
    const std::string joint = Cell(r.joint_error_mm, "%.1f mm");
    std::vector<std::string> su = {r.bench_case.name, joint}, dr = su;
    std::vector<std::string> sp = {r.bench_case.name, Format("%.1f", r.track_ms + r.mask_ms)};
    AppendObjectCells(su, r, compared, [](const MethodResult& m) {
      return Cell(Number(m.measures, "chamfer_mm")) + " / " +
             Cell(100 * Number(m.measures, "completeness"), "%.0f %%");
    });
    AppendMethodCells(dr, r, compared, [](const MethodResult& m) {
      const std::string drift = Cell(Number(m.measures, "trajectory_error_mm", "mean"), "%.1f");
      return LostReason(m) ? drift + " (lost)" : drift;
    });
    AppendMethodCells(sp, r, compared, [](const MethodResult& m) {
      return Format("%.1f", ObjectStageMs(m.measures));
    });
    const MethodResult* ours = Find(r, "ours");
    sp.push_back(ours && ours->ok ? Format("%.1f", Number(ours->measures, "export_ms") / 1000)
                                  : "–");
    sp.push_back(r.app_fps > 0 ? Format("%.1f", r.app_fps) : "–");
    sp.push_back(r.app_peak_mib > 0 ? Format("%.0f", r.app_peak_mib) : "–");
    surface.rows.push_back(su);
    drift.rows.push_back(dr);
    speed.rows.push_back(sp);
  }
  md << "## Surface: Chamfer distance (mm) / completeness (true surface within 2 mm)\n\n"
     << surface.Markdown() << "\n"
     << "## Object trajectory: mean drift (mm; the true object's points where the scan puts "
        "them, both trajectories tied at the first registered frame)\n\n"
     << drift.Markdown() << "\n"
     << "## Speed and memory\n\n"
     << "Per frame on one core, measured in the benchmark's single-threaded pass: the tracker "
        "(shared by all methods), then each method's object stage (SIFT + registration + ICP + "
        "TSDF; open3d: odometry + integration; open3d-f2m: ICP + raycast + integration). Export: "
        "marching cubes + cleanup + smoothing + "
        "Poisson. App: `inhandscan replay` on the same recording, threaded, as fast as it goes, "
        "with its peak resident memory.\n\n"
     << speed.Markdown() << "\n";
}

/// Where ours spends its time, stage by stage.
void ReportWriter::Stages() {
  Table stages;
  stages.header = {"case",     "segmentation", "hand fit", "contacts",  "hand mask", "SIFT",
                   "pairwise", "raycast",      "ICP",      "integrate", "total"};
  const char* stage_keys[] = {"segmentation", "hand_fit", "contacts", "mask",     "features",
                              "pairwise",     "raycast",  "icp",      "integrate"};
  for (const CaseResult& r : results) {
    const MethodResult* ours = Find(r, "ours");
    if (!ours || !ours->ok) continue;
    const json& ms = ours->measures.value("ms_per_frame", json::object());
    std::vector<std::string> row = {r.bench_case.name};
    for (const char* key : stage_keys) row.push_back(Format("%.1f", ms.value(key, 0.0)));
    row.push_back(Format("%.1f", ms.value("track", 0.0) + ms.value("mask", 0.0) +
                                     ms.value("features", 0.0) + ms.value("fusion", 0.0)));
    stages.rows.push_back(row);
  }
  md << "Ours, ms per frame by stage (tracker: segmentation, hand fit, contacts, hand mask; "
        "object: SIFT, pairwise solve, raycast of the model, ICP, TSDF integration):\n\n"
     << stages.Markdown() << "\n";
}

/// The γt sweep: pairwise error per case and γt, as a table, a chart and a CSV.
void ReportWriter::Sweep() {
  Chart sweep_chart;
  sweep_chart.title = "Pairwise registration error vs gamma_t (contact weight)";
  sweep_chart.x_label = "gamma_t";
  sweep_chart.y_label = "mm";
  Table sweep_table;
  sweep_table.header = {"case", "γt →"};
  for (double g : options.sweep) sweep_table.header.push_back(Format("%g", g));
  int series = 0;
  for (const CaseResult& r : results) {
    Series s;
    s.name = r.bench_case.name;
    s.color = PaletteColor(series++);
    s.markers = true;
    std::vector<std::string> row = {r.bench_case.name, "pairwise mm"};
    for (double g : options.sweep) {
      const Method* method = nullptr;
      for (const Method& m : methods)
        if (m.gamma_t == g && m.visual && m.icp) method = &m;
      const MethodResult* m = method ? Find(r, method->name) : nullptr;
      const double e = m && m->ok ? Number(m->measures, "pairwise_error_mm", "mean") : NAN;
      row.push_back(Cell(e));
      if (!std::isfinite(e)) continue;
      s.x.push_back(g);
      s.y.push_back(e);
      sweep_csv.rows.push_back({r.bench_case.name, Format("%g", g), Format("%.3f", e),
                                Cell(Number(m->measures, "pairwise_error_mm", "std"), "%.3f"),
                                Cell(Number(m->measures, "trajectory_error_mm", "mean"), "%.3f")});
    }
    sweep_table.rows.push_back(row);
    sweep_chart.series.push_back(s);
  }
  sweep_chart.log_y = true;
  WriteChartPng(sweep_chart, assets / "gamma_sweep.png");
  md << "## Contact weight γt (the paper's Figure: error vs γt)\n\n"
     << sweep_table.Markdown() << "\n![error vs γt](benchmarks/gamma_sweep.png)\n\n";
}

/// Trajectories and meshes per case.
void ReportWriter::TrajectoriesAndMeshes() {
  md << "## Trajectories and meshes\n\n"
     << "Left: the object's rotation since the first frame, truth (dashed) and each method. "
        "Right: each method's drift over time. Below: every method's watertight mesh beside the "
        "true object, drawn from the same side in the true object's frame.\n\n";
  std::unique_ptr<MeshView> view;
  if (options.mesh_pictures) view = std::make_unique<MeshView>(280);
  for (const CaseResult& r : results) {
    CaseCharts(r);
    if (view) CaseMeshes(r, *view);
  }
}

/// The case's rotation and drift charts, side by side.
void ReportWriter::CaseCharts(const CaseResult& r) {
  Chart angle, error_chart;
  angle.title = r.bench_case.name + ": rotation since the first frame";
  angle.x_label = "time (s)";
  angle.y_label = "degrees";
  error_chart.title = r.bench_case.name + ": drift of the object's trajectory";
  error_chart.x_label = "time (s)";
  error_chart.y_label = "mm";
  error_chart.log_y = true;
  if (!r.truth.empty()) angle.series.push_back(TruthRotation(r.truth));
  int k = 0;
  for (const auto& name : compared) {
    const MethodResult* m = Find(r, name);
    Series a{name, {}, {}, PaletteColor(k), false, false}, d = a;
    ++k;
    if (m && m->ok && !m->trajectory.empty() && !r.truth.empty()) AddMethodTrajectory(r, *m, a, d);
    angle.series.push_back(a);
    error_chart.series.push_back(d);
  }
  const std::string stem = r.bench_case.name;
  WriteChartPng(angle, assets / ("rotation-" + stem + ".png"));
  WriteChartPng(error_chart, assets / ("drift-" + stem + ".png"));
  md << "### " << stem << "\n\n![rotation](benchmarks/rotation-" << stem
     << ".png) ![drift](benchmarks/drift-" << stem << ".png)\n\n";
}

/// Every method's mesh beside the true object, in the true object's frame.
void ReportWriter::CaseMeshes(const CaseResult& r, MeshView& view) {
  const TriangleMesh truth_mesh = ReadMesh(r.gt_dir / "object.ply");
  Eigen::Vector3d low = Eigen::Vector3d::Constant(1e9), high = -low;
  for (const auto& v : truth_mesh.vertices) {
    low = low.cwiseMin(v.cast<double>());
    high = high.cwiseMax(v.cast<double>());
  }
  const Eigen::Vector3d center = 0.5 * (low + high);
  const double radius = 0.5 * (high - low).norm();
  std::vector<Tile> tiles;
  tiles.push_back({"truth", view.Draw(truth_mesh, Rigid3(), center, radius)});
  for (const auto& name : compared) {
    const MethodResult* m = Find(r, name);
    if (!m || !m->ok || m->trajectory.empty()) {
      tiles.push_back({name + ": failed", {}});
      continue;
    }
    const StampedPose* first_truth = eval::FindPose(r.truth, m->trajectory.front().time_s);
    const Rigid3 truth_from_scan =
        first_truth ? first_truth->transform.Inverse() * m->trajectory.front().transform : Rigid3();
    const TriangleMesh& mesh = m->watertight.Empty() ? m->seen : m->watertight;
    tiles.push_back({name, view.Draw(mesh, truth_from_scan, center, radius)});
  }
  const std::string stem = r.bench_case.name;
  WriteTileGridPng(tiles, view.size(), view.size(), static_cast<int>(tiles.size()),
                   assets / ("meshes-" + stem + ".png"));
  md << "![meshes](benchmarks/meshes-" << stem << ".png)\n\n";
}

/// The list of files; writes the CSV files and the Markdown, and returns the Markdown.
std::string ReportWriter::Files() {
  md << "## Files\n\n`benchmarks/results.csv` (every case × method), `benchmarks/full_turns.csv`, "
        "`benchmarks/table1.csv`, `benchmarks/gamma_sweep.csv`.\n";
  turns_csv.Write(assets / "full_turns.csv");
  table1_csv.Write(assets / "table1.csv");
  ResultsCsv(results).Write(assets / "results.csv");
  sweep_csv.Write(assets / "gamma_sweep.csv");
  const std::string text = md.str();
  std::ofstream file(options.out / "benchmarks.md");
  file << text;
  if (!file) throw OutputError((options.out / "benchmarks.md").string() + ": cannot write");
  return text;
}

}  // namespace

std::string WriteReport(const std::vector<CaseResult>& results, const std::vector<Method>& methods,
                        const ReportOptions& options) {
  ReportWriter report(results, methods, options);
  report.Introduction();
  report.FullTurnsTable();
  report.Table1();
  report.Watertight();
  report.Table2();
  report.Ratios();
  report.SurfaceDriftSpeed();
  report.Stages();
  report.Sweep();
  report.TrajectoriesAndMeshes();
  return report.Files();
}

}  // namespace ihs::bench
