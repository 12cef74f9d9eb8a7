// Evaluation against ground truth: the true trajectory scores zero, a known error is measured
// as such, and the true object placed by any consistent trajectory matches itself.

#include "tools/evaluation.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/mesh_io.h"
#include "sensor/tum_directory.h"
#include "tests/mesh_fixtures.h"
#include "tests/test_util.h"
#include "tools/synth/sequence.h"
#include "tracker/hand_joints_io.h"

namespace ihs::eval {
namespace {

class EvaluationTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir();
    synth::SequenceOptions options;
    options.scripted.frames = 60;
    options.last_frame = 19;
    options.write_oni = false;
    synth::GenerateSequence(options, dir_->path() / "seq");
  }
  static void TearDownTestSuite() { delete dir_; }
  static std::filesystem::path Gt() { return dir_->path() / "seq" / "gt"; }
  static inline test::TempDir* dir_ = nullptr;
};

TEST_F(EvaluationTest, TheTrueTrajectoryHasNoErrorAndAKnownSlipIsMeasured) {
  const auto truth = ReadTumTrajectory(Gt() / "trajectory.txt");
  ASSERT_EQ(truth.size(), 20u);
  const PairwiseError exact = ContactPairwiseError(Gt(), truth);
  ASSERT_GT(exact.samples, 20);  // Two or three fingertips on the ball in most frames.
  EXPECT_LT(exact.mean_mm, 1e-6);
  EXPECT_LT(CompareTrajectory(Gt(), truth).max_mm, 1e-6);

  // The scan's object frame is anything consistent: the truth's, moved by a fixed offset.
  std::vector<StampedPose> offset = truth;
  const Rigid3 scan_from_truth =
      Rigid3::Translation({5, -3, 40}) * Rigid3::FromAxisAngle({0, 0, 1}, 0.3);
  for (auto& pose : offset) pose.transform = pose.transform * scan_from_truth.Inverse();
  EXPECT_LT(ContactPairwiseError(Gt(), offset).mean_mm, 1e-6);
  EXPECT_LT(CompareTrajectory(Gt(), offset).max_mm, 1e-6);

  // One frame k alone 2 mm off along x in the camera: the pairs k−1 → k and k → k+1 are off by
  // exactly 2 mm at every fingertip touching in both of their frames, the others not at all.
  int checked = 0;
  for (size_t k = 1; k + 1 < truth.size(); ++k) {
    std::vector<StampedPose> slipped = truth;
    slipped[k].transform = Rigid3::Translation({2, 0, 0}) * slipped[k].transform;
    const PairwiseError slip = ContactPairwiseError(Gt(), slipped);
    EXPECT_EQ(slip.samples, exact.samples);
    const double touching = slip.mean_mm * slip.samples / 2.0;
    EXPECT_NEAR(touching, std::round(touching), 1e-6) << "frame " << k;
    EXPECT_LE(std::round(touching), 10) << "frame " << k;
    checked += touching > 0.5;
    EXPECT_NEAR(CompareTrajectory(Gt(), slipped).max_mm, 2.0, 1e-6);
    EXPECT_NEAR(CompareTrajectory(Gt(), slipped).mean_mm, 2.0 / slipped.size(), 1e-6);
  }
  EXPECT_GT(checked, 5);
}

