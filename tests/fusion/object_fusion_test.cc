// The fusion stage on an analytic sequence: an ellipsoid (and a sphere) turned a full turn in
// front of the camera, with fingertip contacts on it; the trajectory and the mesh against the
// truth, each registration source alone, and frames that must be skipped.

#include "fusion/object_fusion.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "tests/frame_fixtures.h"
#include "tests/free_space_fixtures.h"
#include "tests/test_util.h"

namespace ihs::fusion {
namespace {

const CameraIntrinsics kIntrinsics = CameraIntrinsics::Carmine109();
constexpr int kFrames = 90;  // 4° a frame: a full turn.

// The object's true pose in frame i: turning about a tilted axis through its centre.
Rigid3 Truth(int i) {
  return Rigid3::Translation({5, -10, 600}) *
         Rigid3::FromAxisAngle(Eigen::Vector3d(0.3, 1, 0.2), i * 4 * M_PI / 180) *
         Rigid3::FromAxisAngle({1, 0, 0}, 0.3);
}

// `count` points spread evenly over the ellipsoid's surface (a Fibonacci lattice of directions).
std::vector<Eigen::Vector3d> SurfaceSpots(const Eigen::Vector3d& semi_axes, int count) {
  std::vector<Eigen::Vector3d> spots;
  for (int k = 0; k < count; ++k) {
    const double z = 1 - (2 * k + 1.0) / count, ring = std::sqrt(1 - z * z);
    const double angle = k * M_PI * (3 - std::sqrt(5.0));
    const Eigen::Vector3d direction(ring * std::cos(angle), ring * std::sin(angle), z);
    spots.push_back(direction / direction.cwiseQuotient(semi_axes).norm());
  }
  return spots;
}

// The ends of the ellipsoid's semi-axes (object frame): the positive ones, or both.
std::vector<Eigen::Vector3d> AxisEnds(const Eigen::Vector3d& semi_axes, bool both_ends) {
  std::vector<Eigen::Vector3d> ends;
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {1.0, -1.0}) {
      if (sign < 0 && !both_ends) continue;
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      p[axis] = sign * semi_axes[axis];
      ends.push_back(p);
    }
  }
  return ends;
}

// The largest distance between where `cam_from_volume` and the truth (`cam_from_object`) put
// `points` (object frame), the volume's frame fixed to the object by `object_from_volume`, mm.
double WorstPointError(const Rigid3& cam_from_volume, const Rigid3& cam_from_object,
                       const Rigid3& object_from_volume,
                       const std::vector<Eigen::Vector3d>& points) {
  double worst = 0;
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d in_volume = object_from_volume.Inverse() * p;
    worst = std::max(
        worst,
        (cam_from_volume * in_volume - cam_from_object * object_from_volume * in_volume).norm());
  }
  return worst;
}

struct SequenceRun {
  std::vector<FusionResult> results;
  double pose_error_mm = 0;  // The worst over the sequence, at the object's extreme points.
  TriangleMesh mesh;         // In the object's own frame.
};

// Fuses the sequence; `contacts` fixed points of the object touch the fingers (noise 0.3 mm
// each, and `shared_noise_mm` per frame common to all of them, as a mistracked hand moves all
// its fingertips): round the object's equator, or with `patch_mm` > 0 on a circle of that
// radius round the end of its first axis (one fingertip's patch); the tracker found them at
// `contact_threshold_mm` (FusionInput::contact_threshold_mm). With `features` > 0, that many
// points spread over the surface are visual features too, matched from frame to frame while
// they face the camera (their index the track's id), each sighting 1 mm off at random. In the
// turn's middle frame every contact is seen `jolt` off (a mistracked hand's fingertips jumping
// together).
SequenceRun FuseSequence(const Eigen::Vector3d& semi_axes, int contacts,
                         const FusionOptions& options, double shared_noise_mm = 0,
                         double patch_mm = 0, double contact_threshold_mm = 0, int features = 0,
                         const Eigen::Vector3d& jolt = Eigen::Vector3d::Zero()) {
  std::mt19937 rng = test::Rng();
  const std::vector<Eigen::Vector3d> spots = SurfaceSpots(semi_axes, features);
  std::vector<std::vector<Eigen::Vector3d>> sighting_noise(kFrames);
  std::normal_distribution<double> feature_noise(0, 1.0 / std::sqrt(3.0));
  for (auto& frame_noise : sighting_noise) {
    for (size_t k = 0; k < spots.size(); ++k) {
      frame_noise.emplace_back(feature_noise(rng), feature_noise(rng), feature_noise(rng));
    }
  }
  auto faces_camera = [&](int i, size_t k) {
    const Eigen::Vector3d normal =
        Truth(i).RotateVector(spots[k].cwiseQuotient(semi_axes.cwiseAbs2())).normalized();
    return normal.dot(-(Truth(i) * spots[k]).normalized()) > 0.3;
  };
  std::normal_distribution<double> noise(0, 0.3);
  std::normal_distribution<double> shared_noise(0, std::max(1e-9, shared_noise_mm));
  std::vector<Eigen::Vector3d> touched;  // Object frame.
  for (int k = 0; k < contacts; ++k) {
    const double angle = 2 * M_PI * k / std::max(1, contacts);
    if (patch_mm > 0) {
      // On the surface: the point of the ellipsoid in that direction.
      const Eigen::Vector3d direction(semi_axes.x(), patch_mm * std::cos(angle),
                                      patch_mm * std::sin(angle));
      touched.push_back(direction / direction.cwiseQuotient(semi_axes).norm());
      continue;
    }
    touched.push_back(semi_axes.cwiseProduct(Eigen::Vector3d(std::cos(angle), std::sin(angle), 0)));
  }
  // Each registration source alone: the ellipsoid's two colour halves are not one of them here
  // (the colour's own tests are in colour_align_test.cc). With the colour on, exact contacts
  // and one colour edge pulled against each other: one fingertip's patch on the sphere 12.4 ->
  // 24.4 mm (docs/fusion.md).
  // Nor is the outline (silhouette.h, tested in silhouette_test.cc): on this small smooth
  // ellipsoid its edge in the model is off by about a voxel, and with it the worst pose error of
  // the full turn with contacts went 1.41 -> 2.92 mm, of the loose contacts 2.16 -> 3.80 mm
  // (docs/fusion.md, "The outline where a face turns edge-on").
  FusionOptions sources = options;
  sources.colour.enabled = false;
  sources.silhouette.weight = 0;
  ObjectFusion fusion(kIntrinsics, sources);
  SequenceRun run;
  for (int i = 0; i < kFrames; ++i) {
    const Frame frame = test::RenderEllipsoid(kIntrinsics, Truth(i), semi_axes);
    std::vector<std::uint8_t> mask(frame.depth_mm.size());
    for (size_t p = 0; p < mask.size(); ++p) mask[p] = frame.depth_mm[p] != 0;
    FusionInput input{&frame, &mask, {}};
    input.contact_threshold_mm = contact_threshold_mm;
    if (i > 0) {
      Eigen::Vector3d shared = Eigen::Vector3d::Zero();
      if (shared_noise_mm > 0) shared = {shared_noise(rng), shared_noise(rng), shared_noise(rng)};
      if (i == kFrames / 2) shared += jolt;
      for (const Eigen::Vector3d& q : touched) {
        input.correspondences.Pairs("contacts", MatchKind::kContact)
            .push_back({Truth(i - 1) * q, Truth(i) * q + shared +
                                              Eigen::Vector3d(noise(rng), noise(rng), noise(rng))});
      }
      for (size_t k = 0; k < spots.size(); ++k) {
        if (!faces_camera(i - 1, k) || !faces_camera(i, k)) continue;
        input.correspondences.Pairs("sift", MatchKind::kVisual)
            .push_back({Truth(i - 1) * spots[k] + sighting_noise[i - 1][k],
                        Truth(i) * spots[k] + sighting_noise[i][k], static_cast<int>(k)});
      }
    }
    run.results.push_back(fusion.Fuse(input));
  }
  // The volume's frame is fixed to the object: cam_from_volume(i) = Truth(i)·object_from_volume.
  // The error: the largest over the sequence, at the object's extreme points.
  const Rigid3 object_from_volume = Truth(0).Inverse() * run.results.front().cam_from_object;
  for (int i = 0; i < kFrames; ++i) {
    run.pose_error_mm =
        std::max(run.pose_error_mm, WorstPointError(run.results[i].cam_from_object, Truth(i),
                                                    object_from_volume, AxisEnds(semi_axes, true)));
  }
  run.mesh = fusion.ExtractMesh();
  for (auto& v : run.mesh.vertices)
    v = (object_from_volume * Eigen::Vector3d(v.cast<double>())).cast<float>();
  return run;
}

