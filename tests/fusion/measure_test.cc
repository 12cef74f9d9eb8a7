// Measuring meshes: the paper's objects' dimensions from their true meshes in any orientation,
// and surface comparison distances.

#include "fusion/measure.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <vector>

#include "tests/mesh_fixtures.h"
#include "tests/test_util.h"
#include "tools/synth/objects.h"

namespace ihs::fusion {
namespace {

// The paper's object `name`, its profile resampled every 0.5 mm or less (a scan's mesh is
// dense everywhere), turned and moved somewhere arbitrary.
TriangleMesh PaperObject(const std::string& name) {
  const synth::LatheProfile profile = synth::ResampleProfile(synth::PaperObjectProfile(name), 0.5);
  TriangleMesh mesh = synth::MakeLatheMesh(profile, 256);
  const Eigen::Matrix3f turn =
      Eigen::AngleAxisf(0.7f, Eigen::Vector3f(1, 2, 3).normalized()).toRotationMatrix();
  for (auto& v : mesh.vertices) v = turn * v + Eigen::Vector3f(12, -40, 610);
  return mesh;
}

// The faces of `whole` that `keep` (given a face's centroid and its normal) keeps.
template <typename Keep>
TriangleMesh KeepFaces(const TriangleMesh& whole, Keep keep) {
  TriangleMesh kept;
  std::vector<int> index(whole.vertices.size(), -1);
  for (const auto& f : whole.faces) {
    const Eigen::Vector3d a = whole.vertices[f[0]].cast<double>();
    const Eigen::Vector3d b = whole.vertices[f[1]].cast<double>();
    const Eigen::Vector3d c = whole.vertices[f[2]].cast<double>();
    if (!keep((a + b + c) / 3, (b - a).cross(c - a))) continue;
    std::array<int, 3> face;
    for (int k = 0; k < 3; ++k) {
      if (index[f[k]] < 0) {
        index[f[k]] = static_cast<int>(kept.vertices.size());
        kept.vertices.push_back(whole.vertices[f[k]]);
      }
      face[k] = index[f[k]];
    }
    kept.faces.push_back(face);
  }
  return kept;
}

TEST(MeasureTest, ThePaperObjectsMeasureToTheirDimensions) {
  struct Case {
    std::string name;
    double height, widest, head;
  };
  for (const Case& c : {Case{"water-bottle", 218, 73, 0}, Case{"small-bottle", 80, 52, 0},
                        Case{"bowling-pin", 268, 82, 50}}) {
    const RevolutionMeasures m = MeasureRevolution(PaperObject(c.name));
    EXPECT_NEAR(m.height_mm, c.height, 0.5) << c.name;
    EXPECT_NEAR(m.widest_diameter_mm, c.widest, 0.5) << c.name;
    EXPECT_NEAR(m.head_diameter_mm, c.head, 0.5) << c.name;
    const Eigen::Vector3d true_axis =
        Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()) * Eigen::Vector3d::UnitZ();
    EXPECT_GT(std::abs(m.axis.dot(true_axis)), 0.999) << c.name;
  }
  const RevolutionMeasures sphere = MeasureRevolution(PaperObject("sphere"));
  EXPECT_NEAR(sphere.widest_diameter_mm, 70, 0.5);
  EXPECT_NEAR(sphere.height_mm, 70, 0.5);
  EXPECT_THROW(MeasureRevolution(TriangleMesh{}), std::invalid_argument);
}

TEST(MeasureTest, APartlySeenObjectStillMeasuresToItsDimensions) {
  // A third of the bottle's surface never seen (a scan's blind side): its sections are arcs.
  const TriangleMesh whole = synth::MakeLatheMesh(
      synth::ResampleProfile(synth::PaperObjectProfile("water-bottle"), 0.5), 256);
  TriangleMesh seen = whole;
  seen.faces.clear();
  for (const auto& f : whole.faces) {
    const Eigen::Vector3f c =
        (whole.vertices[f[0]] + whole.vertices[f[1]] + whole.vertices[f[2]]) / 3;
    if (std::atan2(c.y(), c.x()) < M_PI / 3) seen.faces.push_back(f);
  }
  const RevolutionMeasures m = MeasureRevolution(seen);
  EXPECT_NEAR(m.widest_diameter_mm, 73, 0.5);
  // The principal axis of two thirds of the surface tilts a little (218.83 mm along it); the
  // line through the sections' centres measures 218.00 mm.
  EXPECT_NEAR(m.height_mm, 218, 0.3);
}

TEST(MeasureTest, TheAxisOfAHalfSeenSquatBottleIsItsSymmetryAxis) {
  // Half of the small bottle's side and none of its bottom seen, turned: the principal axes of
  // what is left tilt away from the symmetry axis, and the height along them comes out long.
  // The sections' centres put the axis back.
  const TriangleMesh whole = PaperObject("small-bottle");
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d true_axis = turn.col(2);
  const Eigen::Vector3d side = turn.col(0);
  const TriangleMesh seen =
      KeepFaces(whole, [&](const Eigen::Vector3d& centroid, const Eigen::Vector3d&) {
        const Eigen::Vector3d c = centroid - Eigen::Vector3d(12, -40, 610);
        return c.dot(side) >= 0 && c.dot(true_axis) >= 1.0;
      });
  const RevolutionMeasures m = MeasureRevolution(seen);
  // Measured: 0.01° off the axis, height 79.00 mm (80 less the 1 mm of bottom left out); the
  // principal axis alone was 6.2° off and measured 81.24 mm.
  EXPECT_GT(std::abs(m.axis.dot(true_axis)), std::cos(0.3 * M_PI / 180));
  EXPECT_NEAR(m.height_mm, 79, 0.5);
  EXPECT_NEAR(m.widest_diameter_mm, 52, 0.5);
  // The point given on the axis is on it (the centroid of the half seen is 10 mm off it), and
  // the sections are circles.
  const Eigen::Vector3d off = m.axis_point - Eigen::Vector3d(12, -40, 610);
  EXPECT_LT((off - off.dot(true_axis) * true_axis).norm(), 0.3);
  EXPECT_GT((m.centre - Eigen::Vector3d(12, -40, 610) -
             (m.centre - Eigen::Vector3d(12, -40, 610)).dot(true_axis) * true_axis)
                .norm(),
            5.0);
  EXPECT_LT(m.roundness_residual, 0.01);
}

TEST(MeasureTest, ASmallBottleSeenFromBelowOnOneSideMeasuresItsHeight) {
  // What a camera sees of the small bottle from 40° below its base on one side (the faces
  // turned towards it): half of the side and the bottom, as in a scan that never turned the
  // bottle. Its principal axes tilt by more than the sections' centres can correct: measured
  // 12.7° off the axis and 85.96 mm high without the line the normals meet, 0.02° and 80.02 mm
  // with it. (On such a scan, the unseen stretch u4 in docs/fusion.md: 16° off, +6.9 mm.)
  const TriangleMesh whole = PaperObject("small-bottle");
  const Eigen::Matrix3d turn =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d true_axis = turn.col(2);
  const Eigen::Vector3d towards_camera =
      turn * Eigen::Vector3d(std::cos(40 * M_PI / 180), 0, -std::sin(40 * M_PI / 180));
  const TriangleMesh seen =
      KeepFaces(whole, [&](const Eigen::Vector3d&, const Eigen::Vector3d& normal) {
        return normal.dot(towards_camera) > 0;
      });
  const RevolutionMeasures m = MeasureRevolution(seen);
  std::printf("%.2f° off the axis, height %.2f mm, widest %.2f mm\n",
              std::acos(std::min(1.0, std::abs(m.axis.dot(true_axis)))) * 180 / M_PI, m.height_mm,
              m.widest_diameter_mm);
  EXPECT_GT(std::abs(m.axis.dot(true_axis)), std::cos(1.0 * M_PI / 180));
  EXPECT_NEAR(m.height_mm, 80, 0.5);
  EXPECT_NEAR(m.widest_diameter_mm, 52, 0.5);
}

TEST(MeasureTest, ABoxFacesAlongThreeDirectionsARoundObjectDoesNot) {
  // The generator's 60 x 45 x 90 mm box, turned, whole and as the three faces seen from one
  // corner: its faces along its own axes; the paper's round objects nowhere near.
  TriangleMesh box = synth::MakeTexturedBox({60, 45, 90});
  const Eigen::Matrix3f turn =
      Eigen::AngleAxisf(0.7f, Eigen::Vector3f(1, 2, 3).normalized()).toRotationMatrix();
  for (auto& v : box.vertices) v = turn * v;
  const TriangleMesh corner = KeepFaces(box, [&](const Eigen::Vector3d&, const Eigen::Vector3d& n) {
    return (turn.cast<double>().transpose() * n).minCoeff() > -1e-9;  // Faces toward +x, +y, +z.
  });
  for (const TriangleMesh* mesh : {static_cast<const TriangleMesh*>(&box), &corner}) {
    const BoxMeasures m = MeasureBox(*mesh);
    EXPECT_GT(m.face_share, 0.99);
    // Each found axis is one of the box's.
    const Eigen::Matrix3d along = turn.cast<double>().transpose() * m.axes;
    for (int k = 0; k < 3; ++k) EXPECT_GT(along.col(k).cwiseAbs().maxCoeff(), 0.999) << k;
    EXPECT_NEAR(std::abs(m.axes.determinant()), 1.0, 1e-9);
  }
  for (const char* name : {"sphere", "water-bottle", "small-bottle", "bowling-pin"}) {
    EXPECT_LT(MeasureBox(PaperObject(name)).face_share, 0.5) << name;
  }
  EXPECT_EQ(MeasureBox(TriangleMesh{}).face_share, 0);
}

TEST(MeasureTest, AnExtentHoldsThePointsOrAllButItsOutliers) {
  // 1000 points in a turned 60 x 45 x 90 mm box, and three 6 mm proud of its +y face (a blob):
  // every point's extent takes them in; leaving out 0.5 % at each end cuts them off.
  std::mt19937 rng = test::Rng();
  std::uniform_real_distribution<float> unit(-0.5f, 0.5f);
  const Eigen::Matrix3d axes =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(2, 1, -1).normalized()).toRotationMatrix();
  std::vector<Eigen::Vector3f> points;
  for (int k = 0; k < 1000; ++k) {
    const Eigen::Vector3d local(60 * unit(rng), 45 * unit(rng), 90 * unit(rng));
    points.push_back((axes * local).cast<float>());
  }
  for (int k = 0; k < 3; ++k)
    points.push_back((axes * Eigen::Vector3d(k, 22.5 + 6, 10 * k)).cast<float>());
  const BoxExtent all = MeasureExtent(points, axes);
  const BoxExtent kept = MeasureExtent(points, axes, 0.005);
  EXPECT_NEAR(all.high.y(), 28.5, 1e-4);
  EXPECT_LT(kept.high.y(), 22.5 + 1e-4);
  EXPECT_GT(kept.high.y(), 22.0);  // Five points of 1003 off the face: about 0.2 mm.
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_LE(all.low[axis], kept.low[axis]);
    EXPECT_NEAR(kept.Size()[axis], Eigen::Vector3d(60, 45, 90)[axis], 1.5) << axis;
  }
  EXPECT_EQ(MeasureExtent({}, axes).Size(), Eigen::Vector3d::Zero());
  EXPECT_THROW(MeasureExtent(points, axes, 0.5), std::invalid_argument);
}

