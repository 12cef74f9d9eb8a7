#include "fusion/object_fusion.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "core/check.h"
#include "core/stopwatch.h"

namespace ihs::fusion {

const char* ToString(FusionStatus status) {
  switch (status) {
    case FusionStatus::kStarted:
      return "started";
    case FusionStatus::kFused:
      return "fused";
    case FusionStatus::kSkipped:
      return "skipped";
  }
  return "unknown";
}

void FusionOptions::Check() const {
  tsdf.Check();
  pairwise.Check();
  icp.Check();
  model_contacts.Check();
  coverage.Check();
  turn_carry.Check();
  free_space.Check();
  loop_closure.Check();
  colour.Check();
  silhouette.Check();
  hidden.Check();
  see_through.Check();
  IHS_CHECK_ARG(
      !model_contacts.enabled ||
          model_contacts.distance_mm < tsdf.truncation_voxels * tsdf.size_mm / tsdf.resolution,
      "fusion.model_contacts.distance_mm must be less than the TSDF's truncation");
  IHS_CHECK_ARG(min_object_points >= 10, "fusion.min_object_points must be >= 10");
  IHS_CHECK_ARG(loose_contact_mm > 0, "fusion.loose_contact_mm must be positive");
  IHS_CHECK_ARG(max_jump_mm > 0 && max_jump_deg > 0,
                "fusion.max_jump_mm and max_jump_deg must be positive");
  IHS_CHECK_ARG(jump_held_frames >= 0, "fusion.jump_held_frames must not be negative");
  IHS_CHECK_ARG(anchor_slip_mm > 0, "fusion.anchor_slip_mm must be positive");
  IHS_CHECK_ARG(free_turn_min_visual_inliers >= 3,
                "fusion.free_turn_min_visual_inliers must be at least 3");
  IHS_CHECK_ARG(free_turn_visual_prior_deg >= 0, "fusion.free_turn_visual_prior_deg must be >= 0");
  IHS_CHECK_ARG(contact_noise_reference_mm >= 0, "fusion.contact_noise_reference_mm must be >= 0");
  IHS_CHECK_ARG(icp_retry_fraction >= 0 && icp_retry_fraction <= 1,
                "fusion.icp_retry_fraction must be in [0, 1]");
  IHS_CHECK_ARG(icp_retry_drop >= 0 && icp_retry_drop <= 1,
                "fusion.icp_retry_drop must be in [0, 1]");
  IHS_CHECK_ARG(icp_retry_gain > 0, "fusion.icp_retry_gain must be positive");
  IHS_CHECK_ARG(std::isfinite(colour_still_margin),
                "fusion.colour_still_margin must be a finite number");
  IHS_CHECK_ARG(colour_recheck_frames >= 1, "fusion.colour_recheck_frames must be at least 1");
}

ObjectFusion::ObjectFusion(const CameraIntrinsics& intrinsics, FusionOptions options)
    : intrinsics_(intrinsics),
      options_((options.Check(), std::move(options))),
      volume_(options_.tsdf),
      coverage_(options_.coverage),
      free_space_(intrinsics, options_.free_space),
      contact_noise_mm_(options_.contact_noise_reference_mm),
      turn_carry_(options_.turn_carry),
      hidden_(options_.hidden),
      keyframes_(intrinsics, options_.loop_closure, options_.icp) {}

FusionResult ObjectFusion::Skip(std::string reason) const {
  FusionResult result;
  result.status = FusionStatus::kSkipped;
  result.reason = std::move(reason);
  result.cam_from_object = cam_from_object_;
  result.coverage = coverage_.Share();
  return result;
}

int ObjectFusion::AddModelContacts(const FusionInput& input,
                                   std::vector<PointMatch>* contacts) const {
  if (!options_.model_contacts.enabled || !input.hand || !input.fingertips ||
      previous_hand_.empty() || !started_) {
    return 0;
  }
  // Without ids the tracker's contacts cannot be told apart from the model's: none added.
  std::vector<int> known;
  for (const PointMatch& contact : *contacts) {
    if (contact.id < 0) return 0;
    known.push_back(contact.id);
  }
  const std::vector<ModelContact> found =
      FindModelContacts(volume_, cam_from_object_.Inverse(), previous_hand_, input.hand->vertices,
                        *input.fingertips, options_.model_contacts);
  std::sort(known.begin(), known.end());
  int added = 0;
  for (const ModelContact& contact : found) {
    if (std::binary_search(known.begin(), known.end(), contact.vertex)) continue;
    contacts->push_back({contact.previous, contact.current, contact.vertex});
    ++added;
  }
  return added;
}

int ObjectFusion::ApplyAnchors(const Anchors& anchors, std::vector<PointMatch>* pairs) const {
  int anchored = 0;
  for (PointMatch& pair : *pairs) {
    const auto found = pair.id < 0 ? anchors.end() : anchors.find(pair.id);
    if (found == anchors.end()) continue;
    pair.previous = cam_from_object_ * found->second.object_point;
    ++anchored;
  }
  return anchored;
}

void ObjectFusion::UpdateAnchors(const std::vector<PointMatch>& pairs,
                                 const Rigid3& cam_from_object, Anchors* anchors) const {
  Anchors held;
  const Rigid3 object_from_cam = cam_from_object.Inverse();
  for (const PointMatch& pair : pairs) {
    if (pair.id < 0) continue;
    const Eigen::Vector3d seen = object_from_cam * pair.current;
    Anchor anchor{seen, 1};
    const auto found = anchors->find(pair.id);
    if (found != anchors->end() &&
        (found->second.object_point - seen).norm() <= options_.anchor_slip_mm) {
      // The running mean of where the pair has been seen.
      anchor = found->second;
      ++anchor.observations;
      anchor.object_point += (seen - anchor.object_point) / anchor.observations;
    }
    held[pair.id] = anchor;
  }
  *anchors = std::move(held);
}

void ObjectFusion::UpdateFeatureAnchors(const PairwiseInput& correspondences,
                                        const Rigid3& cam_from_object) {
  if (!options_.anchor_features) return;
  for (const MatchSet& set : correspondences.sets) {
    if (set.kind == MatchKind::kVisual) {
      UpdateAnchors(set.pairs, cam_from_object, &feature_anchors_[set.source]);
    }
  }
}

int ObjectFusion::DropPairsMovingWith(const Rigid3& hand_motion,
                                      std::vector<PointMatch>* pairs) const {
  const double inlier_mm = options_.pairwise.inlier_mm;
  const auto moves_with_hand = [&](const PointMatch& pair) {
    const double with_hand = (hand_motion * pair.previous - pair.current).norm();
    return with_hand < inlier_mm && with_hand < (pair.previous - pair.current).norm();
  };
  const size_t before = pairs->size();
  pairs->erase(std::remove_if(pairs->begin(), pairs->end(), moves_with_hand), pairs->end());
  return static_cast<int>(before - pairs->size());
}

void ObjectFusion::MoveAnchors(const Rigid3& object_from_moved) {
  for (auto& [id, anchor] : anchors_) anchor.object_point = object_from_moved * anchor.object_point;
  for (auto& [source, anchors] : feature_anchors_) {
    for (auto& [id, anchor] : anchors)
      anchor.object_point = object_from_moved * anchor.object_point;
  }
}

void ObjectFusion::CatchUpTurn(FusionResult* result) {
  const double radians = turn_carry_.TakeCatchUp();
  if (radians <= 0 || !options_.turn_carry.enabled || !turn_carry_.SurfaceLeavesTurnFree()) return;
  const Rigid3 caught_up =
      turn_carry_.Turn(cam_from_object_, cam_from_object_ * pivot_in_object_, radians);
  // An anchor stays where the camera saw it; in the object frame it moves back by the turn.
  MoveAnchors(caught_up.Inverse() * cam_from_object_);
  cam_from_object_ = caught_up;
  result->hand_caught_up_deg = radians * 180.0 / M_PI;
}

FusionResult ObjectFusion::Fuse(const FusionInput& input) {
  const auto started_at = SteadyClock::now();
  IHS_CHECK_ARG(input.frame != nullptr && input.object_mask != nullptr,
                "Fuse needs a frame and its object mask");
  IHS_CHECK_ARG(input.object_mask->size() == input.frame->depth_mm.size(),
                "the object mask does not fit the frame");
  FusionResult result;
  result.cam_from_object = cam_from_object_;
  auto finish = [&](FusionStatus status, std::string reason = {}) {
    return Finish(input, started_at, status, std::move(reason), &result);
  };
  if (input.hand_motion) {
    hand_turn_since_ = *input.hand_motion * hand_turn_since_;
  } else {
    hand_turn_known_ = false;
  }
  const ObjectPixels object = FindObject(*input.frame, *input.object_mask);
  // Only where the surface fixes every direction (a box): elsewhere the model's shape does not
  // show a wrong turn about the free axis, and holding frames out lost more of it (small
  // bottles).
  result.hidden = hidden_.Observe(static_cast<int>(object.points.size())) &&
                  !turn_carry_.SurfaceLeavesTurnFree();
  if (static_cast<int>(object.points.size()) < options_.min_object_points) {
    return finish(FusionStatus::kSkipped,
                  "too few object points: " + std::to_string(object.points.size()) + " (need " +
                      std::to_string(options_.min_object_points) + ")");
  }
  if (!started_) {
    Start(input, object, &result);
    return finish(FusionStatus::kStarted);
  }

  // The correspondences' motion (or the hand's turn), then ICP from there.
  result.hand_turn = JudgeHandTurn(input);
  std::vector<PointMatch> contacts;
  // None where the hand turns back; the tracker's loose ones only where the surface leaves a
  // turn free.
  const bool firm_or_free =
      (!input.contacts_held && input.contact_threshold_mm <= options_.loose_contact_mm) ||
      turn_carry_.SurfaceLeavesTurnFree();
  Rigid3 pose =
      Register(input, result.hand_turn != HandTurn::kBack, firm_or_free, &contacts, &result);
  if (result.hand_turn == HandTurn::kOn && !result.pairwise.ok) {
    pose = turn_carry_.Carry(cam_from_object_, cam_from_object_ * pivot_in_object_);
    result.hand_carried_deg = turn_carry_.carried_rad() * 180.0 / M_PI;
  }
  if (options_.use_icp) {
    if (!Refine(object, contacts, &pose, &result)) {
      return finish(FusionStatus::kSkipped,
                    "no registration: " + result.pairwise.reason + "; " + result.icp.reason);
    }
  } else if (!result.pairwise.ok) {
    return finish(FusionStatus::kSkipped, "no registration: " + result.pairwise.reason);
  }

  if (result.hidden && options_.hidden.shown_share > 0) {
    result.hidden = ShowsLittleOfModel(object, pose);
  }
  if (result.see_through_held) result.hidden = true;
  // A patch of the object says little of what its surface leaves free.
  if (result.icp.ok && !result.hidden) turn_carry_.ObserveSurface(result.icp.free_directions);
  const Rigid3 step = pose * cam_from_object_.Inverse();
  if (std::string jump = ImplausibleJump(cam_from_object_, pose); jump.empty()) {
    jump_held_ = 0;
  } else if (JumpHolds(pose, result.icp.ok)) {
    result.jump_taken = true;
  } else {
    return finish(FusionStatus::kSkipped, std::move(jump));
  }
  UpdateContactNoise(contacts, step, &result);
  if (result.hidden) {
    // Tracked, not integrated: a few hundred points registered from a patch may be turned far
    // off, and would write that turn into the model.
    Follow(pose, &result);
  } else {
    Integrate(input, object, pose, &result);
  }
  if (options_.anchor_contacts) UpdateAnchors(contacts, pose, &anchors_);
  UpdateFeatureAnchors(input.correspondences, pose);
  // Only where ICP judged the free directions: there it took the turns about where the model's
  // normal lines meet (a ball's centre, a bottle's axis); where anchors joined every direction,
  // about the points' centroid, which a turn carried about moves the surface off itself.
  if (result.icp.ok && result.icp.free_directions >= 0) {
    pivot_in_object_ = pose.Inverse() * result.icp.pivot;
  }
  turn_carry_.Learn(result.ContactsUsed(), result.ContactsUsed() || result.pairwise.ok);
  CatchUpTurn(&result);
  return finish(FusionStatus::kFused);
}

HandTurn ObjectFusion::JudgeHandTurn(const FusionInput& input) {
  const HandTurn turn = turn_carry_.Judge(input.hand_motion, cam_from_object_);
  // Where the surface fixes every direction (a box), ICP follows the object by itself.
  if (!options_.turn_carry.enabled || !turn_carry_.SurfaceLeavesTurnFree()) {
    return HandTurn::kUnknown;
  }
  return turn;
}

FusionResult ObjectFusion::Finish(const FusionInput& input, SteadyClock::time_point started_at,
                                  FusionStatus status, std::string reason, FusionResult* result) {
  result->status = status;
  result->reason = std::move(reason);
  // The hand of a registered frame, for the next frame's model contacts (kept only when they
  // are looked for: a copy of every vertex each frame).
  if (options_.model_contacts.enabled && status != FusionStatus::kSkipped && input.hand) {
    previous_hand_ = input.hand->vertices;
  } else {
    previous_hand_.clear();
  }
  // The object frame's origin is the first frame's object points' centroid: within a few cm
  // of the object's centre, a few degrees of the direction to a camera half a metre away.
  if (status != FusionStatus::kSkipped && !result->hidden) {
    coverage_.Observe(result->cam_from_object, {0, 0, 0});
  }
  result->coverage = coverage_.Share();
  result->milliseconds = MillisecondsSince(started_at);
  return std::move(*result);
}

ObjectFusion::ObjectPixels ObjectFusion::FindObject(const Frame& frame,
                                                    const std::vector<std::uint8_t>& mask) const {
  // The object's points and where they are in the image.
  ObjectPixels object{frame, mask, {}, {frame.width, frame.height, 0, 0}};
  std::array<int, 4>& box = object.box;
  for (int v = 0; v < frame.height; ++v) {
    for (int u = 0; u < frame.width; ++u) {
      const int pixel = v * frame.width + u;
      if (!mask[pixel] || frame.depth_mm[pixel] == 0) continue;
      object.points.push_back(intrinsics_.BackProject(u, v, frame.depth_mm[pixel]).cast<float>());
      box = {std::min(box[0], u), std::min(box[1], v), std::max(box[2], u + 1),
             std::max(box[3], v + 1)};
    }
  }
  return object;
}

void ObjectFusion::Start(const FusionInput& input, const ObjectPixels& object,
                         FusionResult* result) {
  // The volume around the object: centred on its points, axes the camera's.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : object.points) centre += p.cast<double>();
  centre /= static_cast<double>(object.points.size());
  last_step_ = Rigid3();
  surface_left_free_ = true;
  Integrate(input, object, Rigid3::Translation(centre), result);
  started_ = true;
}

void ObjectFusion::Follow(const Rigid3& pose, FusionResult* result) {
  if (started_) last_step_ = pose * cam_from_object_.Inverse();
  cam_from_object_ = pose;
  hand_turn_since_ = Rigid3();
  hand_turn_known_ = true;
  result->cam_from_object = pose;
}

void ObjectFusion::Integrate(const FusionInput& input, const ObjectPixels& object,
                             const Rigid3& pose, FusionResult* result) {
  Follow(pose, result);
  const auto integrate_start = SteadyClock::now();
  result->integrated_voxels = volume_.Integrate(object.frame, object.mask, intrinsics_, pose);
  result->integrate_ms = MillisecondsSince(integrate_start);
  free_space_.Observe(object.frame, object.box, pose, input.hand, fused_frames_);
  CloseLoops(object, result);
  ++fused_frames_;
}

void ObjectFusion::CloseLoops(const ObjectPixels& object, FusionResult* result) {
  const double kept_pairs =
      result->icp.first_inliers > 0
          ? static_cast<double>(result->icp.inliers) / result->icp.first_inliers
          : 1.0;
  const KeyframeUpdate update =
      keyframes_.Observe(object.frame, object.mask, object.box, cam_from_object_, fused_frames_,
                         kept_pairs, turn_carry_.SurfaceLeavesTurnFree());
  result->keyframe = update.added;
  result->loops = update.loops;
  result->feature_loops = update.feature_loops;
  if (std::isfinite(keyframes_.alias_deg())) result->keypoint_alias_deg = keyframes_.alias_deg();
  if (update.corrected) ApplyCorrection(update, result);
}

void ObjectFusion::ApplyCorrection(const KeyframeUpdate& update, FusionResult* result) {
  const auto refuse_start = SteadyClock::now();
  const std::vector<Keyframe>& keyframes = keyframes_.keyframes();
  // This frame is the newest keyframe.
  const Rigid3 moved = update.corrections.back();
  cam_from_object_ = cam_from_object_ * moved;
  result->cam_from_object = cam_from_object_;
  result->loop_correction_mm = update.correction_mm;
  const Rigid3 object_from_moved = moved.Inverse();
  MoveAnchors(object_from_moved);
  pivot_in_object_ = object_from_moved * pivot_in_object_;
  free_space_.Repose(
      [&](int stamp) { return KeyframeGraph::CorrectionAt(keyframes, update.corrections, stamp); });
  volume_.Clear();
  Frame canvas = Frame::Blank(intrinsics_.width, intrinsics_.height);
  std::vector<std::uint8_t> mask(canvas.depth_mm.size(), 0);
  for (const Keyframe& keyframe : keyframes) {
    keyframe.PasteInto(&canvas, &mask);
    volume_.Integrate(canvas, mask, intrinsics_, keyframe.cam_from_object);
    keyframe.ClearFrom(&canvas, &mask);
  }
  result->refuse_ms = MillisecondsSince(refuse_start);
}

Rigid3 ObjectFusion::Register(const FusionInput& input, bool with_contacts,
                              bool with_tracker_contacts, std::vector<PointMatch>* contacts,
                              FusionResult* result) const {
  Rigid3 pose = cam_from_object_;
  const auto pairwise_start = SteadyClock::now();
  // The contact sets as one, with the model's contacts and the anchors.
  PairwiseInput correspondences;
  for (const MatchSet& set : input.correspondences.sets) {
    if (set.kind == MatchKind::kVisual) {
      correspondences.sets.push_back(set);
      if (options_.drop_features_moving_back && result->hand_turn == HandTurn::kBack &&
          input.hand_motion) {
        result->features_moving_back +=
            DropPairsMovingWith(*input.hand_motion, &correspondences.sets.back().pairs);
      }
      const auto anchors = feature_anchors_.find(set.source);
      if (options_.anchor_features && anchors != feature_anchors_.end()) {
        result->anchored_features +=
            ApplyAnchors(anchors->second, &correspondences.sets.back().pairs);
      }
    }
    if (set.kind == MatchKind::kContact && with_contacts && with_tracker_contacts) {
      contacts->insert(contacts->end(), set.pairs.begin(), set.pairs.end());
    }
  }
  if (with_contacts) {
    result->model_contacts = AddModelContacts(input, contacts);
    if (options_.anchor_contacts) result->anchored_contacts = ApplyAnchors(anchors_, contacts);
  }
  correspondences.sets.push_back({"contacts", MatchKind::kContact, *contacts});
  PairwiseOptions pairwise = options_.pairwise;
  if (turn_carry_.SurfaceLeavesTurnFree()) {
    pairwise.min_visual_inliers =
        std::max(pairwise.min_visual_inliers, options_.free_turn_min_visual_inliers);
    pairwise.visual_turn_prior_deg = options_.free_turn_visual_prior_deg;
    // The correspondences' motion is all that carries the free turn: kept even where its pairs
    // disagree with it (ICP needs only a start where the surface fixes every direction).
    pairwise.max_rms_mm = 0;
  }
  result->pairwise = RegisterPair(correspondences, pairwise);
  result->pairwise_ms = MillisecondsSince(pairwise_start);
  if (result->pairwise.ok) {
    pose = result->pairwise.current_from_previous * cam_from_object_;
  } else if (options_.predict_moving && !surface_left_free_) {
    pose = last_step_ * cam_from_object_;
  }
  return pose;
}

bool ObjectFusion::Refine(const ObjectPixels& object, const std::vector<PointMatch>& contacts,
                          Rigid3* pose, FusionResult* result) {
  const IcpSetup setup = PrepareIcp(object, *pose, *result);
  // The contacts, where the registration moved them (where it did not, where they were),
  // hold ICP where the surface cannot (FusionOptions::icp_contacts_need_spread).
  const std::vector<IcpAnchor> anchors = ContactAnchors(contacts, *pose, *result);
  result->contact_noise_mm = contact_noise_mm_;
  result->icp_anchors = static_cast<int>(anchors.size());
  result->icp = AlignAt(object, setup, *pose, anchors, result);
  Rigid3 icp_predicted = *pose;
  // A registration that lands far off (a bad contact, a slipped finger) leaves ICP few pairs;
  // from where the object was, it may find more.
  const double paired = static_cast<double>(result->icp.inliers) / object.points.size();
  // Only where the surface fixes every direction: where it leaves a turn free, the object where
  // it was pairs as many points as where the correspondences turned it.
  const bool dropped =
      !turn_carry_.SurfaceLeavesTurnFree() && paired < options_.icp_retry_drop * last_paired_;
  if (result->pairwise.ok && (!result->icp.ok || paired < options_.icp_retry_fraction || dropped)) {
    IcpResult retry = AlignAt(object, setup, cam_from_object_, {}, result);
    if (retry.ok && retry.inliers > options_.icp_retry_gain * result->icp.inliers) {
      result->icp = std::move(retry);
      icp_predicted = cam_from_object_;
      result->icp_from_previous = true;
    }
  }
  if (result->icp.ok) {
    *pose = result->icp.cam_from_volume;
    BlendHandTurn(object, setup, &icp_predicted, pose, result);
    AlignColours(object, icp_predicted, pose, result);
    WeighStillByColour(object, setup, icp_predicted, pose, result);
    CheckSeeThrough(object, setup, pose, result);
    last_paired_ = static_cast<double>(result->icp.inliers) / object.points.size();
    surface_left_free_ = result->icp.free_directions != 0;
    return true;
  }
  if (!result->pairwise.ok) return false;
  CheckSeeThrough(object, setup, pose, result);
  return true;
}

void ObjectFusion::BlendHandTurn(const ObjectPixels& object, const IcpSetup& setup,
                                 Rigid3* icp_predicted, Rigid3* pose, FusionResult* result) {
  if (result->hand_turn != HandTurn::kOn || !(options_.turn_carry.hand_weight > 0)) return;
  double moved_rad = 0;
  const Rigid3 blended =
      turn_carry_.Blend(cam_from_object_, *pose, *pose * pivot_in_object_, &moved_rad);
  // ICP again from there, without the contacts: the surface fixes the directions it fixes
  // (an axis or pivot a little off is taken back), the turn it leaves free stays. The blend
  // moves the pose by a degree or less: the model as cast for the first ICP still pairs it.
  IcpResult again = AlignFrom(object, setup, blended, result);
  if (!again.ok) return;
  result->icp = std::move(again);
  // Its free directions are in the camera frame the model was cast from.
  *icp_predicted = model_image_pose_;
  *pose = result->icp.cam_from_volume;
  result->hand_blended_deg = moved_rad * 180.0 / M_PI;
}

SeeThrough ObjectFusion::SeeThroughAt(const ObjectPixels& object, const Rigid3& pose,
                                      FusionResult* result) {
  const auto raycast_start = SteadyClock::now();
  // A sample of the pixels the observed voxels' box projects into.
  SeeThroughPixels(object.frame, options_.see_through.step_px, &see_through_depth_);
  volume_.Raycast(intrinsics_, pose, ImageBoxOf(volume_.ObservedBox(), pose, intrinsics_),
                  &see_through_depth_, kSeeThroughWindowMm, &hidden_image_);
  result->raycast_ms += MillisecondsSince(raycast_start);
  return MeasureSeeThrough(hidden_image_, object.frame, intrinsics_, options_.see_through);
}

void ObjectFusion::CheckSeeThrough(const ObjectPixels& object, const IcpSetup& setup, Rigid3* pose,
                                   FusionResult* result) {
  const SeeThroughOptions& options = options_.see_through;
  if (!(options.max_share > 0)) return;
  SeeThrough seen = SeeThroughAt(object, *pose, result);
  if (seen.share() > options.max_share && seen.visible > 0) {
    RetryOnObjectCentre(object, setup, &seen, pose, result);
  }
  result->see_through_share = seen.share();
  const bool through = seen.share() > options.max_share;
  see_through_frames_ = through ? see_through_frames_ + 1 : 0;
  result->see_through_held = through && see_through_frames_ <= options.max_held_frames;
}

void ObjectFusion::RetryOnObjectCentre(const ObjectPixels& object, const IcpSetup& setup,
                                       SeeThrough* seen, Rigid3* pose, FusionResult* result) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& point : object.points) centroid += point.cast<double>();
  centroid /= static_cast<double>(object.points.size());
  const Rigid3 moved = Rigid3::Translation(centroid - seen->visible_centroid) * *pose;
  IcpResult retry = AlignAt(object, setup, moved, {}, result);
  const int inliers = result->icp.ok ? result->icp.inliers : 0;
  if (!retry.ok || retry.inliers < inliers) return;
  const SeeThrough again = SeeThroughAt(object, retry.cam_from_volume, result);
  if (again.share() >= seen->share()) return;
  *pose = retry.cam_from_volume;
  result->icp = std::move(retry);
  result->see_through_moved = true;
  *seen = again;
}