// Mean distance of mesh vertices from the ellipsoid, approximately (radial, mm).
double MeshError(const TriangleMesh& mesh, const Eigen::Vector3d& semi_axes) {
  double sum = 0;
  for (const auto& v : mesh.vertices) {
    const Eigen::Vector3d p = v.cast<double>();
    const double scale = p.cwiseQuotient(semi_axes).norm();  // 1 on the surface.
    sum += std::abs(p.norm() * (1 - 1 / scale));
  }
  return sum / std::max<size_t>(1, mesh.vertices.size());
}

int Count(const SequenceRun& run, FusionStatus status) {
  return static_cast<int>(std::count_if(run.results.begin(), run.results.end(),
                                        [&](const FusionResult& r) { return r.status == status; }));
}

TEST(ObjectFusionTest, AFullTurnOfAnEllipsoidWithContactsAndIcpStaysOnTrack) {
  const Eigen::Vector3d axes(45, 30, 18);
  const SequenceRun run = FuseSequence(axes, 6, {});
  std::printf(
      "ellipsoid, contacts + ICP: %d fused, worst pose error %.2f mm, mesh error %.3f mm, "
      "coverage %.3f after one frame, %.3f at the end\n",
      Count(run, FusionStatus::kFused), run.pose_error_mm, MeshError(run.mesh, axes),
      run.results.front().coverage, run.results.back().coverage);
  EXPECT_EQ(run.results.front().status, FusionStatus::kStarted);
  EXPECT_EQ(Count(run, FusionStatus::kFused), kFrames - 1);
  // Measured: worst pose error 1.41 mm over the turn, mesh 0.25 mm from the surface.
  EXPECT_LT(run.pose_error_mm, 3.0);
  EXPECT_LT(MeshError(run.mesh, axes), 0.5);
  // Coverage: one view sees the directions within 75° of the camera's, (1 - cos 75°) / 2 =
  // 37.1 % of them; the turn about an axis 100.9° from the camera's direction sweeps the
  // directions 25.9°-175.9° from that axis, (cos 25.9° - cos 175.9°) / 2 = 94.9 %.
  EXPECT_NEAR(run.results.front().coverage, 0.371, 0.02);
  EXPECT_NEAR(run.results.back().coverage, 0.949, 0.02);
  for (int i = 1; i < kFrames; ++i) EXPECT_GE(run.results[i].coverage, run.results[i - 1].coverage);
}

TEST(ObjectFusionTest, OnASphereOnlyTheContactsKeepTheTurn) {
  // A sphere looks the same however it turns: ICP alone cannot see the rotation, the fingertips
  // can (the paper's case).
  const Eigen::Vector3d sphere = Eigen::Vector3d::Constant(35);
  const SequenceRun icp_only = FuseSequence(sphere, 0, {});
  const SequenceRun with_contacts = FuseSequence(sphere, 6, {});
  FusionOptions no_icp;
  no_icp.use_icp = false;
  const SequenceRun contacts_only = FuseSequence(sphere, 6, no_icp);
  std::printf(
      "sphere: worst pose error ICP only %.1f mm, contacts + ICP %.2f mm, contacts only "
      "%.2f mm\n",
      icp_only.pose_error_mm, with_contacts.pose_error_mm, contacts_only.pose_error_mm);
  // Measured: 69.8 mm with ICP alone, 5.2 mm with the contacts (0.3 mm of noise each, adding
  // up over the turn; they weigh in ICP as their 0.46 mm of disagreement earns), 4.6 mm with
  // the contacts alone.
  EXPECT_GT(icp_only.pose_error_mm, 20.0);
  EXPECT_LT(with_contacts.pose_error_mm, 7.0);
  EXPECT_LT(contacts_only.pose_error_mm, 7.0);
  EXPECT_EQ(Count(contacts_only, FusionStatus::kFused), kFrames - 1);
}