TEST_F(EvaluationTest, TheRotationErrorAndTheTurnFollowedAreMeasured) {
  const auto truth = ReadTumTrajectory(Gt() / "trajectory.txt");
  const TrajectoryError exact = CompareTrajectory(Gt(), truth);
  EXPECT_LT(exact.rotation_max_deg, 1e-4);
  ASSERT_GT(exact.truth_turned_deg, 5.0);  // The scripted grasp turns the ball.
  EXPECT_NEAR(exact.scan_turned_deg, exact.truth_turned_deg, 1e-4);

  // A scan that holds the object still in its first pose: the error is the truth's own turn
  // since then, and it follows none of the turn.
  std::vector<StampedPose> still = truth;
  for (auto& pose : still) pose.transform = truth.front().transform;
  const TrajectoryError held = CompareTrajectory(Gt(), still);
  EXPECT_NEAR(held.scan_turned_deg, 0.0, 1e-6);
  const Eigen::AngleAxisd since_first(truth.front().transform.rotation().transpose() *
                                      truth.back().transform.rotation());
  EXPECT_NEAR(held.rotation_final_deg, since_first.angle() * 180 / M_PI, 1e-6);
  EXPECT_GE(held.rotation_max_deg, held.rotation_final_deg);

  // One frame k alone turned by 3° about the camera's z: 3° off there, 0 elsewhere.
  std::vector<StampedPose> turned = truth;
  const size_t k = truth.size() / 2;
  const Eigen::Vector3d centre = turned[k].transform.translation();
  turned[k].transform = Rigid3::Translation(centre) *
                        Rigid3::FromAxisAngle({0, 0, 1}, 3 * M_PI / 180) *
                        Rigid3::Translation(-centre) * turned[k].transform;
  const TrajectoryError one = CompareTrajectory(Gt(), turned);
  EXPECT_NEAR(one.rotation_max_deg, 3.0, 1e-6);
  EXPECT_NEAR(one.rotation_mean_deg, 3.0 / truth.size(), 1e-6);
  EXPECT_NEAR(one.rotation_final_deg, 0.0, 1e-6);
}

TEST_F(EvaluationTest, TheTurnWhileTheTruthStandsStillIsMeasured) {
  const auto truth = ReadTumTrajectory(Gt() / "trajectory.txt");
  const TrajectoryError exact = CompareTrajectory(Gt(), truth);
  ASSERT_GT(exact.still_steps, 0) << "the fixture's hand reaches for the ball first";
  EXPECT_NEAR(exact.scan_turned_still_deg, 0.0, 1e-3);
  EXPECT_NEAR(exact.scan_wandered_still_deg, 0.0, 1e-3);

  // The truth's turn axis (its steps summed, object frame) and a step where it stands still.
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  size_t still = 0;
  for (size_t k = 1; k < truth.size(); ++k) {
    const Eigen::AngleAxisd step(truth[k - 1].transform.rotation().transpose() *
                                 truth[k].transform.rotation());
    axis += step.angle() * step.axis();
    if (step.angle() < 1e-5 && still == 0) still = k;
  }
  ASSERT_GT(still, 0u);
  axis.normalize();
  // A scan that turns the object back by 3° about that axis in that still step and follows the
  // truth otherwise: 3° back while still, 3° in all.
  std::vector<StampedPose> back = truth;
  for (size_t k = still; k < back.size(); ++k) {
    back[k].transform = back[k].transform * Rigid3::FromAxisAngle(axis, -3 * M_PI / 180);
  }
  const TrajectoryError turned_back = CompareTrajectory(Gt(), back);
  EXPECT_EQ(turned_back.still_steps, exact.still_steps);
  EXPECT_NEAR(turned_back.scan_turned_still_deg, -3.0, 1e-3);
  EXPECT_NEAR(turned_back.scan_wandered_still_deg, 3.0, 1e-3);
}