bool ObjectFusion::ShowsLittleOfModel(const ObjectPixels& object, const Rigid3& pose) {
  // The whole image: rays are followed only through the box of observed voxels.
  volume_.Raycast(intrinsics_, pose, {0, 0, 0, 0}, nullptr, 0, &hidden_image_);
  const auto [u0, v0, u1, v1] = hidden_image_.written;
  int in_view = 0, shown = 0;
  for (int v = v0; v < v1; ++v) {
    for (int u = u0; u < u1; ++u) {
      const int pixel = v * hidden_image_.width + u;
      const float model = hidden_image_.depth_mm[pixel];
      if (!(model > 0)) continue;
      // Something behind where the model is: the model is not there (its edges, a pose a little
      // off), rather than the object hidden.
      const std::uint16_t depth = object.frame.depth_mm[pixel];
      if (depth > model + options_.hidden.background_margin_mm) continue;
      ++in_view;
      if (object.mask[pixel]) ++shown;
    }
  }
  return in_view > 0 && shown < options_.hidden.shown_share * in_view;
}

bool ObjectFusion::ContactsSpread(const FusionResult& result) const {
  return result.pairwise.contact_spread_mm >= options_.pairwise.min_contact_spread_mm;
}

std::vector<IcpAnchor> ObjectFusion::ContactAnchors(const std::vector<PointMatch>& contacts,
                                                    const Rigid3& pose,
                                                    const FusionResult& result) const {
  std::vector<IcpAnchor> anchors;
  if (!(options_.pairwise.contact_weight > 0 &&
        static_cast<int>(contacts.size()) >= options_.pairwise.min_contacts &&
        (!options_.icp_contacts_need_spread || (result.pairwise.ok && ContactsSpread(result))))) {
    return anchors;
  }
  const Rigid3 predicted_step = pose * cam_from_object_.Inverse();
  const double inlier_sq = options_.pairwise.inlier_mm * options_.pairwise.inlier_mm;
  for (const PointMatch& contact : contacts) {
    // Where feature matches fixed the motion, a contact they contradict is a mistracked
    // fingertip (see PairwiseOptions::check_contacts): it must not steer what the surface
    // leaves free and the features saw (a flat face's sliding). This is checked against the
    // registered motion (features and contacts), not RegisterPair's features-only one: it
    // also drops contacts that disagree with the other fingertips (taking RegisterPair's
    // verdict instead raised the pin session's pairwise error from 0.55 to 0.60 mm).
    if (options_.pairwise.check_contacts && result.pairwise.visual_inliers > 0 &&
        (predicted_step * contact.previous - contact.current).squaredNorm() > inlier_sq) {
      continue;
    }
    anchors.push_back(
        {contact.current, predicted_step * contact.previous, options_.pairwise.contact_weight});
  }
  return anchors;
}