TEST(ObjectFusionTest, LooseContactsCountOnlyWhereTheSurfaceLeavesATurnFree) {
  // Contacts the tracker found only past FusionOptions::loose_contact_mm: on a flat ellipsoid,
  // whose surface fixes its motion, they are left out and ICP follows it alone (the 45 x 30 x
  // 18 mm one's cap fixes a turn too weakly: IcpOptions::min_constraint_over_noise); on the
  // sphere, whose surface leaves every turn free, they keep its turn as firm ones do. Measured:
  // used in 89 / 0 / 88 frames, worst pose error 1.95 / 2.16 / 6.98 mm.
  const Eigen::Vector3d axes(50, 28, 12), sphere = Eigen::Vector3d::Constant(35);
  const SequenceRun firm = FuseSequence(axes, 6, {}, 0, 0, 5.0);
  const SequenceRun loose = FuseSequence(axes, 6, {}, 0, 0, 15.0);
  const SequenceRun loose_on_sphere = FuseSequence(sphere, 6, {}, 0, 0, 15.0);
  auto used = [](const SequenceRun& run) {
    return std::count_if(run.results.begin(), run.results.end(),
                         [](const FusionResult& r) { return r.ContactsUsed(); });
  };
  std::printf(
      "contacts used in %d / %d / %d frames (ellipsoid firm, loose; sphere loose), worst pose "
      "error %.2f / %.2f / %.2f mm\n",
      static_cast<int>(used(firm)), static_cast<int>(used(loose)),
      static_cast<int>(used(loose_on_sphere)), firm.pose_error_mm, loose.pose_error_mm,
      loose_on_sphere.pose_error_mm);
  EXPECT_GE(used(firm), kFrames - 2);
  EXPECT_EQ(used(loose), 0);
  EXPECT_LT(loose.pose_error_mm, 3.0);
  EXPECT_GE(used(loose_on_sphere), kFrames - 3);
  EXPECT_LT(loose_on_sphere.pose_error_mm, 7.0);
}

TEST(ObjectFusionTest, OneFingertipsPatchKeepsASpheresTurnTogetherWithTheSurface) {
  // Six contacts 5 mm round one point of the ball (one fingertip: spread 3.5 mm, under the
  // registration's 20 mm): alone they fix a point, not the turn, so the registration does not
  // use them; in ICP, whose surface fixes everything but the ball's turns about its centre,
  // their shift 35 mm from the centre is that turn, about the two axes across the patch. The
  // twist about the patch's own normal only its 5 mm radius fixes: with 0.3 mm of noise per
  // contact that drifts by about 1.4° a frame.
  const Eigen::Vector3d sphere = Eigen::Vector3d::Constant(35);
  const SequenceRun patch = FuseSequence(sphere, 6, {}, 0, 5.0);
  FusionOptions need_spread;
  need_spread.icp_contacts_need_spread = true;
  const SequenceRun spread_rule = FuseSequence(sphere, 6, need_spread, 0, 5.0);
  std::printf("sphere, one fingertip's patch: worst pose error %.2f mm (spread rule: %.1f mm)\n",
              patch.pose_error_mm, spread_rule.pose_error_mm);
  EXPECT_EQ(Count(patch, FusionStatus::kFused), kFrames - 1);
  for (const FusionResult& result : patch.results) EXPECT_EQ(result.pairwise.contacts, 0);
  // Measured: 12.4 mm worst over the turn (the twist about the patch's normal), 69.8 mm with
  // the spread rule (ICP alone).
  EXPECT_GT(spread_rule.pose_error_mm, 40.0);
  EXPECT_LT(patch.pose_error_mm, 20.0);
  EXPECT_LT(patch.pose_error_mm, 0.3 * spread_rule.pose_error_mm);
}

TEST(ObjectFusionTest, AnchoredFeaturesKeepASpheresTurnFromWalking) {
  // Feature matches with 1 mm of noise at each sighting on a ball, whose surface leaves every
  // turn free, their turn shrunk each frame by a prior of 1° (FusionOptions::
  // free_turn_visual_prior_deg; 0 by default): matched frame to frame only, what each frame
  // loses of the ball's 4° is lost for good and the pose walks; held at their anchors (the mean
  // of where each was seen on the ball), the next frame's pairs show it again.
  // Measured: 59.6 mm frame to frame, 11.5 mm anchored.
  const Eigen::Vector3d sphere = Eigen::Vector3d::Constant(35);
  FusionOptions frame_to_frame;
  frame_to_frame.free_turn_visual_prior_deg = 1.0;
  frame_to_frame.anchor_features = false;
  FusionOptions anchored = frame_to_frame;
  anchored.anchor_features = true;
  const SequenceRun walking = FuseSequence(sphere, 0, frame_to_frame, 0, 0, 0, 40);
  const SequenceRun held = FuseSequence(sphere, 0, anchored, 0, 0, 0, 40);
  int anchored_pairs = 0;
  for (const FusionResult& result : held.results) anchored_pairs += result.anchored_features;
  std::printf(
      "sphere, features only: worst pose error %.2f mm frame to frame, %.2f mm anchored (%d "
      "pairs anchored)\n",
      walking.pose_error_mm, held.pose_error_mm, anchored_pairs);
  EXPECT_EQ(Count(held, FusionStatus::kFused), kFrames - 1);
  for (const FusionResult& result : walking.results) EXPECT_EQ(result.anchored_features, 0);
  EXPECT_GT(anchored_pairs, 4 * kFrames);
  EXPECT_LT(held.pose_error_mm, 0.5 * walking.pose_error_mm);
}