TEST_F(EvaluationTest, ContactUseIsCountedAgainstTheTruesGraspsAndDistances) {
  const auto truth = ReadTumTrajectory(Gt() / "trajectory.txt");
  // The truth's own count, read here from contacts.csv: grasps (two or more fingertips
  // touching) and frames with no fingertip within 1 mm (the fixture's fingers are within 3 mm
  // of the ball from its first frame on; within 1 mm only once they close on it).
  std::ifstream csv(Gt() / "contacts.csv");
  std::string line;
  std::getline(csv, line);
  int grasps = 0, far = 0;
  std::array<int, 5> finger_far{};
  std::vector<bool> far_frames;
  while (std::getline(csv, line)) {
    std::vector<double> fields;
    std::stringstream row(line);
    for (std::string field; std::getline(row, field, ',');) fields.push_back(std::stod(field));
    ASSERT_EQ(fields.size(), 13u);  // frame, held, 5 touches, 5 distances, penetration.
    int touching = 0;
    double nearest = 1e9;
    for (int f = 0; f < 5; ++f)
      touching += fields[2 + f] > 0.5, nearest = std::min(nearest, fields[7 + f]);
    grasps += touching >= 2;
    far += nearest > 1.0;
    for (int f = 0; f < 5; ++f) finger_far[f] += fields[7 + f] > 1.0;
    far_frames.push_back(nearest > 1.0);
  }
  ASSERT_EQ(far_frames.size(), truth.size());
  ASSERT_GT(grasps, 5);
  ASSERT_GT(far, 0);

  // The finger farthest from the ball most often: frames whose contacts are that finger alone
  // are judged by its distance alone.
  const int finger =
      static_cast<int>(std::max_element(finger_far.begin(), finger_far.end()) - finger_far.begin());
  std::vector<FrameContactUse> none, all, near_only, one_finger;
  for (size_t k = 0; k < truth.size(); ++k) {
    none.push_back({truth[k].time_s, false, {}});
    all.push_back({truth[k].time_s, true, {}});
    one_finger.push_back({truth[k].time_s, true, {finger}});
    near_only.push_back({truth[k].time_s, !far_frames[k], {}});
  }
  all.push_back({truth.back().time_s + 10.0, true, {}});  // No such frame in the truth: ignored.
  const ContactUse unused = CompareContactUse(Gt(), none, 1.0);
  EXPECT_EQ(unused.grasp_frames, grasps);
  EXPECT_EQ(unused.used_in_grasp, 0);
  EXPECT_EQ(unused.used_frames, 0);
  EXPECT_EQ(unused.recall, 0.0);
  const ContactUse every = CompareContactUse(Gt(), all, 1.0);
  EXPECT_EQ(every.used_in_grasp, grasps);
  EXPECT_EQ(every.recall, 1.0);
  EXPECT_EQ(every.used_frames, static_cast<int>(truth.size()));
  EXPECT_EQ(every.false_frames, far);
  EXPECT_NEAR(every.false_share, static_cast<double>(far) / truth.size(), 1e-12);
  EXPECT_EQ(CompareContactUse(Gt(), near_only, 1.0).false_frames, 0);
  EXPECT_LE(CompareContactUse(Gt(), all).false_frames, far);  // 3 mm: fewer are that far.
  ASSERT_GT(finger_far[finger], far);
  EXPECT_EQ(CompareContactUse(Gt(), one_finger, 1.0).false_frames, finger_far[finger]);
}

TEST_F(EvaluationTest, GraspingFingertipsAreJudgedAgainstTheTruths) {
  // The truth's own joints as the tracker's: every grasping frame within any distance.
  const std::filesystem::path truth_csv = Gt() / "hand_joints.csv";
  const GraspTips exact = CompareGraspTips(Gt(), truth_csv);
  ASSERT_GT(exact.grasp_frames, 5);
  ASSERT_EQ(exact.share.size(), 3u);
  for (double share : exact.share) EXPECT_EQ(share, 1.0);

  // Every joint 8 mm off along x, and the last frame missing: within 10 and 15 mm but not 6,
  // and the missing frame counts against.
  std::vector<tracker::HandJointsRow> rows = tracker::ReadHandJointsCsv(truth_csv);
  rows.pop_back();
  for (auto& row : rows) {
    for (auto& joint : row.joints_mm) joint.x() += 8.0;
  }
  std::ifstream header_in(truth_csv);
  std::string header;
  std::getline(header_in, header);
  // The bones, from the header's "<bone>_end_x" columns (joint 0 is the root's start).
  std::vector<std::string> bones;
  std::stringstream columns(header);
  int column = 0;
  for (std::string name; std::getline(columns, name, ','); ++column) {
    if (column >= 4 && (column - 1) % 3 == 0) bones.push_back(name.substr(0, name.size() - 6));
  }
  ASSERT_EQ(bones.size() + 1, rows.front().joints_mm.size());
  const test::TempDir tracked;
  tracker::WriteHandJointsCsv(tracked.path() / "hand_joints.csv", bones, rows);
  const GraspTips off = CompareGraspTips(Gt(), tracked.path() / "hand_joints.csv");
  EXPECT_EQ(off.grasp_frames, exact.grasp_frames);
  EXPECT_EQ(off.share[0], 0.0);
  // Was the last frame a grasp? Then it is the one not within.
  const auto touching_last = [&] {
    std::ifstream in(Gt() / "contacts.csv");
    std::string line, last;
    while (std::getline(in, line)) last = line;
    std::stringstream fields(last);
    std::vector<double> values;
    for (std::string field; std::getline(fields, field, ',');) values.push_back(std::stod(field));
    int touching = 0;
    for (int f = 0; f < 5; ++f) touching += values[2 + f] > 0.5;
    return touching;
  }();
  const double expected =
      touching_last >= 2 ? static_cast<double>(exact.grasp_frames - 1) / exact.grasp_frames : 1.0;
  EXPECT_NEAR(off.share[1], expected, 1e-12);
  EXPECT_NEAR(off.share[2], expected, 1e-12);
  EXPECT_THROW(CompareGraspTips(Gt(), tracked.path() / "missing.csv"), InputError);
}

