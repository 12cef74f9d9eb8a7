// A closure that balloons past what the views saw is cut back to the space they did not see
// empty, and one that bulges past the seen surface's convex hull back to the hull; one that
// stays inside both is left as it is.

#include "fusion/closure_bound.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <utility>
#include <vector>

#include "core/mesh_intersections.h"
#include "fusion/convex_hull.h"
#include "fusion/surface_mesh.h"
#include "tests/free_space_fixtures.h"
#include "tests/mesh_fixtures.h"

namespace ihs::fusion {
namespace {

using test::kCubeEdgeMm;

// The views' evidence alone (the hull off), keeping `keep_seen_mm` around the seen surface.
ClosureBoundOptions FreeSpaceOnly(double keep_seen_mm = 2.0) {
  ClosureBoundOptions options;
  options.keep_seen_mm = keep_seen_mm;
  options.seen_hull = false;
  return options;
}

// Views of the cube from a ring of directions about y, 30° apart, and from above and below.
FreeSpace RingOfViews() {
  const CameraIntrinsics camera = CameraIntrinsics::Carmine109();
  FreeSpace free_space(camera);
  auto observe = [&](const Rigid3& cube_turn) {
    const Rigid3 pose = Rigid3::Translation({0, 0, 450}) * cube_turn;
    const test::RenderedView view = test::CubeView(camera, pose);
    free_space.Observe(view.frame, view.object_box, pose);
  };
  for (int step = 0; step < 12; ++step) {
    observe(Rigid3::FromAxisAngle({0, 1, 0}, (step * 30 + 15) * M_PI / 180));
  }
  observe(Rigid3::FromAxisAngle({1, 0, 0}, M_PI / 2));
  observe(Rigid3::FromAxisAngle({1, 0, 0}, M_PI / 2 + 0.2));
  observe(Rigid3::FromAxisAngle({1, 0, 0}, -M_PI / 2));
  observe(Rigid3::FromAxisAngle({1, 0, 0}, -M_PI / 2 - 0.2));
  return free_space;
}

TEST(ClosureBoundTest, ABalloonThroughSpaceTheViewsSawEmptyIsCutBackToIt) {
  const FreeSpace free_space = RingOfViews();
  ASSERT_EQ(free_space.views(), 16);
  // Poisson's guess: a ball round the cube, 15 % past its corners, 4.2 times its volume.
  const TriangleMesh balloon = test::MakeUvSphere(kCubeEdgeMm, 32, 64);
  const TriangleMesh seen = test::MakeCube(kCubeEdgeMm);
  const ClosureBound bound = BoundClosure(balloon, seen, free_space, FreeSpaceOnly());
  ASSERT_TRUE(bound.changed);
  const TriangleMesh& mesh = bound.mesh;
  EXPECT_TRUE(mesh.IsWatertight());
  EXPECT_EQ(FindSelfIntersections(mesh, 0).pairs, 0);
  // What is left: the cube grown by the margin (5.5 mm) along the views' rays, and cut off the
  // corners where their silhouettes pass (1.63 times the cube when written).
  const double cube = std::pow(kCubeEdgeMm, 3);
  EXPECT_GT(mesh.Volume(), 0.9 * cube);
  EXPECT_LT(mesh.Volume(), 1.9 * cube);
  EXPECT_GT(bound.removed_share, 0.5);
  EXPECT_NEAR(bound.removed_share, 1 - mesh.Volume() / balloon.Volume(), 1e-9);
  // The ball reached 20 mm past the faces; what is left stays within 10 mm of them. Past the
  // margin it is thin fins along the edges where the ring's views graze the top and bottom
  // faces: as many views saw a surface there as saw through, and a tie is not empty.
  const float reach = kCubeEdgeMm / 2 + 10.0f;
  for (const auto& v : mesh.vertices) {
    ASSERT_LE(v.cwiseAbs().maxCoeff(), reach) << v.transpose();
    // Nothing left where the views saw empty space: a vertex lies within the lattice's step
    // (1 mm, along an axis: marching cubes puts it on a lattice edge) of a point they did not
    // see empty (a silhouette's edge, or a tie half a millimetre thick, falls between points).
    float least = free_space.Emptiness(v, 3);
    for (int axis = 0; axis < 3; ++axis) {
      for (float step : {-1.0f, -0.75f, -0.5f, -0.25f, 0.25f, 0.5f, 0.75f, 1.0f}) {
        Eigen::Vector3f moved = v;
        moved[axis] += step;
        least = std::min(least, free_space.Emptiness(moved, 3));
      }
    }
    ASSERT_LE(least, 0.0f) << v.transpose();
  }
  // Colours of the closed mesh carried over.
  TriangleMesh coloured = balloon;
  coloured.colors.assign(coloured.vertices.size(), {10, 200, 30});
  const ClosureBound with_colour = BoundClosure(coloured, seen, free_space, FreeSpaceOnly());
  ASSERT_TRUE(with_colour.mesh.HasColors());
  EXPECT_EQ(with_colour.mesh.colors.front(), (TriangleMesh::Color{10, 200, 30}));
}

TEST(ClosureBoundTest, TheSeenSurfaceIsNeverCut) {
  // A seen ball 10 mm wider than the cube the views saw (they were misregistered): the views
  // saw space empty around its poles and equator, but nothing within `keep_seen_mm` of it goes.
  const FreeSpace free_space = RingOfViews();
  const TriangleMesh big = test::MakeCube(kCubeEdgeMm + 30);
  const float radius = kCubeEdgeMm / 2 + 10;
  const TriangleMesh seen = test::MakeUvSphere(radius, 48, 96);
  const ClosureBound kept = BoundClosure(big, seen, free_space, FreeSpaceOnly(3.0));
  ASSERT_TRUE(kept.changed);
  Eigen::Vector3f reach = Eigen::Vector3f::Zero();
  for (const auto& v : kept.mesh.vertices) reach = reach.cwiseMax(v.cwiseAbs());
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_GT(reach[axis], radius - 0.5f) << axis;  // The ball's extent stays.
    EXPECT_LT(reach[axis], radius + 3.5f) << axis;  // The big cube's does not.
  }
}

TEST(ClosureBoundTest, AClosureInsideWhatWasNotSeenEmptyIsLeftAsItIs) {
  const FreeSpace free_space = RingOfViews();
  const TriangleMesh inside = test::MakeUvSphere(kCubeEdgeMm * 0.45f, 16, 32);
  const TriangleMesh seen = test::MakeCube(kCubeEdgeMm);
  const ClosureBound bound = BoundClosure(inside, seen, free_space, {});
  EXPECT_FALSE(bound.changed);
  EXPECT_EQ(bound.removed_share, 0);
  EXPECT_EQ(bound.mesh.vertices, inside.vertices);
  EXPECT_FALSE(BoundClosure(inside, seen, FreeSpace(), {}).changed);
}

// The profile of a body of revolution about z from z = 0 to `height` (radius `radius(z)`, 1 mm
// apart), with a bulge of `bulge_mm` past each end (an ellipsoidal cap: Poisson's guess over an
// unseen base) when `bulge_mm` > 0; open at both ends otherwise.
template <typename Radius>
std::vector<std::pair<float, float>> Profile(float height, Radius radius, float bulge_mm) {
  std::vector<std::pair<float, float>> profile;
  auto cap = [&](float end, float sign) {
    for (int step = 10; step > 0; --step) {
      const float t = step / 10.0f;  // 1 at the pole, 0 at the rim.
      profile.emplace_back(end + sign * bulge_mm * t, radius(end) * std::sqrt(1 - t * t));
    }
  };
  if (bulge_mm > 0) cap(0, -1);
  for (int z = 0; z <= static_cast<int>(height); ++z) {
    profile.emplace_back(static_cast<float>(z), radius(static_cast<float>(z)));
  }
  if (bulge_mm > 0) {
    const size_t top = profile.size();
    cap(height, 1);
    std::reverse(profile.begin() + top, profile.end());
  }
  return profile;
}

TEST(ClosureBoundTest, ABulgePastTheSeenRimIsCutFlatAtTheRimsPlane) {
  // A bottle's side seen, its base and top never: Poisson bulged 15 mm past both rims, where no
  // view looked (no views here at all).
  auto cylinder = [](float) { return 30.0f; };
  const TriangleMesh seen = test::MakeLathe(Profile(80, cylinder, 0), 64);
  const TriangleMesh bulging = test::MakeLathe(Profile(80, cylinder, 15), 64);
  ASSERT_TRUE(bulging.IsWatertight());
  const ClosureBound bound = BoundClosure(bulging, seen, FreeSpace(), {});
  ASSERT_TRUE(bound.changed);
  const TriangleMesh& mesh = bound.mesh;
  EXPECT_TRUE(mesh.IsWatertight());
  EXPECT_EQ(FindSelfIntersections(mesh, 0).pairs, 0);
  EXPECT_GE(bound.hull_planes, 4);
  EXPECT_EQ(bound.hull_shape, HullShape::kRevolved);  // A body of revolution.
  // Flat at the rims' planes: nothing past them by more than 1.5 mm (the seen surface is inside
  // its hull: the cut comes right to the rims), and the caps' middles on them.
  int on_caps = 0;
  for (const auto& v : mesh.vertices) {
    ASSERT_GT(v.z(), -1.5f) << v.transpose();
    ASSERT_LT(v.z(), 81.5f) << v.transpose();
    if (v.head<2>().norm() > 26) continue;
    ++on_caps;
    ASSERT_LT(std::min(std::abs(v.z()), std::abs(v.z() - 80)), 1.0f) << v.transpose();
  }
  EXPECT_GT(on_caps, 1000);
  // The cylinder's volume (the 64-gon's), within what the 1 mm lattice and the kept rims give.
  const double cylinder_volume = 0.5 * 64 * 30 * 30 * std::sin(2 * M_PI / 64) * 80;
  EXPECT_NEAR(mesh.Volume(), cylinder_volume, 0.02 * cylinder_volume);
  EXPECT_NEAR(bound.removed_share, 1 - mesh.Volume() / bulging.Volume(), 1e-9);
  EXPECT_NEAR(bound.hull_share, bound.removed_share, 0.03);

  // Off: no views, no hull, nothing cut; the bulge stays.
  ClosureBoundOptions off;
  off.seen_hull = false;
  const ClosureBound kept = BoundClosure(bulging, seen, FreeSpace(), off);
  EXPECT_FALSE(kept.changed);
  EXPECT_EQ(kept.hull_planes, 0);
  EXPECT_EQ(kept.mesh.vertices, bulging.vertices);
}

// `mesh` without the faces whose centroid lies within `half_angle` (radians) of the +x axis,
// seen from z: a body of revolution's side with an unseen stretch.
TriangleMesh WithoutStretch(const TriangleMesh& mesh, double half_angle) {
  TriangleMesh out = mesh;
  out.faces.clear();
  for (const auto& face : mesh.faces) {
    const Eigen::Vector3f centroid =
        (mesh.vertices[face[0]] + mesh.vertices[face[1]] + mesh.vertices[face[2]]) / 3;
    if (std::abs(std::atan2(centroid.y(), centroid.x())) > half_angle) out.faces.push_back(face);
  }
  return RemoveSmallComponents(out, 0);  // Without the vertices left unused.
}

// A box of edge `edge_mm` centred at the origin, each side a grid of `cells` × `cells` squares
// (a scan's box has vertices all over its sides, not only at its corners).
// A cube's faces (`faces`: bit 2·axis for the face at −edge/2 along that axis, bit 2·axis + 1
// for the one at +edge/2; all six by default), a grid of `cells` × `cells` squares each.
TriangleMesh GridBox(float edge_mm, int cells, int faces = 0x3f) {
  TriangleMesh box;
  for (int axis = 0; axis < 3; ++axis) {
    for (const float sign : {-1.0f, 1.0f}) {
      if (!(faces & (1 << (2 * axis + (sign > 0 ? 1 : 0))))) continue;
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const auto first = static_cast<std::int32_t>(box.vertices.size());
      for (int j = 0; j <= cells; ++j) {
        for (int i = 0; i <= cells; ++i) {
          Eigen::Vector3f p;
          p[axis] = sign * edge_mm / 2;
          p[u] = edge_mm * (static_cast<float>(i) / cells - 0.5f);
          p[v] = edge_mm * (static_cast<float>(j) / cells - 0.5f);
          box.vertices.push_back(p);
        }
      }
      for (int j = 0; j < cells; ++j) {
        for (int i = 0; i < cells; ++i) {
          const std::int32_t a = first + j * (cells + 1) + i, b = a + 1, c = a + cells + 1;
          box.faces.push_back({a, b, c});  // Orientation does not matter to the hull.
          box.faces.push_back({b, c + 1, c});
        }
      }
    }
  }
  return box;
}

TEST(ClosureBoundTest, TheUnseenSideOfARoundObjectIsLeftToTheClosure) {
  // A cylinder's side seen over 240° (120° round +x never turned to the camera), its ends never:
  // the hull of its revolution cuts the ends flat and leaves Poisson's round side; the plain
  // hull would cut that side along the chord across the unseen stretch, about 15 mm from the
  // axis.
  auto cylinder = [](float) { return 30.0f; };
  const TriangleMesh seen = WithoutStretch(test::MakeLathe(Profile(80, cylinder, 0), 64), M_PI / 3);
  const TriangleMesh bulging = test::MakeLathe(Profile(80, cylinder, 15), 64);
  const ClosureBound bound = BoundClosure(bulging, seen, FreeSpace(), {});
  ASSERT_TRUE(bound.changed);
  EXPECT_EQ(bound.hull_shape, HullShape::kRevolved);
  float reach_x = 0;
  for (const auto& v : bound.mesh.vertices) {
    ASSERT_GT(v.z(), -1.5f) << v.transpose();
    ASSERT_LT(v.z(), 81.5f) << v.transpose();
    reach_x = std::max(reach_x, v.x());
  }
  EXPECT_GT(reach_x, 29.0f);

  ClosureBoundOptions plain;
  plain.revolve_max_residual = 0;
  const ClosureBound chord = BoundClosure(bulging, seen, FreeSpace(), plain);
  ASSERT_TRUE(chord.changed);
  EXPECT_NE(chord.hull_shape, HullShape::kRevolved);
  reach_x = 0;
  for (const auto& v : chord.mesh.vertices) reach_x = std::max(reach_x, v.x());
  EXPECT_LT(reach_x, 18.0f);  // The chord: 15 mm, or 16.7 where a face half in the stretch stays.
  EXPECT_LT(chord.mesh.Volume(), 0.95 * bound.mesh.Volume());
}

TEST(ClosureBoundTest, ABoxIsNotRoundAndGetsItsBox) {
  // A box seen whole inside a ball 20 mm past its corners: cut back to the box itself.
  const TriangleMesh seen = GridBox(40, 20);
  const ClosureBound bound = BoundClosure(test::MakeUvSphere(55, 32, 64), seen, FreeSpace(), {});
  ASSERT_TRUE(bound.changed);
  EXPECT_EQ(bound.hull_shape, HullShape::kBox);
  EXPECT_EQ(bound.hull_planes, 6);
  for (const auto& v : bound.mesh.vertices) ASSERT_LT(v.cwiseAbs().maxCoeff(), 21.0f);
  EXPECT_NEAR(bound.mesh.Volume(), 40.0 * 40 * 40, 0.03 * 40 * 40 * 40);
}

TEST(ClosureBoundTest, ABoxSeenFromOneSideKeepsTheCornerBehindIt) {
  // Two faces of a turned 40 mm cube seen (its front and its top, sharing an edge), inside a
  // ball as Poisson's guess. The plain hull of what was seen is the prism between the two faces'
  // far edges: half the cube. The box along the faces is the whole cube.
  const Eigen::Matrix3f turn =
      Eigen::AngleAxisf(0.7f, Eigen::Vector3f(1, 2, 0.5).normalized()).toRotationMatrix();
  TriangleMesh seen = GridBox(40, 20, (1 << 5) | (1 << 3));
  for (auto& v : seen.vertices) v = turn * v;
  const TriangleMesh ball = test::MakeUvSphere(55, 32, 64);
  const ClosureBound box = BoundClosure(ball, seen, FreeSpace(), {});
  ClosureBoundOptions plain;
  plain.box_min_face_share = 0;
  const ClosureBound hull = BoundClosure(ball, seen, FreeSpace(), plain);
  std::printf("two faces of a 64 000 mm³ cube: %.0f mm³ in their box, %.0f in their hull\n",
              box.mesh.Volume(), hull.mesh.Volume());
  ASSERT_TRUE(box.changed && hull.changed);
  EXPECT_EQ(box.hull_shape, HullShape::kBox);
  EXPECT_EQ(hull.hull_shape, HullShape::kSeen);
  EXPECT_NEAR(box.mesh.Volume(), 40.0 * 40 * 40, 0.04 * 40 * 40 * 40);
  EXPECT_NEAR(hull.mesh.Volume(), 0.5 * 40 * 40 * 40, 0.04 * 40 * 40 * 40);
  for (const auto& v : box.mesh.vertices)
    ASSERT_LT((turn.transpose() * v).cwiseAbs().maxCoeff(), 21.0f);
}

TEST(ClosureBoundTest, ABlobProudOfABoxsFaceIsCutBackToTheFace) {
  // A 40 mm cube seen all round, with a 3 x 3 vertex blob 5 mm proud of its +x face (a piece of
  // the hand fused with it), inside a ball as Poisson's guess. The box that holds every seen
  // vertex holds the blob; leaving out half a percent of them beyond each face, it ends at the
  // face.
  TriangleMesh seen = GridBox(40, 20);
  const auto first = static_cast<std::int32_t>(seen.vertices.size());
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) seen.vertices.emplace_back(25.0f, 2.0f * i, 2.0f * j);
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 2; ++i) {
      const std::int32_t a = first + 3 * j + i;
      seen.faces.push_back({a, a + 1, a + 3});
      seen.faces.push_back({a + 1, a + 4, a + 3});
    }
  }
  const TriangleMesh ball = test::MakeUvSphere(55, 32, 64);
  ClosureBoundOptions all;
  all.box_outlier_share = 0;
  const ClosureBound every = BoundClosure(ball, seen, FreeSpace(), all);
  const ClosureBound face = BoundClosure(ball, seen, FreeSpace(), {});  // Half a percent.
  EXPECT_EQ(ClosureBoundOptions().box_outlier_share, 0.005);
  ASSERT_TRUE(every.changed && face.changed);
  EXPECT_EQ(face.hull_shape, HullShape::kBox);
  float every_x = -INFINITY, face_x = -INFINITY;
  for (const auto& v : every.mesh.vertices) every_x = std::max(every_x, v.x());
  for (const auto& v : face.mesh.vertices) face_x = std::max(face_x, v.x());
  EXPECT_GT(every_x, 24.0f);
  EXPECT_LT(face_x, 21.0f);
  EXPECT_NEAR(face.mesh.Volume(), 40.0 * 40 * 40, 0.04 * 40 * 40 * 40);
}

