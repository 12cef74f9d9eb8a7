#include "fusion/surface_mesh.h"

#include <fcntl.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/surface/poisson.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <numeric>
#include <thread>
#include <vector>

#include "core/check.h"
#include "core/mesh_intersections.h"
#include "core/point_kd_tree.h"
#include "core/stopwatch.h"
#include "fusion/closure_bound.h"
#include "fusion/measure.h"

namespace ihs::fusion {
namespace {

int Root(std::vector<int>& parent, int i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

// The mesh with only the faces whose flag is set, and only the vertices they use.
TriangleMesh KeepFaces(const TriangleMesh& mesh, const std::vector<bool>& keep) {
  TriangleMesh out;
  std::vector<std::int32_t> new_index(mesh.vertices.size(), -1);
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    if (!keep[f]) continue;
    TriangleMesh::Face face;
    for (int c = 0; c < 3; ++c) {
      const std::int32_t v = mesh.faces[f][c];
      if (new_index[v] < 0) {
        new_index[v] = static_cast<std::int32_t>(out.vertices.size());
        out.vertices.push_back(mesh.vertices[v]);
        if (mesh.HasNormals()) out.normals.push_back(mesh.normals[v]);
        if (mesh.HasColors()) out.colors.push_back(mesh.colors[v]);
      }
      face[c] = new_index[v];
    }
    out.faces.push_back(face);
  }
  return out;
}

// Sends what is written to stdout to /dev/null while it lives (PCL's Poisson prints its
// diagnostics with printf). The project writes nothing to stdout while meshing: logs go to
// stderr.
class SilencedStdout {
 public:
  SilencedStdout() {
    std::fflush(stdout);
    saved_ = dup(STDOUT_FILENO);
    const int null = open("/dev/null", O_WRONLY);
    if (saved_ >= 0 && null >= 0) dup2(null, STDOUT_FILENO);
    if (null >= 0) close(null);
  }
  ~SilencedStdout() {
    std::fflush(stdout);
    if (saved_ >= 0) {
      dup2(saved_, STDOUT_FILENO);
      close(saved_);
    }
  }
  SilencedStdout(const SilencedStdout&) = delete;
  SilencedStdout& operator=(const SilencedStdout&) = delete;

 private:
  int saved_ = -1;
};

}  // namespace

void MeshingOptions::Check() const {
  IHS_CHECK_ARG(min_component_fraction >= 0 && min_component_fraction <= 1,
                "meshing.min_component_fraction must be in [0, 1], got " << min_component_fraction);
  IHS_CHECK_ARG(smoothing_iterations >= 0 && smoothing_iterations <= 100,
                "meshing.smoothing_iterations must be in [0, 100], got " << smoothing_iterations);
  IHS_CHECK_ARG(smoothing_alpha >= 0 && smoothing_alpha <= 1,
                "meshing.smoothing_alpha must be in [0, 1], got " << smoothing_alpha);
  IHS_CHECK_ARG(smoothing_beta >= 0 && smoothing_beta <= 1,
                "meshing.smoothing_beta must be in [0, 1], got " << smoothing_beta);
  IHS_CHECK_ARG(poisson_depth >= 5 && poisson_depth <= 12,
                "meshing.poisson_depth must be in [5, 12], got " << poisson_depth);
  IHS_CHECK_ARG(
      poisson_samples_per_node >= 1 && poisson_samples_per_node <= 50,
      "meshing.poisson_samples_per_node must be in [1, 50], got " << poisson_samples_per_node);
  IHS_CHECK_ARG(poisson_scale >= 1 && poisson_scale <= 4,
                "meshing.poisson_scale must be in [1, 4] (below 1 the cube cuts the surface), got "
                    << poisson_scale);
  IHS_CHECK_ARG(
      poisson_threads >= 0 && poisson_threads <= 256,
      "meshing.poisson_threads must be in [0, 256] (0: one per core), got " << poisson_threads);
  IHS_CHECK_ARG(bound_voxel_mm >= 0.25 && bound_voxel_mm <= 20,
                "meshing.bound_voxel_mm must be in [0.25, 20], got " << bound_voxel_mm);
  IHS_CHECK_ARG(bound_keep_seen_mm >= 0 && bound_keep_seen_mm <= 50,
                "meshing.bound_keep_seen_mm must be in [0, 50], got " << bound_keep_seen_mm);
  IHS_CHECK_ARG(
      bound_revolve_max_residual >= 0 && bound_revolve_max_residual <= 1,
      "meshing.bound_revolve_max_residual must be in [0, 1], got " << bound_revolve_max_residual);
  IHS_CHECK_ARG(
      bound_box_min_face_share >= 0 && bound_box_min_face_share <= 1,
      "meshing.bound_box_min_face_share must be in [0, 1], got " << bound_box_min_face_share);
  IHS_CHECK_ARG(
      bound_box_outlier_share >= 0 && bound_box_outlier_share <= 0.05,
      "meshing.bound_box_outlier_share must be in [0, 0.05], got " << bound_box_outlier_share);
}

TriangleMesh RemoveSmallComponents(const TriangleMesh& mesh, double min_fraction) {
  std::vector<int> parent(mesh.vertices.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& face : mesh.faces) {
    const int a = Root(parent, face[0]);
    parent[Root(parent, face[1])] = a;
    parent[Root(parent, face[2])] = a;
  }
  std::vector<int> faces_of(mesh.vertices.size(), 0);
  for (const auto& face : mesh.faces) ++faces_of[Root(parent, face[0])];
  const int largest = faces_of.empty() ? 0 : *std::max_element(faces_of.begin(), faces_of.end());
  std::vector<bool> keep(mesh.faces.size());
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    keep[f] = faces_of[Root(parent, mesh.faces[f][0])] >= min_fraction * largest;
  }
  return KeepFaces(mesh, keep);
}