ObjectFusion::IcpSetup ObjectFusion::PrepareIcp(const ObjectPixels& object, const Rigid3& pose,
                                                const FusionResult& result) {
  const std::array<int, 4>& box = object.box;
  IcpSetup setup;
  // The model where the object's points are, grown by what ICP can still pair them over
  // (a point moves by less than that between ICP's start and its end).
  const int margin = static_cast<int>(std::ceil(2 * options_.icp.max_distance_mm * intrinsics_.fx /
                                                std::max(1.0, pose.translation().z())));
  setup.roi = {box[0] - margin, box[1] - margin, box[2] + margin, box[3] + margin};
  // The model is needed only near the object's points: rays start a little in front of them.
  near_depth_.assign(object.frame.depth_mm.size(), 0);
  for (int v = std::max(0, box[1]); v < box[3]; ++v) {
    for (int u = std::max(0, box[0]); u < box[2]; ++u) {
      const int pixel = v * object.frame.width + u;
      if (object.mask[pixel]) near_depth_[pixel] = object.frame.depth_mm[pixel];
    }
  }
  if (options_.silhouette.weight > 0) {
    // The model's edge is looked for beyond the object's pixels too (by ICP's correction
    // farther still).
    setup.contour.points =
        FindContour(object.frame, object.mask, object.box, intrinsics_, options_.silhouette);
    MarkContourBand(setup.contour.points, intrinsics_, options_.silhouette.search_px + 3,
                    &near_depth_);
    setup.contour.pairable = &object.mask;
    setup.contour.options = options_.silhouette;
  }
  setup.window = static_cast<float>(2 * options_.icp.max_distance_mm + volume_.truncation_mm());
  setup.options = options_.icp;
  // Contacts that fix a point but hardly a turn decide only what the surface leaves free.
  setup.options.anchors_free_directions_only = !ContactsSpread(result);
  if (options_.contact_noise_reference_mm > 0 && contact_noise_mm_ > 0) {
    const double ratio = options_.contact_noise_reference_mm / contact_noise_mm_;
    setup.options.anchor_share *= std::clamp(ratio * ratio, 0.01, 100.0);
  }
  return setup;
}