TEST(ObjectFusionTest, WhereTheSurfaceLeavesTheTurnFreeAWholeFeatureSetKeepsItsTurn) {
  // A ball turned 4° a frame with features all over it (40 spots, about 14 in view): once ICP
  // has seen the surface leave its turns free, the features' turn is kept as fitted; shrunk by
  // a prior of 1° a frame (the pairwise default, kept where the surface fixes the turn) it is
  // cut every frame and the ball falls behind. With 24 spots (about 8 pairs a frame) the sets are
  // too small to be trusted there (FusionOptions::free_turn_min_visual_inliers): they are left
  // to ICP and the contacts. Measured: 2.3 / 59.6 mm worst pose error; the small sets used in
  // 0 of the last 45 frames, 45 where sets of 3 are allowed (6, the pairwise default, then).
  const Eigen::Vector3d sphere = Eigen::Vector3d::Constant(35);
  FusionOptions shrunk;
  shrunk.free_turn_visual_prior_deg = 1.0;
  const SequenceRun kept = FuseSequence(sphere, 0, {}, 0, 0, 0, 40);
  const SequenceRun cut = FuseSequence(sphere, 0, shrunk, 0, 0, 0, 40);
  const SequenceRun few = FuseSequence(sphere, 0, {}, 0, 0, 0, 24);
  FusionOptions any_set;
  any_set.free_turn_min_visual_inliers = 3;
  const SequenceRun few_taken = FuseSequence(sphere, 0, any_set, 0, 0, 0, 24);
  auto registered = [](const SequenceRun& run) {
    return std::count_if(run.results.begin() + kFrames / 2, run.results.end(),
                         [](const FusionResult& r) { return r.pairwise.visual_inliers > 0; });
  };
  std::printf(
      "ball, features only: worst pose error %.2f mm kept, %.2f mm shrunk; about 8 pairs a frame "
      "registered %d of the last %d frames (%d with sets of 3 allowed)\n",
      kept.pose_error_mm, cut.pose_error_mm, static_cast<int>(registered(few)), kFrames / 2,
      static_cast<int>(registered(few_taken)));
  EXPECT_LT(kept.pose_error_mm, 5.0);
  EXPECT_GT(cut.pose_error_mm, 20.0);
  EXPECT_EQ(registered(few), 0);
  EXPECT_GT(registered(few_taken), kFrames / 4);
}

TEST(ObjectFusionTest, NoisyContactsWeighLessInIcp) {
  // Contacts 2 mm off together in every frame (a poorly tracked hand) on the ellipsoid, whose
  // surface fixes every direction: ICP weighs them by how well they agree with its motion, so
  // they cannot drag it; with their weight fixed at the share meant for accurate contacts they
  // do.
  const Eigen::Vector3d axes(45, 30, 18);
  const SequenceRun adaptive = FuseSequence(axes, 6, {}, 2.0);
  FusionOptions fixed;
  fixed.contact_noise_reference_mm = 0;
  const SequenceRun fixed_share = FuseSequence(axes, 6, fixed, 2.0);
  std::printf(
      "ellipsoid, contacts 2 mm off: contact noise estimate %.2f mm, worst pose error %.2f mm "
      "(fixed share: %.2f mm)\n",
      adaptive.results.back().contact_noise_mm, adaptive.pose_error_mm, fixed_share.pose_error_mm);
  // Measured: estimate 2.90 mm (the contacts are 3.5 mm off on average), worst pose error
  // 4.36 mm; 17.3 mm with the fixed share.
  EXPECT_GT(adaptive.results.back().contact_noise_mm, 1.5);
  EXPECT_LT(adaptive.pose_error_mm, 6.0);
  EXPECT_LT(adaptive.pose_error_mm, 0.5 * fixed_share.pose_error_mm);
}

// The worst pose error (mm, at the ellipsoid's extreme points) of ICP alone on an ellipsoid
// turned `degrees_per_frame` about a tilted axis for `frames` frames, and in how many frames
// ICP left a direction free.
std::pair<double, int> FastTurnWithIcpAlone(double degrees_per_frame, int frames,
                                            const FusionOptions& options) {
  const Eigen::Vector3d axes(45, 30, 18);
  const auto truth = [&](int i) {
    return Rigid3::Translation({5, -10, 600}) *
           Rigid3::FromAxisAngle(Eigen::Vector3d(0.3, 1, 0.2), i * degrees_per_frame * M_PI / 180) *
           Rigid3::FromAxisAngle({1, 0, 0}, 0.3);
  };
  ObjectFusion fusion(kIntrinsics, options);
  Rigid3 object_from_volume;
  double worst = 0;
  int left_free = 0;
  for (int i = 0; i < frames; ++i) {
    const Frame frame = test::RenderEllipsoid(kIntrinsics, truth(i), axes);
    std::vector<std::uint8_t> mask(frame.depth_mm.size());
    for (size_t p = 0; p < mask.size(); ++p) mask[p] = frame.depth_mm[p] != 0;
    const FusionResult result = fusion.Fuse({&frame, &mask, {}});
    if (i == 0) object_from_volume = truth(0).Inverse() * result.cam_from_object;
    left_free += result.icp.free_directions > 0 ? 1 : 0;
    worst = std::max(worst, WorstPointError(result.cam_from_object, truth(i), object_from_volume,
                                            AxisEnds(axes, false)));
  }
  return {worst, left_free};
}