void SmoothHcLaplacian(TriangleMesh* mesh, int iterations, double alpha, double beta) {
  const size_t n = mesh->vertices.size();
  if (iterations <= 0 || n == 0) return;
  // Vertex neighbourhoods through the faces' edges.
  std::vector<std::vector<std::int32_t>> neighbours(n);
  for (const auto& face : mesh->faces) {
    for (int c = 0; c < 3; ++c) {
      neighbours[face[c]].push_back(face[(c + 1) % 3]);
      neighbours[face[c]].push_back(face[(c + 2) % 3]);
    }
  }
  for (auto& list : neighbours) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  const std::vector<Eigen::Vector3f> original = mesh->vertices;
  std::vector<Eigen::Vector3f>& p = mesh->vertices;
  std::vector<Eigen::Vector3f> q(n), b(n);
  const float a = static_cast<float>(alpha), be = static_cast<float>(beta);
  for (int iteration = 0; iteration < iterations; ++iteration) {
    q = p;
    // Laplacian step, and how far it moved each vertex from a blend of its original and
    // previous positions.
    for (size_t i = 0; i < n; ++i) {
      if (neighbours[i].empty()) {
        b[i].setZero();
        continue;
      }
      Eigen::Vector3f mean = Eigen::Vector3f::Zero();
      for (std::int32_t j : neighbours[i]) mean += q[j];
      p[i] = mean / static_cast<float>(neighbours[i].size());
      b[i] = p[i] - (a * original[i] + (1 - a) * q[i]);
    }
    // Push back by the vertex's own move and its neighbours' mean move.
    for (size_t i = 0; i < n; ++i) {
      if (neighbours[i].empty()) continue;
      Eigen::Vector3f mean = Eigen::Vector3f::Zero();
      for (std::int32_t j : neighbours[i]) mean += b[j];
      mean /= static_cast<float>(neighbours[i].size());
      p[i] -= be * b[i] + (1 - be) * mean;
    }
  }
  mesh->ComputeVertexNormals();
}

