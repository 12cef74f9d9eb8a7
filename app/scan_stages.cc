#include "app/scan_stages.h"

#include <algorithm>

#include "app/object_mask.h"
#include "core/errors.h"
#include "core/stopwatch.h"
#include "fusion/correspondence_source.h"
#include "fusion/shot_matcher.h"
#include "fusion/sift_matcher.h"
#include "tracker/contacts.h"
#include "tracker/hand_data.h"
#include "tracker/hand_kinematics.h"
#include "tracker/hand_pose.h"

namespace ihs::app {
namespace {

const ScannerOptions& Checked(const ScannerOptions& options) {
  options.Check();
  return options;
}

}  // namespace

tracker::TrackerOptions TrackerOptionsFor(const ScannerOptions& options) {
  tracker::TrackerOptions tracker_options = options.tracker;
  if (options.scan.hand_scale > 0 || options.scan.hand_template != "procedural") {
    tracker_options.scale_frames = 0;
  }
  return tracker_options;
}

const char* FramePacket::HandState() const {
  if (!frame_error.empty() || !track.HasPose()) return "lost";
  return track.doubtful ? "doubtful" : "tracked";
}

const char* FramePacket::ObjectState() const {
  if (Registered()) return fusion.hand_carried_deg > 0 ? "turned by the hand" : "registered";
  return frame_error.empty() && !track.HasPose() ? "paused" : "lost";
}

tracker::HandModel LoadHandTemplate(const ScanOptions& options) {
  tracker::HandModel model = tracker::LoadHandTemplate(options.hand_template, !options.left_hand);
  if (options.hand_scale > 0) model = model.Scaled(options.hand_scale);
  return model;
}

HandStage::HandStage(const ScannerOptions& options, const CameraIntrinsics& intrinsics)
    : options_(Checked(options).scan),
      intrinsics_(intrinsics),
      tracker_(LoadHandTemplate(options.scan), intrinsics, TrackerOptionsFor(options)),
      fingertips_(std::make_shared<const std::vector<std::vector<int>>>(
          tracker::ContactDetector(tracker_.model(), options.tracker.contacts)
              .fingertip_vertices())) {}

HandStage::~HandStage() = default;

void HandStage::Initialise(const tracker::HandPose& pose) { tracker_.Initialise(pose); }

double HandStage::scale() const {
  return tracker_.scale() * (options_.hand_scale > 0 ? options_.hand_scale : 1.0);
}

std::vector<std::string> HandStage::BoneNames() const {
  std::vector<std::string> names;
  for (const auto& bone : tracker_.model().bones) names.push_back(bone.name);
  return names;
}

std::vector<std::string> HandStage::AngleNames() const {
  std::vector<std::string> names;
  const tracker::HandModel& model = tracker_.model();
  for (const tracker::DegreeOfFreedom& dof : tracker::JointDegreesOfFreedom(model)) {
    names.push_back(model.bones[dof.bone].name + "." + std::string(1, "xyz"[dof.axis]));
  }
  return names;
}

void HandStage::Process(FramePacket& packet) {
  if (!packet.frame) throw InternalError("HandStage: a packet without a frame");
  const Frame& frame = *packet.frame;
  try {
    frame.Check();
  } catch (const InputError& error) {
    packet.frame_error = error.what();
    return;
  }
  if (frame.width != intrinsics_.width || frame.height != intrinsics_.height) {
    packet.frame_error = "frame of " + std::to_string(frame.width) + "x" +
                         std::to_string(frame.height) + " pixels from a camera of " +
                         std::to_string(intrinsics_.width) + "x" +
                         std::to_string(intrinsics_.height);
    return;
  }
  packet.track = tracker_.Track(frame);
  const auto start = SteadyClock::now();
  packet.object_mask = packet.track.segmentation.object_mask;
  if (packet.object_mask.size() != frame.depth_mm.size()) {
    packet.object_mask.assign(frame.depth_mm.size(), 0);
  }
  if (packet.track.HasPose()) {
    std::shared_ptr<const TriangleMesh> hand = packet.track.posed_mesh;
    if (!hand) {
      hand = std::make_shared<const TriangleMesh>(
          tracker_.model().Pose(tracker::ForwardKinematics(tracker_.model(), packet.track.pose)));
    }
    packet.hand_pixels_removed =
        RemoveMeshPixels(*hand, frame, intrinsics_, options_.hand_dilation_px,
                         options_.hand_depth_margin_mm, &packet.object_mask);
    packet.hand_mesh = std::move(hand);
    packet.fingertips = fingertips_;
  }
  packet.mask_ms = MillisecondsSince(start);
}

std::vector<std::unique_ptr<fusion::CorrespondenceSource>> MakeCorrespondenceSources(
    const ScannerOptions& options, const CameraIntrinsics& intrinsics) {
  std::vector<std::unique_ptr<fusion::CorrespondenceSource>> sources;
  if (options.scan.features_2d) {
    sources.push_back(std::make_unique<fusion::SiftMatcher>(intrinsics, options.sift));
  }
  if (options.scan.features_3d) {
    sources.push_back(std::make_unique<fusion::ShotMatcher>(intrinsics, options.shot));
  }
  sources.push_back(std::make_unique<fusion::HandContacts>());
  return sources;
}

ObjectStage::ObjectStage(const ScannerOptions& options, const CameraIntrinsics& intrinsics)
    : options_(Checked(options).scan),
      sources_(MakeCorrespondenceSources(options, intrinsics)),
      fusion_(intrinsics, options.fusion) {}

ObjectStage::~ObjectStage() = default;

std::optional<Rigid3> ObjectStage::HandMotion(const FramePacket& packet) {
  std::optional<Rigid3> motion;
  const bool has_pose = packet.frame_error.empty() && packet.track.HasPose();
  // A pose fitted anew (a search won) is not the previous one moved.
  if (has_pose && previous_root_ && packet.track.status == tracker::TrackStatus::kTracked) {
    motion = packet.track.pose.cam_from_root * previous_root_->Inverse();
  }
  previous_root_.reset();
  if (has_pose) previous_root_ = packet.track.pose.cam_from_root;
  return motion;
}

void ObjectStage::SetContactLooseness(const FramePacket& packet, fusion::FusionInput* input) {
  const tracker::Contacts& contacts = packet.track.contacts;
  const bool held = contacts.held_frames > 0;
  input->contact_threshold_mm = std::max(contacts.threshold_mm, previous_contact_threshold_mm_);
  input->contacts_held = held || previous_contacts_held_;
  previous_contact_threshold_mm_ = contacts.bones.empty() ? 0.0 : contacts.threshold_mm;
  previous_contacts_held_ = !contacts.bones.empty() && held;
}

void ObjectStage::Process(FramePacket& packet) {
  std::optional<Rigid3> hand_motion = HandMotion(packet);
  fusion::FusionInput input;
  SetContactLooseness(packet, &input);
  if (!packet.frame_error.empty()) {
    packet.fusion = fusion_.Skip("malformed frame: " + packet.frame_error);
    return;
  }
  if (!options_.fuse_without_hand && !packet.track.HasPose()) {
    packet.fusion = fusion_.Skip(std::string("no hand: the tracker's frame is ") +
                                 tracker::ToString(packet.track.status));
    return;
  }
  const Frame& frame = *packet.frame;
  input.frame = &frame;
  input.object_mask = &packet.object_mask;
  std::vector<fusion::PointMatch> hand_contacts;
  for (const auto& pair : packet.track.contact_pairs) {
    hand_contacts.push_back({pair.previous_mm, pair.current_mm, pair.vertex});
  }
  const fusion::MatchContext context{&frame, &packet.object_mask, &hand_contacts};
  const auto start = SteadyClock::now();
  for (const auto& source : sources_) {
    input.correspondences.sets.push_back(source->MatchSetFor(context));
    const fusion::MatchSet& set = input.correspondences.sets.back();
    packet.matches.emplace_back(set.source, static_cast<int>(set.pairs.size()));
  }
  packet.features_ms = MillisecondsSince(start);
  if (packet.hand_mesh && packet.fingertips) {
    input.hand = packet.hand_mesh.get();
    input.fingertips = packet.fingertips.get();
  }
  input.hand_motion = hand_motion;
  packet.fusion = fusion_.Fuse(input);
}

fusion::ModelSnapshot ObjectStage::Snapshot() const { return fusion_.Snapshot(); }

}  // namespace ihs::app