IcpResult ObjectFusion::AlignAt(const ObjectPixels& object, const IcpSetup& setup,
                                const Rigid3& predicted, const std::vector<IcpAnchor>& anchors,
                                FusionResult* result) {
  const auto raycast_start = SteadyClock::now();
  volume_.Raycast(intrinsics_, predicted, setup.roi, &near_depth_, setup.window, &model_image_);
  model_image_pose_ = predicted;
  result->raycast_ms += MillisecondsSince(raycast_start);
  const auto icp_start = SteadyClock::now();
  IcpResult icp = AlignToModel(object.points, model_image_, intrinsics_, predicted, setup.options,
                               anchors, setup.contour.points.empty() ? nullptr : &setup.contour);
  result->icp_ms += MillisecondsSince(icp_start);
  return icp;
}

IcpResult ObjectFusion::AlignFrom(const ObjectPixels& object, const IcpSetup& setup,
                                  const Rigid3& start, FusionResult* result) const {
  const auto icp_start = SteadyClock::now();
  IcpResult icp =
      AlignToModel(object.points, model_image_, intrinsics_, model_image_pose_, setup.options, {},
                   setup.contour.points.empty() ? nullptr : &setup.contour, &start);
  result->icp_ms += MillisecondsSince(icp_start);
  return icp;
}