int FillHoles(TriangleMesh* mesh) {
  // Directed edges with no opposite twin are the holes' borders; the fill walks them backwards.
  std::map<std::pair<std::int32_t, std::int32_t>, int> directed;
  for (const auto& face : mesh->faces) {
    for (int c = 0; c < 3; ++c) ++directed[{face[c], face[(c + 1) % 3]}];
  }
  std::multimap<std::int32_t, std::int32_t> border;  // a → b for each border edge a→b.
  for (const auto& [edge, count] : directed) {
    if (count == 1 && !directed.count({edge.second, edge.first})) {
      border.emplace(edge.first, edge.second);
    }
  }
  int holes = 0;
  while (!border.empty()) {
    // Follow the border from one edge until it comes back.
    std::vector<std::int32_t> loop;
    auto edge = border.begin();
    const std::int32_t start = edge->first;
    bool closed = false;
    for (std::int32_t at = start;;) {
      loop.push_back(at);
      at = edge->second;
      border.erase(edge);
      if ((closed = at == start)) break;
      edge = border.find(at);
      if (edge == border.end()) break;  // Not a closed loop (a non-manifold border): left.
    }
    if (!closed || loop.size() < 3) continue;
    // A fan around the centroid, each triangle against one border edge.
    const auto centre = static_cast<std::int32_t>(mesh->vertices.size());
    Eigen::Vector3f sum = Eigen::Vector3f::Zero(), normal = Eigen::Vector3f::Zero();
    Eigen::Vector3f rgb = Eigen::Vector3f::Zero();
    for (std::int32_t v : loop) {
      sum += mesh->vertices[v];
      if (mesh->HasNormals()) normal += mesh->normals[v];
      if (mesh->HasColors()) {
        for (int c = 0; c < 3; ++c) rgb[c] += mesh->colors[v][c];
      }
    }
    const float n = static_cast<float>(loop.size());
    mesh->vertices.push_back(sum / n);
    if (mesh->HasNormals()) mesh->normals.push_back(normal.normalized());
    if (mesh->HasColors()) {
      mesh->colors.push_back({static_cast<std::uint8_t>(std::lround(rgb[0] / n)),
                              static_cast<std::uint8_t>(std::lround(rgb[1] / n)),
                              static_cast<std::uint8_t>(std::lround(rgb[2] / n))});
    }
    for (size_t i = 0; i < loop.size(); ++i) {
      mesh->faces.push_back({loop[(i + 1) % loop.size()], loop[i], centre});
    }
    ++holes;
  }
  return holes;
}