TEST(ClosureBoundTest, AConcaveSeenSurfaceIsInsideItsHullAndStays) {
  // A bowling pin's neck, seen all round: 30 mm wide at the ends, 18 mm at the waist. The
  // closure over its unseen ends bulges and is cut; the neck, inside the hull, is not.
  auto neck = [](float z) { return 30.0f - 12.0f * static_cast<float>(std::sin(M_PI * z / 80)); };
  const TriangleMesh seen = test::MakeLathe(Profile(80, neck, 0), 64);
  const TriangleMesh bulging = test::MakeLathe(Profile(80, neck, 15), 64);
  const ClosureBound bound = BoundClosure(bulging, seen, FreeSpace(), {});
  ASSERT_TRUE(bound.changed);
  EXPECT_TRUE(bound.mesh.IsWatertight());
  float lowest = 0;
  for (const auto& v : bound.mesh.vertices) {
    lowest = std::min(lowest, v.z());  // The end is cut flat at the rim.
    if (v.z() < 10 || v.z() > 70) continue;
    // On the seen surface within the lattice's rounding (and the 64-gon's chords).
    ASSERT_NEAR(v.head<2>().norm(), neck(v.z()), 0.6f) << v.transpose();
  }
  EXPECT_GT(lowest, -1.5f);

  // A closure that is the seen surface with flat ends (nothing past the hull) is left as it is.
  std::vector<std::pair<float, float>> flat = Profile(80, neck, 0);
  flat.insert(flat.begin(), {0.0f, 0.0f});
  flat.emplace_back(80.0f, 0.0f);
  const TriangleMesh closed = test::MakeLathe(flat, 64);
  ASSERT_TRUE(closed.IsWatertight());
  const ClosureBound unchanged = BoundClosure(closed, seen, FreeSpace(), {});
  EXPECT_FALSE(unchanged.changed);
  EXPECT_EQ(unchanged.mesh.vertices, closed.vertices);
}