TEST(ObjectFusionTest, AStartThatLeavesIcpFewerPairsThanTheLastFrameIsTriedFromWhereItWas) {
  // Mid-turn, the fingertips jump 11 mm together: the contacts alone say the object moved
  // there, and ICP from there, held by those contacts, stays 10 mm off with 74 % of the
  // object's points paired, 78 % of what the frame before paired (the retry's absolute
  // threshold, 70 %, does not see it). Tried from where the object was, ICP pairs 29 % more and
  // keeps the truth.
  const Eigen::Vector3d axes(45, 30, 18);
  FusionOptions without;
  without.icp_retry_drop = 0;
  const Eigen::Vector3d jolt(8, 8, 0);
  const SequenceRun kept = FuseSequence(axes, 6, without, 0, 0, 0, 0, jolt);
  const SequenceRun retried = FuseSequence(axes, 6, {}, 0, 0, 0, 0, jolt);
  const FusionResult& before = retried.results[kFrames / 2 - 1];
  const FusionResult& jolted = kept.results[kFrames / 2];
  std::printf(
      "fingertips jumping 11 mm: worst pose error %.2f mm kept (%d of %d points paired, %d the "
      "frame before), %.2f mm retried\n",
      kept.pose_error_mm, jolted.icp.inliers, jolted.icp.points, before.icp.inliers,
      retried.pose_error_mm);
  // Measured: 9.94 mm kept, 1.42 mm retried (as without the jump).
  EXPECT_GT(kept.pose_error_mm, 5.0);
  EXPECT_LT(retried.pose_error_mm, 2.5);
  EXPECT_FALSE(jolted.icp_from_previous);
  EXPECT_TRUE(retried.results[kFrames / 2].icp_from_previous);
}

TEST(ObjectFusionTest, AFastTurnNothingRegistersIsPredictedFromTheLastMotion) {
  // No features, no contacts: only ICP, from the predicted pose. Standing still as the
  // prediction, a turn of 10° a frame leaves ICP too far to come back; moving on as in the last
  // frame, it starts near the truth. At 4° a frame both follow.
  // ICP's surface alone: the outline is off as in FuseSequence (with it 2.31 / 1.96 mm at 4°,
  // 6.16 / 6.47 mm at 10°).
  FusionOptions standing_still;
  standing_still.silhouette.weight = 0;
  FusionOptions moving_on = standing_still;
  moving_on.predict_moving = true;
  for (const double rate : {4.0, 10.0}) {
    const auto [moving, moving_free] = FastTurnWithIcpAlone(rate, 24, moving_on);
    const auto [standing, standing_free] = FastTurnWithIcpAlone(rate, 24, standing_still);
    std::printf(
        "%.0f° a frame: worst pose error %.2f mm moving on (%d frames with a free direction), "
        "%.2f mm standing still\n",
        rate, moving, moving_free, standing);
    // Measured: 1.31 / 1.31 mm at 4°, 3.92 / 8.05 mm at 10°.
    if (rate < 5) {
      EXPECT_NEAR(moving, standing, 0.3);
      EXPECT_LT(moving, 2.0);
    } else {
      EXPECT_LT(moving, 5.0);
      EXPECT_LT(moving, 0.6 * standing);
    }
  }
}

TEST(ObjectFusionTest, FramesThatShowTheObjectMostlyHiddenAreTrackedNotIntegrated) {
  // The ellipsoid's turn where, in frames 30-44, a hand 40 mm in front covers all of it but a
  // strip along its left edge (a sixth to a quarter of its points): those frames are registered
  // and tracked, but the model is left as it was; the frames around them are integrated.
  const Eigen::Vector3d axes(45, 30, 18);
  constexpr int kHideFrom = 30, kHideTo = 45;
  FusionOptions options;
  options.colour.enabled = false;
  options.silhouette.weight = 0;
  options.pairwise.visual_turn_prior_deg = 0;  // The features' own turn, as exact as they are.
  ObjectFusion fusion(kIntrinsics, options);
  const std::vector<Eigen::Vector3d> spots = SurfaceSpots(axes, 400);
  Rigid3 object_from_volume;
  double worst_mm = 0;
  std::vector<int> hidden, integrated;
  size_t vertices_before = 0;
  for (int i = 0; i < kHideTo + 5; ++i) {
    Frame frame = test::RenderEllipsoid(kIntrinsics, Truth(i), axes);
    std::vector<std::uint8_t> mask(frame.depth_mm.size());
    int left = frame.width;
    for (size_t p = 0; p < mask.size(); ++p) {
      mask[p] = frame.depth_mm[p] != 0;
      if (mask[p]) left = std::min(left, static_cast<int>(p % frame.width));
    }
    if (i >= kHideFrom && i < kHideTo) {
      for (size_t p = 0; p < mask.size(); ++p) {
        if (mask[p] && static_cast<int>(p % frame.width) > left + 15) {
          mask[p] = 0;
          frame.depth_mm[p] -= 40;
        }
      }
    }
    // Features on what the frame shows of the object (the strip's, while it is covered).
    FusionInput input{&frame, &mask, {}};
    for (size_t k = 0; i > 0 && k < spots.size(); ++k) {
      const Eigen::Vector3d before = Truth(i - 1) * spots[k], now = Truth(i) * spots[k];
      const Eigen::Vector2d pixel = kIntrinsics.Project(now);
      if (!kIntrinsics.Contains(pixel.x(), pixel.y())) continue;
      const size_t at =
          static_cast<size_t>(pixel.y()) * frame.width + static_cast<size_t>(pixel.x());
      if (!mask[at] || std::abs(frame.depth_mm[at] - now.z()) > 2) continue;
      input.correspondences.Pairs("sift", MatchKind::kVisual)
          .push_back({before, now, static_cast<int>(k)});
    }
    if (i == kHideFrom) vertices_before = fusion.ExtractMesh().vertices.size();
    const FusionResult result = fusion.Fuse(input);
    ASSERT_NE(result.status, FusionStatus::kSkipped) << "frame " << i << ": " << result.reason;
    if (result.hidden) hidden.push_back(i);
    if (result.integrated_voxels > 0) integrated.push_back(i);
    if (i == kHideTo - 1) {
      EXPECT_EQ(fusion.ExtractMesh().vertices.size(), vertices_before);
    }
    if (i == 0) object_from_volume = Truth(0).Inverse() * result.cam_from_object;
    worst_mm = std::max(worst_mm, WorstPointError(result.cam_from_object, Truth(i),
                                                  object_from_volume, AxisEnds(axes, false)));
  }
  std::printf(
      "ellipsoid mostly hidden in frames %d-%d: %zu frames held out, worst pose error %.2f mm\n",
      kHideFrom, kHideTo - 1, hidden.size(), worst_mm);
  ASSERT_EQ(hidden.size(), static_cast<size_t>(kHideTo - kHideFrom));
  EXPECT_EQ(hidden.front(), kHideFrom);
  EXPECT_EQ(hidden.back(), kHideTo - 1);
  EXPECT_EQ(integrated.size(), static_cast<size_t>(kHideTo + 5 - (kHideTo - kHideFrom)));
  // Measured: 0.80 mm.
  EXPECT_LT(worst_mm, 3.0);
}

