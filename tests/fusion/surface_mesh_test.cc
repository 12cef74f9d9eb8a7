// Meshing: small pieces dropped, HC Laplacian smoothing without shrinkage, Poisson into a
// watertight mesh at the right size, and colours carried through (a rendered two-colour box).

#include "fusion/surface_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "fusion/tsdf_volume.h"
#include "render/offscreen_renderer.h"
#include "tests/frame_fixtures.h"
#include "tests/mesh_fixtures.h"
#include "tests/test_util.h"

namespace ihs::fusion {
namespace {

// Mean and standard deviation of the vertices' distances from `center`.
std::pair<double, double> RadiusStats(const TriangleMesh& mesh,
                                      const Eigen::Vector3f& center = Eigen::Vector3f::Zero()) {
  double sum = 0, sum_sq = 0;
  for (const auto& v : mesh.vertices) {
    const double r = (v - center).cast<double>().norm();
    sum += r, sum_sq += r * r;
  }
  const double n = static_cast<double>(mesh.vertices.size());
  return {sum / n, std::sqrt(std::max(0.0, sum_sq / n - (sum / n) * (sum / n)))};
}

void Append(const TriangleMesh& part, TriangleMesh* mesh) {
  const auto offset = static_cast<std::int32_t>(mesh->vertices.size());
  mesh->vertices.insert(mesh->vertices.end(), part.vertices.begin(), part.vertices.end());
  mesh->normals.insert(mesh->normals.end(), part.normals.begin(), part.normals.end());
  for (auto face : part.faces) {
    for (auto& index : face) index += offset;
    mesh->faces.push_back(face);
  }
}

TEST(SurfaceMeshTest, SmallPiecesAreDroppedAndTheRestKeptWhole) {
  TriangleMesh mesh = test::MakeUvSphere(35, 24, 48);
  const size_t sphere_faces = mesh.faces.size();
  Append(test::MakeUvSphere(2, 4, 6, {80, 0, 0}), &mesh);
  Append(test::MakeCube(3), &mesh);
  const TriangleMesh kept = RemoveSmallComponents(mesh, 0.05);
  EXPECT_EQ(kept.faces.size(), sphere_faces);
  EXPECT_EQ(kept.vertices.size(), test::MakeUvSphere(35, 24, 48).vertices.size());
  EXPECT_TRUE(kept.IsWatertight());
  EXPECT_NEAR(RadiusStats(kept).first, 35.0, 1e-3);
  // A threshold of zero keeps everything.
  EXPECT_EQ(RemoveSmallComponents(mesh, 0.0).faces.size(), mesh.faces.size());
}

TEST(SurfaceMeshTest, HcLaplacianSmoothsNoiseWithoutShrinking) {
  TriangleMesh mesh = test::MakeUvSphere(35, 48, 96);
  std::mt19937 random(test::Seed());
  std::normal_distribution<float> noise(0.0f, 0.4f);
  for (auto& v : mesh.vertices) v *= 1 + noise(random) / 35;
  const auto [mean_before, spread_before] = RadiusStats(mesh);
  TriangleMesh plain = mesh;
  SmoothHcLaplacian(&mesh, 3, 0.0, 0.5);
  const auto [mean_after, spread_after] = RadiusStats(mesh);
  EXPECT_LT(spread_after, 0.5 * spread_before);
  EXPECT_NEAR(mean_after, 35.0, 0.15);
  EXPECT_TRUE(mesh.IsWatertight());
  // Plain Laplacian averaging, for comparison, does shrink the sphere.
  for (int iteration = 0; iteration < 3; ++iteration) {
    std::vector<Eigen::Vector3f> next = plain.vertices;
    std::vector<int> count(plain.vertices.size(), 0);
    for (auto& v : next) v.setZero();
    for (const auto& face : plain.faces) {
      for (int c = 0; c < 3; ++c) {
        next[face[c]] += plain.vertices[face[(c + 1) % 3]] + plain.vertices[face[(c + 2) % 3]];
        count[face[c]] += 2;
      }
    }
    for (size_t i = 0; i < next.size(); ++i) plain.vertices[i] = next[i] / count[i];
  }
  EXPECT_LT(RadiusStats(plain).first, mean_after - 0.05);
}

TEST(SurfaceMeshTest, HolesAreClosedIntoAWatertightMesh) {
  TriangleMesh mesh = test::MakeUvSphere(35, 24, 48);
  // Three holes: one face, two adjacent faces, and a face far from both.
  for (size_t f : {400u, 301u, 300u, 100u}) mesh.faces.erase(mesh.faces.begin() + f);
  ASSERT_FALSE(mesh.IsWatertight());
  mesh.colors.assign(mesh.vertices.size(), {10, 20, 30});
  const size_t faces = mesh.faces.size();
  EXPECT_EQ(FillHoles(&mesh), 3);
  EXPECT_TRUE(mesh.IsWatertight());
  EXPECT_EQ(mesh.faces.size(), faces + 3 + 4 + 3);  // A fan of one face per border edge.
  EXPECT_EQ(mesh.colors.back(), (TriangleMesh::Color{10, 20, 30}));
  mesh.Check();
  EXPECT_EQ(FillHoles(&mesh), 0);
}

TEST(SurfaceMeshTest, PoissonClosesAnOpenSurfaceNearItsPoints) {
  const TriangleMesh sphere = test::MakeUvSphere(35, 48, 96);
  // Cut off the cap above z = 25 mm: a hole of about 50 mm across.
  std::vector<bool> keep(sphere.faces.size());
  TriangleMesh open;
  open.vertices = sphere.vertices;
  open.normals = sphere.normals;
  for (const auto& face : sphere.faces) {
    bool below = true;
    for (int c = 0; c < 3; ++c) below = below && sphere.vertices[face[c]].z() < 25;
    if (below) open.faces.push_back(face);
  }
  ASSERT_FALSE(open.IsWatertight());
  const TriangleMesh closed = PoissonReconstruct(open, 8, 2.0, 1.5, false);
  ASSERT_GT(closed.faces.size(), 1000u);
  EXPECT_TRUE(closed.IsWatertight());
  EXPECT_GT(closed.Volume(), 0);  // Outward faces.
  // Where there were points, the surface is on them.
  int near = 0, counted = 0;
  for (const auto& v : closed.vertices) {
    if (v.z() > 20) continue;
    ++counted;
    near += std::abs(v.norm() - 35) < 0.5;
  }
  EXPECT_GT(near, 0.98 * counted);
  // On two threads the solve closes the same surface (its volume to within a thousandth).
  const TriangleMesh threaded = PoissonReconstruct(open, 8, 2.0, 1.5, false, 2);
  EXPECT_TRUE(threaded.IsWatertight());
  EXPECT_NEAR(threaded.Volume(), closed.Volume(), 1e-3 * closed.Volume());

  // The export says how much of its watertight mesh is made up: Poisson's cap beyond the seen rim
  // (the smoothed surface's highest point, a little below 25 mm) less the 2 mm band along it.
  MeshingOptions poisson_cap;
  poisson_cap.bound_by_seen_hull = false;
  const MeshingResult meshes = MakeMeshes(open, poisson_cap);
  ASSERT_TRUE(meshes.watertight.IsWatertight());
  float rim_z = -35;
  for (const auto& v : meshes.smoothed.vertices) rim_z = std::max(rim_z, v.z());
  ASSERT_GT(rim_z, 22);
  ASSERT_LT(rim_z, 25);
  // Polar angle where the band ends (2 mm along the sphere from the rim); a cap's share of a
  // sphere's area is (1 - cos θ) / 2.
  const double band_end = std::acos(rim_z / 35.0) - 2.0 / 35;
  EXPECT_NEAR(meshes.unseen_share, (1 - std::cos(band_end)) / 2, 0.01);
  EXPECT_EQ(meshes.cut_share, 0);

  // By default the cap is cut flat at the rim's plane (the seen surface's convex hull; a sphere
  // seen in part is a body of revolution about the cap's axis), within the lattice's rounding.
  const MeshingResult flat = MakeMeshes(open);
  ASSERT_TRUE(flat.IsWatertight());
  float top = -35;
  for (const auto& v : flat.watertight.vertices) top = std::max(top, v.z());
  EXPECT_LT(top, rim_z + 1.5f);
  EXPECT_EQ(flat.hull_shape, HullShape::kRevolved);
  EXPECT_GT(flat.cut_share, 0.01);
  EXPECT_NEAR(flat.hull_cut_share, flat.cut_share, 0.01);
}

TEST(SurfaceMeshTest, ATsdfSphereGivesAWatertightMeshOfItsSize) {
  const CameraIntrinsics intrinsics = CameraIntrinsics::Carmine109();
  TsdfVolume volume;
  for (const Rigid3& view : test::ViewsAround(600)) {
    volume.Integrate(test::RenderEllipsoid(intrinsics, view, Eigen::Vector3d::Constant(35)), {},
                     intrinsics, view);
  }
  const MeshingResult meshes = MakeMeshes(volume.ExtractMesh());
  ASSERT_TRUE(meshes.watertight.IsWatertight());
  const auto [radius, spread] = RadiusStats(meshes.watertight);
  EXPECT_NEAR(radius, 35.0, 0.5);
  EXPECT_LT(spread, 0.5);
  const double volume_true = 4.0 / 3.0 * M_PI * 35 * 35 * 35;
  EXPECT_NEAR(meshes.watertight.Volume() / volume_true, 1.0, 0.02);
  EXPECT_LT(meshes.unseen_share, 0.01);  // Seen from all around.
  EXPECT_TRUE(meshes.watertight.HasColors());
  EXPECT_NEAR(RadiusStats(meshes.smoothed).first, 35.0, 0.5);
  std::printf(
      "poisson: %zu faces, radius %.3f ± %.3f mm, %.0f ms (cleanup %.0f, smoothing %.0f), unseen "
      "%.4f\n",
      meshes.watertight.faces.size(), radius, spread, meshes.poisson_ms, meshes.cleanup_ms,
      meshes.smoothing_ms, meshes.unseen_share);
}

// A box of half-extents `half` whose x > 0 half is red and whose x < 0 half is blue: each face
// a 4×4 grid of cells with their own vertices and one colour per triangle, so no triangle
// straddles the seam and no colour blends across it.
TriangleMesh TwoColourBox(const Eigen::Vector3f& half) {
  constexpr int kCells = 4;
  TriangleMesh box;
  for (int axis = 0; axis < 3; ++axis) {
    for (float sign : {-1.0f, 1.0f}) {
      const int a = (axis + 1) % 3, b = (axis + 2) % 3;
      auto corner = [&](int i, int j) -> Eigen::Vector3f {
        Eigen::Vector3f p;
        p[axis] = sign * half[axis];
        p[a] = half[a] * (2.0f * i / kCells - 1);
        p[b] = half[b] * (2.0f * j / kCells - 1);
        return p;
      };
      for (int i = 0; i < kCells; ++i) {
        for (int j = 0; j < kCells; ++j) {
          const Eigen::Vector3f quad[4] = {corner(i, j), corner(i + 1, j), corner(i + 1, j + 1),
                                           corner(i, j + 1)};
          for (const auto& tri : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
            Eigen::Vector3f p[3] = {quad[tri[0]], quad[tri[1]], quad[tri[2]]};
            if ((p[1] - p[0]).cross(p[2] - p[0])[axis] * sign < 0) std::swap(p[1], p[2]);
            const Eigen::Vector3f centre = (p[0] + p[1] + p[2]) / 3;
            const TriangleMesh::Color color = centre.x() > 0 ? TriangleMesh::Color{220, 30, 30}
                                                             : TriangleMesh::Color{30, 30, 220};
            const auto base = static_cast<std::int32_t>(box.vertices.size());
            for (const auto& v : p) {
              box.vertices.push_back(v);
              box.colors.push_back(color);
            }
            box.faces.push_back({base, base + 1, base + 2});
          }
        }
      }
    }
  }
  box.ComputeVertexNormals();
  return box;
}

TEST(SurfaceMeshTest, ARenderedTwoColourBoxKeepsItsColoursInTheExportedMesh) {
  const CameraIntrinsics intrinsics = CameraIntrinsics::Carmine109();
  const Eigen::Vector3f half(40, 30, 25);
  const TriangleMesh box = TwoColourBox(half);
  render::OffscreenRenderer renderer(intrinsics);
  TsdfVolume volume;
  for (const Rigid3& view : test::ViewsAround(600)) {
    render::RenderItem item;
    item.mesh = &box;
    item.cam_from_mesh = view;
    item.use_vertex_colors = true;
    const render::RenderOutput image = renderer.Render({item});
    Frame frame = Frame::Blank(image.width, image.height);
    frame.depth_mm = image.DepthMillimetres();
    frame.rgb = image.rgb;
    volume.Integrate(frame, {}, intrinsics, view);
  }
  const MeshingResult meshes = MakeMeshes(volume.ExtractMesh());
  for (const TriangleMesh* mesh : {&meshes.smoothed, &meshes.watertight}) {
    ASSERT_TRUE(mesh->HasColors());
    int right = 0, counted = 0;
    for (size_t i = 0; i < mesh->vertices.size(); ++i) {
      const Eigen::Vector3f& v = mesh->vertices[i];
      // Away from the x = 0 seam, where the two colours meet.
      if (std::abs(v.x()) < 5) continue;
      ++counted;
      const auto& rgb = mesh->colors[i];
      right += v.x() > 0 ? rgb[0] > rgb[2] + 60 : rgb[2] > rgb[0] + 60;
    }
    ASSERT_GT(counted, 500);
    EXPECT_GT(right, 0.97 * counted);
  }
  EXPECT_TRUE(meshes.watertight.IsWatertight());
  // Each face where it belongs (the median over the vertices facing along its axis; corners
  // and edges of a TSDF are rounded, so the bounds would not do).
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<float> offsets;
    for (size_t i = 0; i < meshes.smoothed.vertices.size(); ++i) {
      if (std::abs(meshes.smoothed.normals[i][axis]) > 0.95f) {
        offsets.push_back(std::abs(meshes.smoothed.vertices[i][axis]));
      }
    }
    ASSERT_GT(offsets.size(), 50u);
    std::nth_element(offsets.begin(), offsets.begin() + offsets.size() / 2, offsets.end());
    EXPECT_NEAR(offsets[offsets.size() / 2], half[axis], 0.5) << "axis " << axis;
  }
}

}  // namespace
}  // namespace ihs::fusion