namespace {

#if defined(__SANITIZE_THREAD__)
constexpr bool kThreadSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
constexpr bool kThreadSanitizer = true;
#else
constexpr bool kThreadSanitizer = false;
#endif
#else
constexpr bool kThreadSanitizer = false;
#endif

// The threads Poisson's solve gets for `requested` (0: one per core); 1 under ThreadSanitizer,
// which cannot see libgomp's synchronisation.
int PoissonThreads(int requested) {
  if (kThreadSanitizer) return 1;
  if (requested > 0) return requested;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

}  // namespace

TriangleMesh PoissonReconstruct(const TriangleMesh& mesh, int depth, double samples_per_node,
                                double scale, bool color, int threads) {
  constexpr size_t kMinPoints = 16;
  if (mesh.vertices.size() < kMinPoints) return {};
  TriangleMesh oriented = mesh;
  if (!oriented.HasNormals()) oriented.ComputeVertexNormals();

  pcl::PointCloud<pcl::PointNormal>::Ptr cloud(new pcl::PointCloud<pcl::PointNormal>);
  cloud->reserve(oriented.vertices.size());
  for (size_t i = 0; i < oriented.vertices.size(); ++i) {
    const Eigen::Vector3f& n = oriented.normals[i];
    if (!n.allFinite() || n.squaredNorm() < 0.25f) continue;  // Vertices of degenerate faces.
    pcl::PointNormal point;
    point.getVector3fMap() = oriented.vertices[i];
    point.getNormalVector3fMap() = n;
    cloud->push_back(point);
  }
  if (cloud->size() < kMinPoints) return {};

  pcl::Poisson<pcl::PointNormal> poisson;
  poisson.setDepth(depth);
  poisson.setSamplesPerNode(static_cast<float>(samples_per_node));
  poisson.setManifold(true);
  poisson.setScale(static_cast<float>(scale));
  poisson.setThreads(PoissonThreads(threads));
  poisson.setOutputPolygons(false);
  poisson.setInputCloud(cloud);
  pcl::PointCloud<pcl::PointNormal> points;
  std::vector<pcl::Vertices> polygons;
  {
    static std::mutex stdout_mutex;
    const std::lock_guard<std::mutex> lock(stdout_mutex);
    const SilencedStdout silenced;
    poisson.reconstruct(points, polygons);
  }

  TriangleMesh out;
  out.vertices.reserve(points.size());
  for (const auto& point : points) out.vertices.push_back(point.getVector3fMap());
  for (const auto& polygon : polygons) {
    // Triangulated output; anything else is fanned.
    for (size_t c = 2; c < polygon.vertices.size(); ++c) {
      out.faces.push_back({static_cast<std::int32_t>(polygon.vertices[0]),
                           static_cast<std::int32_t>(polygon.vertices[c - 1]),
                           static_cast<std::int32_t>(polygon.vertices[c])});
    }
  }
  // Drop unused vertices, close what PCL left open, and orient the faces outward (positive
  // enclosed volume).
  out = KeepFaces(out, std::vector<bool>(out.faces.size(), true));
  FillHoles(&out);
  if (out.Volume() < 0) {
    for (auto& face : out.faces) std::swap(face[1], face[2]);
  }
  out.ComputeVertexNormals();
  if (color && mesh.HasColors() && !out.Empty()) {
    const PointKdTree tree(mesh.vertices);
    out.colors.resize(out.vertices.size());
    for (size_t i = 0; i < out.vertices.size(); ++i) {
      float distance_sq = 0;
      out.colors[i] = mesh.colors[tree.Nearest(out.vertices[i], &distance_sq)];
    }
  }
  return out;
}

MeshingResult MakeMeshes(const TriangleMesh& raw, const MeshingOptions& options,
                         const FreeSpace* free_space) {
  options.Check();
  MeshingResult result;
  auto start = SteadyClock::now();
  result.smoothed = RemoveSmallComponents(raw, options.min_component_fraction);
  if (!options.color) result.smoothed.colors.clear();
  result.cleanup_ms = MillisecondsSince(start);
  start = SteadyClock::now();
  SmoothHcLaplacian(&result.smoothed, options.smoothing_iterations, options.smoothing_alpha,
                    options.smoothing_beta);
  if (!result.smoothed.HasNormals()) result.smoothed.ComputeVertexNormals();
  result.smoothing_ms = MillisecondsSince(start);
  if (options.poisson) {
    start = SteadyClock::now();
    // Poisson may close off stray bubbles beside the surface: they go like small pieces do.
    result.watertight = RemoveSmallComponents(
        PoissonReconstruct(result.smoothed, options.poisson_depth, options.poisson_samples_per_node,
                           options.poisson_scale, options.color, options.poisson_threads),
        options.min_component_fraction);
    result.poisson_ms = MillisecondsSince(start);
    const bool has_views = free_space != nullptr && free_space->views() > 0;
    if (has_views || options.bound_by_seen_hull) {
      start = SteadyClock::now();
      ClosureBoundOptions bound_options;
      bound_options.voxel_mm = options.bound_voxel_mm;
      bound_options.keep_seen_mm = options.bound_keep_seen_mm;
      bound_options.seen_hull = options.bound_by_seen_hull;
      bound_options.revolve_max_residual = options.bound_revolve_max_residual;
      bound_options.box_min_face_share = options.bound_box_min_face_share;
      bound_options.box_outlier_share = options.bound_box_outlier_share;
      bound_options.min_component_fraction = options.min_component_fraction;
      ClosureBound bound = BoundClosure(result.watertight, result.smoothed,
                                        has_views ? *free_space : FreeSpace(), bound_options);
      result.watertight = std::move(bound.mesh);
      result.cut_share = bound.removed_share;
      result.hull_cut_share = bound.hull_share;
      result.hull_shape = bound.hull_shape;
      result.bound_ms = MillisecondsSince(start);
    }
    result.self_intersections = FindSelfIntersections(result.watertight, 0).pairs;
    if (result.self_intersections > 0 && options.repair_self_intersections) {
      start = SteadyClock::now();
      TriangleMesh remade =
          RemeshClosed(result.watertight, options.bound_voxel_mm, options.min_component_fraction);
      if (remade.IsWatertight() && FindSelfIntersections(remade, 0).pairs == 0) {
        result.repaired_intersections = result.self_intersections;
        result.self_intersections = 0;
        result.watertight = std::move(remade);
      }
      result.repair_ms = MillisecondsSince(start);
    }
    result.unseen_share = UnseenShare(result.watertight, result.smoothed);
  }
  return result;
}

}  // namespace ihs::fusion