TEST(ClosureBoundTest, ASeenSurfaceWithoutVolumeHasNoHull) {
  // A flat patch (one face of a box seen head on) spans no volume: no hull, nothing cut.
  TriangleMesh patch;
  patch.vertices = {{0, 0, 0}, {40, 0, 0}, {40, 40, 0}, {0, 40, 0}};
  patch.faces = {{0, 1, 2}, {0, 2, 3}};
  const TriangleMesh ball = test::MakeUvSphere(30, 16, 32, {20, 20, 0});
  const ClosureBound bound = BoundClosure(ball, patch, FreeSpace(), {});
  EXPECT_EQ(bound.hull_planes, 0);
  EXPECT_FALSE(bound.changed);
  EXPECT_TRUE(ConvexHull::Of(patch.vertices, 0.25).Empty());
  EXPECT_TRUE(ConvexHull::Of({}, 0.25).Empty());
}

// A closed mesh that crosses itself is re-made without the crossings, enclosing what it
// enclosed: two overlapping 20 mm cubes as one mesh become their union (parity would have
// hollowed out the overlap), and a ball whose pole was pushed through its far side becomes the
// ball with the fold's spike.
TEST(ClosureBoundTest, AClosedMeshCrossingItselfIsRemadeWithoutTheCrossings) {
  const TriangleMesh cube = test::MakeCube(20);
  const TriangleMesh overlapping = test::MergeMeshes(cube, cube, {8, 6, 4});
  ASSERT_TRUE(overlapping.IsWatertight());
  ASSERT_GT(FindSelfIntersections(overlapping).pairs, 0);
  const TriangleMesh joined = RemeshClosed(overlapping, 1.0, 0.05);
  EXPECT_TRUE(joined.IsWatertight());
  EXPECT_EQ(FindSelfIntersections(joined).pairs, 0);
  const double union_volume = 2 * 8000.0 - 12 * 14 * 16;  // 13 312 mm³.
  std::printf("two overlapping cubes: union %.0f mm³, re-made %.0f mm³\n", union_volume,
              joined.Volume());
  EXPECT_NEAR(joined.Volume(), union_volume, 0.03 * union_volume);

  TriangleMesh folded = test::MakeUvSphere(30, 24, 48);
  int pole = 0;
  for (int v = 0; v < static_cast<int>(folded.vertices.size()); ++v) {
    if (folded.vertices[v].z() > folded.vertices[pole].z()) pole = v;
  }
  folded.vertices[pole] = {0, 0, -45};
  ASSERT_TRUE(folded.IsWatertight());
  ASSERT_GT(FindSelfIntersections(folded).pairs, 0);
  const TriangleMesh remade = RemeshClosed(folded, 1.0, 0.05);
  EXPECT_TRUE(IsWatertightWithoutSelfIntersections(remade));
  // Nearly all of the ball (its top cap is now a cone down through it) and nothing far beyond.
  const double ball = 4.0 / 3.0 * M_PI * 30 * 30 * 30;
  EXPECT_GT(remade.Volume(), 0.8 * ball);
  EXPECT_LT(remade.Volume(), 1.02 * ball);
}

}  // namespace
}  // namespace ihs::fusion