TEST_F(EvaluationTest, TheShownSurfaceGrowsWithTheFramesThatShowIt) {
  sensor::TumDirectorySource source(dir_->path() / "seq" / "tum");
  source.Start();
  std::vector<std::shared_ptr<const Frame>> frames;
  for (auto read = source.Next(std::chrono::milliseconds(0));
       read.status == sensor::SourceStatus::kFrame;
       read = source.Next(std::chrono::milliseconds(0)))
    frames.push_back(read.frame);
  ASSERT_EQ(frames.size(), 20u);

  ShownSurface none(Gt(), source.Intrinsics());
  EXPECT_EQ(none.Share(), 0.0);
  // A frame the truth does not have shows nothing.
  Frame stranger = *frames.front();
  stranger.depth_timestamp_us += 10'000'000;
  none.Add(stranger);
  EXPECT_EQ(none.Share(), 0.0);

  // One view of the ball shows less than half of it; the twenty frames, turning it, more.
  ShownSurface first(Gt(), source.Intrinsics());
  first.Add(*frames.front());
  ShownSurface all(Gt(), source.Intrinsics());
  for (const auto& frame : frames) all.Add(*frame);
  EXPECT_GT(first.Share(), 0.1);
  EXPECT_LT(first.Share(), 0.5);
  EXPECT_GT(all.Share(), first.Share());
  EXPECT_LE(all.Share(), 1.0);
  // Farther tolerance, more of the surface within it.
  EXPECT_GE(all.Share(5.0), all.Share(2.0));

  EXPECT_THROW(ShownSurface(dir_->path() / "no-such-gt", source.Intrinsics()), ihs::InputError);

  // The labels read alone: the first frame's ball, none for a frame the truth does not have
  // or at another size.
  const Frame& one = *frames.front();
  const std::vector<std::uint8_t> object = TruthObjectPixels(Gt(), 0, one.width, one.height);
  ASSERT_EQ(object.size(), one.depth_mm.size());
  EXPECT_GT(std::count(object.begin(), object.end(), 1), 100);
  EXPECT_TRUE(TruthObjectPixels(Gt(), 999, one.width, one.height).empty());
  EXPECT_TRUE(TruthObjectPixels(Gt(), 0, one.width / 2, one.height).empty());
}

TEST_F(EvaluationTest, TheTrueObjectMatchesItselfPlacedByTheTrajectory) {
  const auto truth = ReadTumTrajectory(Gt() / "trajectory.txt");
  const TriangleMesh object = ReadMesh(Gt() / "object.ply");
  // The "scan" in an object frame of its own, and the trajectory that goes with it.
  const Rigid3 scan_from_truth = Rigid3::Translation({-20, 8, 3});
  TriangleMesh scan = object;
  for (auto& v : scan.vertices)
    v = (scan_from_truth * Eigen::Vector3d(v.cast<double>())).cast<float>();
  std::vector<StampedPose> trajectory = truth;
  for (auto& pose : trajectory) pose.transform = pose.transform * scan_from_truth.Inverse();
  const fusion::SurfaceComparison same = CompareWithTruth(Gt(), scan, trajectory);
  EXPECT_LT(same.chamfer_mm, 0.2);
  EXPECT_GT(same.completeness, 0.999);
  // Dimensions of the true sphere.
  const auto rows = PaperDimensions("sphere", object);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_NEAR(rows[0].truth_mm, 70.0, 0.1);
  EXPECT_NEAR(TrueVolume("sphere") / (4.0 / 3.0 * M_PI * 35 * 35 * 35), 1.0, 0.002);
  EXPECT_THROW(PaperDimensions("teapot", object), std::invalid_argument);
}