void ObjectFusion::AlignColours(const ObjectPixels& object, const Rigid3& icp_predicted,
                                Rigid3* pose, FusionResult* result) {
  if (!options_.colour.enabled || result->icp.free.empty()) return;
  if (colour_skips_left_ > 0) {
    --colour_skips_left_;
    result->colour.reason = "no pattern in a recent frame";
    return;
  }
  const auto start = SteadyClock::now();
  result->colour = AlignColoursOf(object, result->icp, icp_predicted, pose);
  result->colour_ms += MillisecondsSince(start);
  if (result->colour.no_pattern) colour_skips_left_ = options_.colour_recheck_frames - 1;
}

ColourAlignResult ObjectFusion::AlignColoursOf(const ObjectPixels& object, const IcpResult& icp,
                                               const Rigid3& icp_predicted, Rigid3* pose) const {
  // ICP's correction takes the frame's points to where model_image_ sees them.
  const Rigid3 correction = model_image_pose_ * pose->Inverse();
  // The free directions are in the camera frame of ICP's prediction; model_image_ may have been
  // cast from another (a retry from the previous pose that was not kept).
  const Rigid3 to_image = model_image_pose_ * icp_predicted.Inverse();
  std::vector<FreeDirection> free = icp.free;
  for (FreeDirection& direction : free) {
    direction.turn = to_image.rotation() * direction.turn;
    direction.shift = to_image.rotation() * direction.shift;
  }
  ColourAlignResult colour =
      AlignColour(object.frame, object.mask, object.box, model_image_, intrinsics_, correction,
                  free, to_image * icp.free_centre, options_.colour);
  if (colour.applied) *pose = colour.correction.Inverse() * model_image_pose_;
  return colour;
}