TEST(ObjectFusionTest, AFlatObjectTurnedEdgeOnIsIntegratedThoughItShowsFewPoints) {
  // The flat ellipsoid of the loose contacts' test turned edge-on shows a third of its most
  // points with nothing covering it. By the point count alone those frames are held out as
  // hidden, the model never sees its edge, and ICP alone loses it; but such a frame shows all
  // that the model says is in view at its pose (HiddenOptions::shown_share), and with that
  // checked none is held out.
  const Eigen::Vector3d axes(50, 28, 12);
  FusionOptions count_alone;
  count_alone.hidden.shown_share = 0;
  const FusionOptions shown;
  const SequenceRun by_count = FuseSequence(axes, 6, count_alone, 0, 0, 15.0);
  const SequenceRun by_shown = FuseSequence(axes, 6, shown, 0, 0, 15.0);
  auto hidden = [](const SequenceRun& run) {
    return std::count_if(run.results.begin(), run.results.end(),
                         [](const FusionResult& r) { return r.hidden; });
  };
  std::printf(
      "flat ellipsoid: %d frames held out by the point count alone (worst pose error %.1f mm), "
      "%d with what the model shows checked (%.2f mm)\n",
      static_cast<int>(hidden(by_count)), by_count.pose_error_mm,
      static_cast<int>(hidden(by_shown)), by_shown.pose_error_mm);
  EXPECT_GT(hidden(by_count), 0);
  EXPECT_EQ(hidden(by_shown), 0);
  EXPECT_EQ(Count(by_shown, FusionStatus::kFused), kFrames - 1);
  EXPECT_LT(by_shown.pose_error_mm, 3.0);
}

TEST(ObjectFusionTest, EmptyFramesAndImplausibleJumpsAreSkippedWithAReason) {
  const Eigen::Vector3d axes(45, 30, 18);
  ObjectFusion fusion(kIntrinsics);
  const Frame empty = Frame::Blank(640, 480, true);
  const std::vector<std::uint8_t> no_mask(empty.depth_mm.size(), 0);
  FusionResult result = fusion.Fuse({&empty, &no_mask, {}, {}});
  EXPECT_EQ(result.status, FusionStatus::kSkipped);
  EXPECT_NE(result.reason.find("too few object points"), std::string::npos) << result.reason;
  EXPECT_FALSE(fusion.started());

  const Frame first = test::RenderEllipsoid(kIntrinsics, Truth(0), axes);
  std::vector<std::uint8_t> mask(first.depth_mm.size());
  for (size_t p = 0; p < mask.size(); ++p) mask[p] = first.depth_mm[p] != 0;
  EXPECT_EQ(fusion.Fuse({&first, &mask, {}}).status, FusionStatus::kStarted);
  // Contacts that claim the object jumped 80 mm: not integrated.
  FusionInput jump{&first, &mask, {}};
  for (int k = 0; k < 5; ++k) {
    const Eigen::Vector3d p = Truth(0) * Eigen::Vector3d(10.0 * k, 5.0 * k * k, 1.0 * k);
    jump.correspondences.Pairs("contacts", MatchKind::kContact)
        .push_back({p, p + Eigen::Vector3d(80, 0, 0)});
  }
  FusionOptions no_icp;
  no_icp.use_icp = false;
  ObjectFusion contacts_only(kIntrinsics, no_icp);
  contacts_only.Fuse({&first, &mask, {}, {}});
  result = contacts_only.Fuse(jump);
  EXPECT_EQ(result.status, FusionStatus::kSkipped);
  EXPECT_NE(result.reason.find("implausible jump"), std::string::npos) << result.reason;
}