TEST_F(EvaluationTest, AnObjectWithoutThePapersMeasuresGetsItsVolumeFromTheTruthsMesh) {
  EXPECT_TRUE(IsBodyOfRevolution("sphere"));
  EXPECT_TRUE(IsBodyOfRevolution("lathe:profile.txt"));
  EXPECT_FALSE(IsBodyOfRevolution("cube"));
  EXPECT_FALSE(IsBodyOfRevolution(""));
  EXPECT_NE(NotABodyOfRevolution("cube").find("unknown object 'cube'"), std::string::npos);
  EXPECT_EQ(NotABodyOfRevolution("water-bottle"), "");
  // A scan named as a cube or a plain box (no dimensions): the volume of its closed mesh against
  // gt/object.ply's, whatever the name; the same mesh scaled by 1.1 is 33.1 % larger.
  const TriangleMesh object = ReadMesh(Gt() / "object.ply");
  TriangleMesh larger = object;
  for (auto& v : larger.vertices) v *= 1.1f;
  const auto trajectory = ReadTumTrajectory(Gt() / "trajectory.txt");
  for (const std::string name : {"cube", "plain-box", ""}) {
    const nlohmann::json report =
        ReportScan(name, larger, larger, Gt(), trajectory, std::nullopt, nullptr);
    EXPECT_FALSE(report.contains("dimensions")) << name;
    ASSERT_TRUE(report.contains("volume_error")) << name;
    EXPECT_NEAR(report["volume_error"].get<double>(), 0.331, 0.002) << name;
  }
}

TEST_F(EvaluationTest, ABoxsSidesAreMeasuredOnTheSeenSurfaceAndOnTheClosedMesh) {
  // A 90 × 60 × 45 mm box turned off the axes; scans of it 2.5 mm too wide across its shortest
  // side (the seen surface) and 4 mm (the closed mesh). Its sides are found along its own faces,
  // longest to shortest, and compared with the truth's in that order, on both meshes.
  const Eigen::Matrix3f turn =
      Eigen::AngleAxisf(0.6f, Eigen::Vector3f(1, -2, 0.7).normalized()).toRotationMatrix();
  auto box = [&](float x, float y, float z) {
    TriangleMesh mesh = test::MakeCube(1.0f);
    for (auto& v : mesh.vertices) v = turn * Eigen::Vector3f(v.x() * x, v.y() * y, v.z() * z);
    return mesh;
  };
  const TriangleMesh truth = box(60, 90, 45), seen = box(60, 90, 47.5), closed = box(60, 90, 49);
  EXPECT_TRUE(IsBox(truth));
  EXPECT_FALSE(IsBox(test::MakeUvSphere(30, 16, 32)));
  const std::vector<DimensionRow> rows = BoxDimensions(truth, seen);
  ASSERT_EQ(rows.size(), 3u);
  const std::array<double, 3> true_sides = {90, 60, 45}, scan_sides = {90, 60, 47.5};
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_NEAR(rows[k].truth_mm, true_sides[k], 1e-3) << rows[k].measure;
    EXPECT_NEAR(rows[k].captured_mm, scan_sides[k], 1e-3) << rows[k].measure;
  }
  EXPECT_EQ(rows[2].measure, "shortest side");

  // Through the report, the truth's box in a gt/ folder of its own: the seen surface's sides
  // and mesh.ply's, whatever the object is called.
  test::TempDir dir;
  std::filesystem::copy(Gt(), dir.path() / "gt", std::filesystem::copy_options::recursive);
  WriteMesh(dir.path() / "gt" / "object.ply", truth);
  const auto trajectory = ReadTumTrajectory(Gt() / "trajectory.txt");
  const nlohmann::json report =
      ReportScan("plain-box", seen, closed, dir.path() / "gt", trajectory, std::nullopt, nullptr);
  ASSERT_TRUE(report.contains("dimensions") && report.contains("dimensions_watertight"));
  EXPECT_NEAR(report["dimensions"][2]["scan_mm"].get<double>(), 47.5, 1e-3);
  EXPECT_NEAR(report["dimensions_watertight"][2]["scan_mm"].get<double>(), 49.0, 1e-3);
  EXPECT_NEAR(report["dimension_error_mm_mean_watertight"].get<double>(), 4.0 / 3, 1e-3);
}

}  // namespace
}  // namespace ihs::eval