TEST(MeasureTest, SurfaceComparisonMeasuresTheGapAndTheCoverage) {
  const TriangleMesh truth = test::MakeUvSphere(35, 64, 128);
  const SurfaceComparison same = CompareSurfaces(truth, truth);
  EXPECT_LT(same.chamfer_mm, 0.2);  // Only the sampling's own spread.
  EXPECT_DOUBLE_EQ(same.completeness, 1.0);

  const SurfaceComparison bigger = CompareSurfaces(test::MakeUvSphere(36, 64, 128), truth);
  EXPECT_NEAR(bigger.scan_to_truth_mm, 1.0, 0.15);
  EXPECT_NEAR(bigger.truth_to_scan_mm, 1.0, 0.15);
  EXPECT_DOUBLE_EQ(bigger.completeness, 1.0);
  const SurfaceComparison far = CompareSurfaces(test::MakeUvSphere(38, 64, 128), truth);
  EXPECT_DOUBLE_EQ(far.completeness, 0.0);

  // Half the sphere: half the truth is missing.
  TriangleMesh half = truth;
  half.faces.clear();
  for (const auto& f : truth.faces) {
    if (truth.vertices[f[0]].z() > 0 && truth.vertices[f[1]].z() > 0 &&
        truth.vertices[f[2]].z() > 0) {
      half.faces.push_back(f);
    }
  }
  const SurfaceComparison partial = CompareSurfaces(half, truth);
  EXPECT_NEAR(partial.completeness, 0.5, 0.03);
  EXPECT_LT(partial.scan_to_truth_mm, 0.2);
}