void ObjectFusion::WeighStillByColour(const ObjectPixels& object, const IcpSetup& setup,
                                      const Rigid3& icp_predicted, Rigid3* pose,
                                      FusionResult* result) {
  // Only where the object shows a pattern (whether or not the colours could align it from the
  // registered pose: a turn far off leaves them no basin) and the registration moved it. ICP
  // from the previous pose runs without the contacts, so it leaves free every direction the
  // surface leaves free.
  const Rigid3 moved = icp_predicted * cam_from_object_.Inverse();
  if (!options_.colour_weighs_still ||
      !(result->colour.pattern_spread >= options_.colour.min_grey_spread) ||
      !turn_carry_.SurfaceLeavesTurnFree() ||
      (moved.translation().norm() < 1e-6 && Eigen::AngleAxisd(moved.rotation()).angle() < 1e-9)) {
    return;
  }
  IcpResult icp = AlignAt(object, setup, cam_from_object_, {}, result);
  if (!icp.ok || icp.free.empty()) return;
  const auto start = SteadyClock::now();
  Rigid3 still = icp.cam_from_volume;
  ColourAlignResult colour = AlignColoursOf(object, icp, cam_from_object_, &still);
  result->colour_ms += MillisecondsSince(start);
  // Where it stood the colours may have nothing to better (applied false): their correlation
  // is measured all the same, wherever they paired.
  if (!(colour.correlation > 0)) return;
  result->colour_still_correlation = colour.correlation;
  if (colour.correlation > result->colour.correlation + options_.colour_still_margin) {
    result->icp = std::move(icp);
    result->colour = std::move(colour);
    result->colour_kept_still = true;
    *pose = still;
  }
}