TEST(ObjectFusionTest, AJumpThatHoldsIsTheObjectsAndIsTaken) {
  // Ten frames of a 40 mm cube's turn, then the cube as it is 32° further on, in five frames:
  // it turned, with the hand that holds it, while nothing of it was seen. ICP finds it there
  // from the last pose, a step past FusionOptions::max_jump_deg: refused in the first two
  // frames; found again, within the limits of the last, in a third, the jump has held and is
  // taken. Not where the hand did not turn with it, nor with jump_held_frames 0. (On the smooth
  // ellipsoid ICP walks there a few degrees a frame instead: no jump.)
  // Three corners of the cube (object frame).
  std::vector<Eigen::Vector3d> corners;
  for (int axis = 0; axis < 3; ++axis) {
    corners.push_back(Eigen::Vector3d::Constant(test::kCubeEdgeMm / 2));
    corners.back()[axis] *= -1;
  }
  constexpr int kSeen = 10, kAfter = 5, kSkippedTurn = 8;
  auto run = [&](int held_frames, bool hand_turns, std::vector<FusionResult>* results) {
    FusionOptions options;
    options.jump_held_frames = held_frames;
    ObjectFusion fusion(kIntrinsics, options);
    Rigid3 object_from_volume;
    double worst_mm = 0;
    int previous = 0;
    for (int i = 0; i < kSeen + kAfter; ++i) {
      const int truth = i < kSeen ? i : kSeen - 1 + kSkippedTurn;
      const Frame frame = test::CubeView(kIntrinsics, Truth(truth)).frame;
      std::vector<std::uint8_t> mask(frame.depth_mm.size());
      for (size_t p = 0; p < mask.size(); ++p) mask[p] = frame.depth_mm[p] != 0;
      FusionInput input{&frame, &mask, {}};
      // The hand's root turns with the object (or stays where it was).
      input.hand_motion = hand_turns ? Truth(truth) * Truth(previous).Inverse() : Rigid3();
      previous = truth;
      const FusionResult result = fusion.Fuse(input);
      if (i == 0) object_from_volume = Truth(0).Inverse() * result.cam_from_object;
      if (i >= kSeen) results->push_back(result);
      if (result.status == FusionStatus::kSkipped) continue;
      worst_mm = std::max(worst_mm, WorstPointError(result.cam_from_object, Truth(truth),
                                                    object_from_volume, corners));
    }
    return worst_mm;
  };
  std::vector<FusionResult> taken, refused, hand_still;
  const double taken_mm = run(3, true, &taken);
  run(0, true, &refused);
  run(3, false, &hand_still);
  std::printf("a held jump: taken in frame %d after the turn, worst pose error %.2f mm\n",
              static_cast<int>(std::find_if(taken.begin(), taken.end(),
                                            [](const FusionResult& r) { return r.jump_taken; }) -
                               taken.begin()),
              taken_mm);
  for (int k = 0; k < kAfter; ++k) {
    for (const FusionResult& result : {refused[k], hand_still[k]}) {
      EXPECT_EQ(result.status, FusionStatus::kSkipped) << k;
      EXPECT_NE(result.reason.find("implausible jump"), std::string::npos) << result.reason;
    }
    EXPECT_EQ(taken[k].status, k < 2 ? FusionStatus::kSkipped : FusionStatus::kFused) << k;
    EXPECT_EQ(taken[k].jump_taken, k == 2) << k;
  }
  EXPECT_LT(taken_mm, 3.0);
}

// A box of `half_mm` half-extents at `cam_from_box`, in front of a wall `wall_mm` from the
// camera; pixels left of image column `hand_to_u` (and right of the box's left edge) see a
// hand 30 mm in front of the box instead. The mask: the box's pixels the hand does not cover.
struct BoxScene {
  Frame frame;
  std::vector<std::uint8_t> mask;
};
BoxScene RenderBoxScene(const Rigid3& cam_from_box, const Eigen::Vector3d& half_mm, double wall_mm,
                        int hand_to_u) {
  BoxScene scene{Frame::Blank(kIntrinsics.width, kIntrinsics.height, true), {}};
  scene.mask.assign(scene.frame.depth_mm.size(), 0);
  const Rigid3 box_from_cam = cam_from_box.Inverse();
  const Eigen::Vector3d origin = box_from_cam.translation();
  for (int v = 0; v < kIntrinsics.height; ++v) {
    for (int u = 0; u < kIntrinsics.width; ++u) {
      const int pixel = v * kIntrinsics.width + u;
      const Eigen::Vector3d ray = box_from_cam.RotateVector(kIntrinsics.BackProject(u, v, 1.0));
      double enter = 0, leave = std::numeric_limits<double>::infinity();
      for (int axis = 0; axis < 3; ++axis) {
        const double a = (-half_mm[axis] - origin[axis]) / ray[axis];
        const double b = (half_mm[axis] - origin[axis]) / ray[axis];
        enter = std::max(enter, std::min(a, b));
        leave = std::min(leave, std::max(a, b));
      }
      const bool box = enter <= leave;
      const bool hand = box && u < hand_to_u;
      const double depth = hand ? enter - 30 : box ? enter : wall_mm;
      scene.frame.depth_mm[pixel] = static_cast<std::uint16_t>(std::lround(depth));
      scene.mask[pixel] = box && !hand;
      const std::uint8_t grey = box ? 150 : 60;
      for (int c = 0; c < 3; ++c) scene.frame.rgb[3 * pixel + c] = grey;
    }
  }
  return scene;
}

TEST(ObjectFusionTest, APoseSlidAlongAFaceIsMovedBackByWhatTheFrameSeesThrough) {
  // A 90 x 60 x 40 mm box, one face to the camera, moves 3 mm a frame to the left in front of
  // a wall; a hand covers its left 25 mm, and in frames 8-13 all of it. Features on the face
  // register each frame to the one before; the first frame after the hidden ones has none (the
  // frame before did not show them) and only ICP registers it. Found again 21 mm on from where
  // it was last seen, ICP slides the model along the face, which fixes no slide, and keeps it
  // there; the model then overhangs the box's right edge onto the wall. Tried again from where the
  // model's uncovered part lies on the box's points, ICP keeps the truth. The outline's term
  // (silhouette.h) is off: in this clean scene it walks ICP to the box's edges by itself (3.05
  // mm either way); in a generated cube turn found again 20 mm off after ten unseen frames, the
  // hand over its edges, it did not (docs/fusion.md, "A pose the frame sees through").
  const Eigen::Vector3d half(45, 30, 20);
  constexpr int kFrames = 22, kHideFrom = 8, kHideTo = 14;
  auto truth = [](int i) { return Rigid3::Translation({30.0 - 3 * i, 5, 600}); };
  std::vector<Eigen::Vector3d> spots;  // On the face, right of the hand (box frame).
  for (int k = 0; k < 40; ++k) {
    spots.emplace_back(-15 + 55.0 * (k % 8) / 7, -25 + 50.0 * (k / 8) / 4, -half.z());
  }
  auto run = [&](const FusionOptions& options, std::vector<FusionResult>* results) {
    ObjectFusion fusion(kIntrinsics, options);
    double worst_mm = 0;
    Rigid3 box_from_volume;
    for (int i = 0; i < kFrames; ++i) {
      const bool hidden = i >= kHideFrom && i < kHideTo;
      const int hand_to_u =
          hidden ? kIntrinsics.width
                 : static_cast<int>(
                       kIntrinsics.Project(truth(i) * Eigen::Vector3d(-half.x() + 25, 0, -half.z()))
                           .x());
      const BoxScene scene = RenderBoxScene(truth(i), half, 900, hand_to_u);
      FusionInput input{&scene.frame, &scene.mask, {}};
      const bool seen_before = i > 0 && !(i - 1 >= kHideFrom && i - 1 < kHideTo);
      for (size_t k = 0; seen_before && !hidden && k < spots.size(); ++k) {
        input.correspondences.Pairs("sift", MatchKind::kVisual)
            .push_back({truth(i - 1) * spots[k], truth(i) * spots[k], static_cast<int>(k)});
      }
      results->push_back(fusion.Fuse(input));
      if (i == 0) box_from_volume = truth(0).Inverse() * results->back().cam_from_object;
      if (hidden) continue;
      worst_mm = std::max(worst_mm, WorstPointError(results->back().cam_from_object, truth(i),
                                                    box_from_volume, {half, -half}));
    }
    return worst_mm;
  };
  FusionOptions checked;
  checked.silhouette.weight = 0;
  FusionOptions unchecked = checked;
  unchecked.see_through.max_share = 0;
  std::vector<FusionResult> unchecked_results, checked_results;
  const double unchecked_mm = run(unchecked, &unchecked_results);
  const double checked_mm = run(checked, &checked_results);
  const FusionResult& found = checked_results[kHideTo];
  std::printf(
      "a box found again 21 mm on: worst pose error %.2f mm unchecked, %.2f mm checked (%.1f %% "
      "of the model seen through, moved: %d)\n",
      unchecked_mm, checked_mm, 100 * found.see_through_share, found.see_through_moved);
  EXPECT_GT(unchecked_mm, 10.0);
  EXPECT_LT(checked_mm, 3.0);
  EXPECT_TRUE(found.see_through_moved);
  for (int i = 1; i < kFrames; ++i) {
    if (i >= kHideFrom && i < kHideTo) {
      EXPECT_EQ(checked_results[i].status, FusionStatus::kSkipped) << i;
      continue;
    }
    EXPECT_LE(checked_results[i].see_through_share, checked.see_through.max_share) << i;
    EXPECT_FALSE(checked_results[i].see_through_held) << i;
  }
}