TEST(MeasureTest, UnseenShareIsTheClosedAreaFarFromTheSeenSurface) {
  const TriangleMesh closed = test::MakeUvSphere(35, 128, 256);
  // Seen: the sphere above a plane z = h; the unseen cap below it has area 2πR(R + h).
  const auto above = [&](float h) {
    TriangleMesh seen = closed;
    seen.faces.clear();
    for (const auto& f : closed.faces) {
      if (closed.vertices[f[0]].z() > h && closed.vertices[f[1]].z() > h &&
          closed.vertices[f[2]].z() > h) {
        seen.faces.push_back(f);
      }
    }
    return seen;
  };
  EXPECT_LT(UnseenShare(closed, closed), 0.001);
  // The 2 mm band next to the seen rim counts as seen: the unseen share is the cap below
  // z = h - 2 (for a rim on the equator, (35 - 2) / 70).
  EXPECT_NEAR(UnseenShare(closed, above(0)), 33.0 / 70, 0.02);
  EXPECT_NEAR(UnseenShare(closed, above(20)), (35.0 + 18) / 70, 0.02);
  EXPECT_NEAR(UnseenShare(closed, above(0), 0.5), 34.5 / 70, 0.02);
  // A seen surface 3 mm off the closed one everywhere: nothing of it counts as seen.
  EXPECT_GT(UnseenShare(closed, test::MakeUvSphere(38, 64, 128)), 0.999);
  EXPECT_DOUBLE_EQ(UnseenShare(closed, TriangleMesh{}), 1.0);
  EXPECT_DOUBLE_EQ(UnseenShare(TriangleMesh{}, closed), 0.0);
  EXPECT_THROW(UnseenShare(closed, closed, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace ihs::fusion

namespace ihs::fusion {
namespace {

// A flat square of `side` mm, two triangles.
TriangleMesh Square(float side) {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {side, 0, 0}, {side, side, 0}, {0, side, 0}};
  mesh.faces = {{0, 1, 2}, {0, 2, 3}};
  return mesh;
}

TEST(SampleSurfaceTest, SamplesByAreaButNeverBeyondTheCap) {
  // 10 × 10 mm at 0.25 mm: 1600 samples.
  EXPECT_NEAR(SampleSurface(Square(10), 0.25).size(), 1600.0, 2.0);
  // A smeared scan of 2 m × 2 m would need 64 million: it gets the cap instead, spread evenly.
  const std::vector<Eigen::Vector3f> big = SampleSurface(Square(2000), 0.25, 20000);
  EXPECT_NEAR(big.size(), 20000.0, 2.0);
  int far_half = 0;
  for (const auto& p : big) far_half += p.x() > 1000;
  EXPECT_NEAR(far_half, 10000, 500);
  EXPECT_TRUE(SampleSurface(TriangleMesh(), 0.25).empty());
}

}  // namespace
}  // namespace ihs::fusion