std::string ObjectFusion::ImplausibleJump(const Rigid3& from, const Rigid3& to) const {
  const double moved = (to.translation() - from.translation()).norm();
  const double turned = from.RotationAngleToRad(to) * 180.0 / M_PI;
  if (moved > options_.max_jump_mm || turned > options_.max_jump_deg) {
    char reason[128];
    std::snprintf(reason, sizeof reason, "implausible jump: %.1f mm, %.1f° from the last frame",
                  moved, turned);
    return reason;
  }
  return {};
}

bool ObjectFusion::JumpHolds(const Rigid3& pose, bool icp_found) {
  // Only ICP against a model whose shape fixes every direction finds where the object is; a
  // turn the surface leaves free comes from the frame's motion alone (the hand, the features),
  // and a wrong one may hold as well. And the hand that holds the object must have turned the
  // same way since the last pose, within the jump limit: ICP may find a box turned 90° from
  // where it is just as consistently.
  const double off_hand_deg =
      (hand_turn_since_ * cam_from_object_).RotationAngleToRad(pose) * 180.0 / M_PI;
  if (!icp_found || turn_carry_.SurfaceLeavesTurnFree() || !hand_turn_known_ ||
      off_hand_deg > options_.max_jump_deg) {
    jump_held_ = 0;
    return false;
  }
  const bool again = jump_held_ > 0 && ImplausibleJump(jumped_to_, pose).empty();
  jump_held_ = again ? jump_held_ + 1 : 1;
  jumped_to_ = pose;
  if (options_.jump_held_frames == 0 || jump_held_ < options_.jump_held_frames) return false;
  jump_held_ = 0;
  return true;
}

void ObjectFusion::UpdateContactNoise(const std::vector<PointMatch>& contacts, const Rigid3& step,
                                      FusionResult* result) {
  // How far the contacts land from the final motion: their noise, for the next frames' weight.
  // Only where they held ICP (a frame whose registration did without them may have lost the
  // turn they saw, and that is not their noise).
  if (contacts.empty() || !(options_.pairwise.contact_weight > 0) || !result->pairwise.ok ||
      !result->icp.ok || result->icp_from_previous) {
    return;
  }
  std::vector<double> residuals;
  for (const PointMatch& contact : contacts)
    residuals.push_back((step * contact.previous - contact.current).norm());
  std::nth_element(residuals.begin(), residuals.begin() + residuals.size() / 2, residuals.end());
  result->contact_residual_mm = residuals[residuals.size() / 2];
  // A running mean of the per-frame medians over about 20 frames (a frame of bad contacts
  // moves it a little; a worse tracker moves it for good).
  if (contact_noise_mm_ > 0) {
    contact_noise_mm_ += 0.05 * (std::max(0.05, result->contact_residual_mm) - contact_noise_mm_);
  }
}

}  // namespace ihs::fusion