TEST(ObjectFusionTest, AModelPartTheFramesNoLongerShowHoldsFramesOutOnlyForAWhile) {
  // The box face of the test above, moving 1 mm a frame, registered by its features; in frames
  // 0-5 a 60 x 18 mm finger beside it is in the object's mask (the segmentation's mistake) and
  // is fused into the model. From frame 6 it is gone: at the right pose every frame sees the
  // wall through it (12-14 % of the model's samples). The pose is not tried elsewhere (that
  // pairs fewer points); the frames are held out for SeeThroughOptions::max_held_frames in a
  // row, then integrated as registered, and the scan goes on.
  const Eigen::Vector3d half(45, 30, 20), finger_half(30, 9, 9);
  constexpr int kFrames = 30, kFingerTo = 6;
  auto truth = [](int i) { return Rigid3::Translation({10.0 - i, 5, 600}); };
  std::vector<Eigen::Vector3d> spots;  // On the face, right of the hand (box frame).
  for (int k = 0; k < 40; ++k) {
    spots.emplace_back(-15 + 55.0 * (k % 8) / 7, -25 + 50.0 * (k / 8) / 4, -half.z());
  }
  ObjectFusion fusion(kIntrinsics);
  const int max_held = SeeThroughOptions().max_held_frames;
  Rigid3 box_from_volume;
  double worst_mm = 0;
  std::vector<int> held, integrated;
  for (int i = 0; i < kFrames; ++i) {
    const int hand_to_u = static_cast<int>(
        kIntrinsics.Project(truth(i) * Eigen::Vector3d(-half.x() + 25, 0, -half.z())).x());
    BoxScene scene = RenderBoxScene(truth(i), half, 900, hand_to_u);
    if (i < kFingerTo) {
      const Rigid3 cam_from_finger =
          truth(i) * Rigid3::Translation({half.x() + 25, 10, -half.z() + finger_half.z()});
      const BoxScene finger = RenderBoxScene(cam_from_finger, finger_half, 900, 0);
      for (size_t p = 0; p < scene.mask.size(); ++p) {
        if (!finger.mask[p] || finger.frame.depth_mm[p] >= scene.frame.depth_mm[p]) continue;
        scene.frame.depth_mm[p] = finger.frame.depth_mm[p];
        scene.mask[p] = 1;
      }
    }
    FusionInput input{&scene.frame, &scene.mask, {}};
    for (size_t k = 0; i > 0 && k < spots.size(); ++k) {
      input.correspondences.Pairs("sift", MatchKind::kVisual)
          .push_back({truth(i - 1) * spots[k], truth(i) * spots[k], static_cast<int>(k)});
    }
    const FusionResult result = fusion.Fuse(input);
    ASSERT_NE(result.status, FusionStatus::kSkipped) << i << ": " << result.reason;
    if (i == 0) box_from_volume = truth(0).Inverse() * result.cam_from_object;
    worst_mm = std::max(worst_mm, WorstPointError(result.cam_from_object, truth(i), box_from_volume,
                                                  {half, -half}));
    EXPECT_FALSE(result.see_through_moved) << i;
    if (i >= kFingerTo) {
      EXPECT_GT(result.see_through_share, 0.05) << i;
    }
    if (result.see_through_held) held.push_back(i);
    if (result.integrated_voxels > 0) integrated.push_back(i);
  }
  std::printf(
      "a finger fused into the model: %zu frames held out (%d-%d), worst pose error %.2f mm\n",
      held.size(), held.empty() ? -1 : held.front(), held.empty() ? -1 : held.back(), worst_mm);
  ASSERT_EQ(held.size(), static_cast<size_t>(max_held));
  EXPECT_EQ(held.front(), kFingerTo);
  EXPECT_EQ(held.back(), kFingerTo + max_held - 1);
  EXPECT_EQ(integrated.size(), static_cast<size_t>(kFrames - max_held));
  EXPECT_LT(worst_mm, 3.0);
}

}  // namespace
}  // namespace ihs::fusion
