#include "tools/synth/sequence.h"

#include <algorithm>
#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "core/atomic_file.h"
#include "core/check.h"
#include "core/errors.h"
#include "core/mesh_io.h"
#include "core/trajectory_io.h"
#include "render/offscreen_renderer.h"
#include "sensor/oni_writer.h"
#include "sensor/tum_directory.h"
#include "tools/synth/hand_object.h"
#include "tracker/hand_data.h"
#include "tracker/hand_joints_io.h"

namespace ihs::synth {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kFingerNames[5] = {"pinky", "ring", "middle", "index", "thumb"};

// A colour-mapped depth image (near = warm, over the frame's own depth range), black where
// there is no depth.
cv::Mat DepthImage(const Frame& frame) {
  cv::Mat depth(frame.height, frame.width, CV_16UC1,
                const_cast<std::uint16_t*>(frame.depth_mm.data()));
  double near = 0, far = 0;
  cv::minMaxLoc(depth, nullptr, &far);
  cv::Mat masked = depth.clone();
  masked.setTo(65535, depth == 0);
  cv::minMaxLoc(masked, &near);
  const double range = std::max(1.0, far - near);
  cv::Mat scaled;
  depth.convertTo(scaled, CV_8UC1, -255.0 / range, 255.0 * far / range);
  cv::Mat color;
  cv::applyColorMap(scaled, color, cv::COLORMAP_JET);
  color.setTo(cv::Scalar(0, 0, 0), depth == 0);
  return color;
}

cv::Mat LabelImage(const std::vector<std::uint8_t>& labels, int width, int height) {
  cv::Mat image(height, width, CV_8UC3, cv::Scalar(0, 0, 0));
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const std::uint8_t label = labels[static_cast<size_t>(v) * width + u];
      if (label == render::kHand) image.at<cv::Vec3b>(v, u) = cv::Vec3b(90, 150, 230);
      if (label == render::kObject) image.at<cv::Vec3b>(v, u) = cv::Vec3b(220, 120, 40);
    }
  }
  return image;
}

void WritePng(const fs::path& path, const cv::Mat& image) {
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".png", image, bytes)) throw OutputError(path.string() + ": cannot encode PNG");
  WriteFileAtomically(path, std::string(bytes.begin(), bytes.end()));
}

json IntrinsicsJson(const CameraIntrinsics& c) {
  return {{"fx", c.fx}, {"fy", c.fy},       {"cx", c.cx},
          {"cy", c.cy}, {"width", c.width}, {"height", c.height}};
}

// Creates gt/ and gt/labels/.
void CreateGroundTruthFolder(const fs::path& gt) {
  std::error_code error;
  fs::create_directories(gt / "labels", error);
  if (error) throw OutputError(gt.string() + ": cannot create (" + error.message() + ")");
}

// The recording as the user gets it: the .oni file and the TUM directory, each when asked for.
struct SensorWriters {
  SensorWriters(const SequenceOptions& options, const fs::path& out) {
    if (options.write_oni) {
      sensor::OniWriterOptions oni_options;
      oni_options.intrinsics = options.intrinsics;
      oni_options.fps = options.fps;
      oni = std::make_unique<sensor::OniWriter>(out / "sequence.oni", oni_options);
    }
    if (options.write_tum)
      tum = std::make_unique<sensor::TumWriter>(out / "tum", options.intrinsics);
  }

  void Write(const Frame& frame) {
    if (oni) oni->Write(frame);
    if (tum) tum->Write(frame);
  }

  // Closes the .oni file and completes the TUM directory.
  void Finish() {
    if (oni) oni->Close();
    if (tum) tum->Finish();
  }

  std::unique_ptr<sensor::OniWriter> oni;
  std::unique_ptr<sensor::TumWriter> tum;
};

// The per-frame ground truth (object trajectory, hand joints, contacts), gathered while the
// frames are rendered and written at the end, with the summary of held frames and penetration.
class GroundTruth {
 public:
  explicit GroundTruth(const SequenceRenderer& renderer) : renderer_(renderer) {
    const tracker::HandModel& hand = renderer.hand();
    for (const auto& bone : hand.bones) bone_names_.push_back(bone.name);
    std::vector<int> tip_fingers;
    for (int bone : renderer.geometry().fingertip_bones())
      tip_fingers.push_back(hand.FingerOf(bone));
    contacts_csv_ = "frame,held";
    for (int f : tip_fingers) contacts_csv_ += std::string(",") + kFingerNames[f] + "_touch";
    for (int f : tip_fingers) contacts_csv_ += std::string(",") + kFingerNames[f] + "_mm";
    contacts_csv_ += ",penetration_mm\n";
  }

  // Adds frame i.
  void Add(int i, const RenderedFrame& rendered) {
    const double t = rendered.frame.depth_timestamp_us * 1e-6;
    trajectory_.push_back({t, rendered.cam_from_object});
    joints_.push_back({i, rendered.joints_mm});
    const HandObjectContact& contact = rendered.contact;
    std::string row = std::to_string(i) + "," + (rendered.held ? "1" : "0");
    for (const auto& tip : contact.fingertips) row += tip.touching ? ",1" : ",0";
    char number[32];
    for (const auto& tip : contact.fingertips) {
      std::snprintf(number, sizeof number, ",%.3f", std::min(tip.distance_mm, 999.0));
      row += number;
    }
    std::snprintf(number, sizeof number, ",%.3f\n", contact.max_penetration_mm);
    contacts_csv_ += row + number;
    summary_.held_frames += rendered.held ? 1 : 0;
    summary_.max_penetration_mm = std::max(summary_.max_penetration_mm, contact.max_penetration_mm);
  }

  // Held frames and deepest penetration so far (the rest of the summary left unset).
  const SequenceSummary& summary() const { return summary_; }

  // Writes trajectory.txt, object.ply, hand_joints.csv and contacts.csv into `gt`.
  void Write(const fs::path& gt) const {
    WriteTumTrajectory(
        gt / "trajectory.txt", trajectory_,
        {"cam_from_object of " + renderer_.object().name() + " (mm), one pose per frame"});
    WriteMesh(gt / "object.ply", renderer_.object_mesh());
    tracker::WriteHandJointsCsv(gt / "hand_joints.csv", bone_names_, joints_);
    WriteFileAtomically(gt / "contacts.csv", contacts_csv_);
  }

 private:
  const SequenceRenderer& renderer_;
  std::vector<std::string> bone_names_;
  std::vector<StampedPose> trajectory_;
  std::vector<tracker::HandJointsRow> joints_;
  std::string contacts_csv_;
  SequenceSummary summary_;
};

// The rendered frame's labels as an image (sharing its data).
cv::Mat LabelsMat(const RenderedFrame& rendered) {
  return cv::Mat(rendered.frame.height, rendered.frame.width, CV_8UC1,
                 const_cast<std::uint8_t*>(rendered.labels.data()));
}

// Writes frame i's labels as gt/labels/NNNNNN.png.
void WriteLabels(const fs::path& gt, int i, const cv::Mat& labels) {
  char name[32];
  std::snprintf(name, sizeof name, "%06d.png", i);
  WritePng(gt / "labels" / name, labels);
}

// The contact sheet: a few frames' colour, colour-mapped depth and labels side by side.
class ContactSheet {
 public:
  // Picks the sheet's frames out of `count`.
  explicit ContactSheet(int count) {
    // Fractions of the sequence that fall on different phases of a periodic motion.
    for (double fraction : {0.1, 0.3, 0.55, 0.85}) {
      frames_.push_back(static_cast<int>(fraction * (count - 1)));
    }
  }

  // Keeps frame i's panels when it is one of the sheet's frames; `labels` is LabelsMat's image.
  void Add(int i, const RenderedFrame& rendered, const cv::Mat& labels) {
    if (std::find(frames_.begin(), frames_.end(), i) == frames_.end()) return;
    const Frame& frame = rendered.frame;
    cv::Mat rgb(frame.height, frame.width, CV_8UC3, const_cast<std::uint8_t*>(frame.rgb.data()));
    cv::Mat bgr;
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    panels_.push_back(
        {bgr, DepthImage(frame), LabelImage(rendered.labels, frame.width, frame.height)});
    const cv::Rect box = cv::boundingRect(labels);
    box_ = box_.area() == 0 ? box : (box_ | box);
  }

  // Writes the sheet, cropped to where the hand and object are (with a margin and the label).
  void Write(const fs::path& path, const CameraIntrinsics& intrinsics) {
    const int margin = 30;
    box_ = cv::Rect(box_.x - margin, box_.y - margin, box_.width + 2 * margin,
                    box_.height + 2 * margin);
    box_ &= cv::Rect(0, 0, intrinsics.width, intrinsics.height);
    std::vector<cv::Mat> rows;
    for (size_t r = 0; r < panels_.size(); ++r) {
      const auto& panels = panels_[r];
      cv::putText(panels[0], "frame " + std::to_string(frames_[r]), {box_.x + 5, box_.y + 20},
                  cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1);
      cv::Mat row;
      cv::hconcat(std::vector<cv::Mat>{panels[0](box_), panels[1](box_), panels[2](box_)}, row);
      rows.push_back(row);
    }
    cv::Mat sheet;
    cv::vconcat(rows, sheet);
    WritePng(path, sheet);
  }

 private:
  std::vector<int> frames_;
  std::vector<std::array<cv::Mat, 3>> panels_;
  cv::Rect box_;
};

// The sensor model's options, for the manifest.
json SensorJson(const SensorModelOptions& s) {
  return {{"depth_noise", s.depth_noise},
          {"noise_coefficient_per_mm", s.noise_coefficient_per_mm},
          {"quantization", s.quantization},
          {"baseline_mm", s.baseline_mm},
          {"subpixel", s.subpixel},
          {"grazing_dropout", s.grazing_dropout},
          {"max_incidence_deg", s.max_incidence_deg},
          {"silhouette_effects", s.silhouette_effects},
          {"edge_jump_mm", s.edge_jump_mm},
          {"edge_dropout_probability", s.edge_dropout_probability},
          {"flying_probability", s.flying_probability},
          {"color_noise", s.color_noise},
          {"color_sigma", s.color_sigma},
          {"misregistration", s.misregistration},
          {"max_misregistration_px", s.max_misregistration_px}};
}

// A recorded motion's options and placement report, for the manifest.
json RecordedJson(const RecordedMotionOptions& rc, const RecordedMotionReport& r) {
  return {{"contact_mm", rc.contact_mm},
          {"max_penetration_mm", rc.max_penetration_mm},
          {"prior_weight", rc.prior_weight},
          {"slip_mm", rc.slip_mm},
          {"report",
           {{"placed_frames", r.frames},
            {"grasp_frame", r.grasp_frame},
            {"held_frames", r.held_frames},
            {"carried_within_3mm_share", r.carried_within_3mm_share},
            {"placed_within_3mm_share", r.placed_within_3mm_share},
            {"penetration_p95_mm", r.penetration_p95_mm},
            {"penetration_max_mm", r.penetration_max_mm}}}};
}

// A scripted motion's options and grasp height, for the manifest.
json ScriptedJson(const ScriptedMotionOptions& sc, const ObjectShape& object) {
  return {{"frames", sc.frames},
          {"turns", sc.turns},
          {"turn_per_grasp_deg", sc.turn_per_grasp_deg},
          {"distance_mm", sc.distance_mm},
          {"tilt_deg", sc.tilt_deg},
          {"start_azimuth_deg", sc.start_azimuth_deg},
          {"sway_mm", sc.sway_mm},
          {"sway_deg", sc.sway_deg},
          {"press_mm", sc.press_mm},
          {"release_mm", sc.release_mm},
          {"slip_mm", sc.slip_mm},
          {"seed", sc.seed},
          {"grasp_height_mm", GraspHeight(object)}};
}

// The manifest: every parameter of the sequence and its summary.
json ManifestJson(const SequenceRenderer& renderer, const SequenceSummary& summary) {
  const SequenceOptions& options = renderer.options();
  const ObjectShape& object = renderer.object();
  const int count = renderer.frame_count();
  const int last = options.first_frame + (count - 1) * options.frame_step;
  json manifest = {
      {"generator", "inhandscan-synth " IHS_VERSION},
      {"object",
       {{"spec", options.object},
        {"name", object.name()},
        {"height_mm", object.height_mm()},
        {"max_radius_mm", object.max_radius_mm()},
        {"textured", object.textured()},
        {"label", options.textured && options.label},
        {"volume_mm3", object.mesh().Volume()},
        {"rendered", !options.empty_hand}}},
      {"motion", options.motion},
      {"hand", renderer.hand_source()},
      {"hand_scale", options.hand_scale},
      {"left_hand", options.left_hand},
      {"hand_bones", renderer.hand().bones.size()},
      {"frames",
       {{"first", options.first_frame},
        {"last", last},
        {"step", options.frame_step},
        {"count", count}}},
      {"seed", options.seed},
      {"fps", options.fps},
      {"touch_mm", options.touch_mm},
      {"hand_rgb", options.hand_rgb},
      {"object_rgb", options.object_rgb},
      {"intrinsics", IntrinsicsJson(options.intrinsics)},
      {"sensor", SensorJson(options.sensor)},
      {"summary",
       {{"frames", count},
        {"held_frames", summary.held_frames},
        {"max_penetration_mm", summary.max_penetration_mm},
        {"seconds", summary.seconds}}},
  };
  const bool recorded = options.motion != "scripted";
  if (recorded) {
    manifest["recorded"] = RecordedJson(options.recorded, renderer.recorded_report());
  } else {
    manifest["scripted"] = ScriptedJson(options.scripted, renderer.object());
  }
  return manifest;
}

}  // namespace

void SequenceOptions::Check() const {
  IHS_CHECK_ARG(first_frame >= 0, "frames: the first frame must be >= 0");
  IHS_CHECK_ARG(last_frame == -1 || last_frame >= first_frame,
                "frames: the last frame must not come before the first");
  IHS_CHECK_ARG(frame_step >= 1 && frame_step <= 10, "frame step must be in [1, 10]");
  IHS_CHECK_ARG(fps > 0 && fps <= 1000, "fps must be in (0, 1000]");
  IHS_CHECK_ARG(touch_mm > 0, "touch_mm must be positive");
  IHS_CHECK_ARG(!label || textured, "a label (--label) needs a textured object (--textured)");
  IHS_CHECK_ARG(motion == "scripted" || motion.rfind("recorded:", 0) == 0,
                "motion must be 'scripted' or 'recorded:DIR', got '" << motion << "'");
  IHS_CHECK_ARG(hand_scale >= 0.5 && hand_scale <= 2.0, "hand scale must be in [0.5, 2]");
  IHS_CHECK_ARG(hand_scale == 1.0 || motion == "scripted",
                "a hand scale needs the scripted motion (a recorded motion has its own hand)");
  IHS_CHECK_ARG(!left_hand || motion == "scripted",
                "a left hand needs the scripted motion (the recorded hand is a right one)");
  intrinsics.Check();
  sensor.Check();
  scripted.Check();
  recorded.Check();
}

SequenceRenderer::SequenceRenderer(const SequenceOptions& options)
    : options_(options),
      object_(ObjectShape::FromSpec(
          (options.Check(), options.object), options.textured, options.object_rgb,
          options.label ? std::optional<std::uint32_t>(options.seed) : std::nullopt)) {
  // The range's last frame, checked against the motion's length.
  auto checked_last = [&](int available) {
    const int last = options_.last_frame < 0 ? available - 1 : options_.last_frame;
    if (options_.first_frame >= available || last >= available) {
      throw std::invalid_argument("frames " + std::to_string(options_.first_frame) + ":" +
                                  std::to_string(last) +
                                  " outside the motion's 0:" + std::to_string(available - 1));
    }
    return last;
  };
  const bool recorded = options_.motion != "scripted";
  if (recorded) {
    const fs::path session = options_.motion.substr(9);
    const fs::path data_dir = options_.hand == "procedural" ? session.parent_path().parent_path()
                                                            : fs::path(options_.hand);
    tracker::RecordedHand recording = tracker::LoadRecordedHand(data_dir, session);
    RecordedMotionOptions recorded_options = options_.recorded;
    recorded_options.last_frame = options_.last_frame;
    motion_ = MakeRecordedMotion(recording, object_, recorded_options, &recorded_report_);
    hand_ = std::move(recording.model);
    hand_source_ = data_dir.string();
  } else {
    // A scripted motion's length is known before it is planned (seconds of inverse kinematics,
    // minutes under a sanitizer): a range outside it fails at once.
    checked_last(options_.scripted.frames);
    hand_ = tracker::LoadHandTemplate(options_.hand, !options_.left_hand);
    hand_source_ = options_.hand;
    if (options_.hand_scale != 1.0) hand_ = hand_.Scaled(options_.hand_scale);
    motion_ = MakeScriptedMotion(hand_, object_, options_.scripted);
  }
  last_ = checked_last(static_cast<int>(motion_.frames.size()));
  object_mesh_ = object_.mesh();
  if (!object_.textured())
    object_mesh_.colors.assign(object_mesh_.vertices.size(), options_.object_rgb);
  geometry_ = std::make_unique<HandObjectGeometry>(hand_);
  renderer_ = std::make_unique<render::OffscreenRenderer>(options_.intrinsics);
}

SequenceRenderer::~SequenceRenderer() = default;

RenderedFrame SequenceRenderer::Render(int i) {
  IHS_CHECK_ARG(i >= 0 && i < frame_count(), "frame " << i << " outside 0:" << frame_count() - 1);
  const MotionFrame& m = motion_.frames[options_.first_frame + i * options_.frame_step];
  RenderedFrame out;
  out.posed_hand = hand_.Pose(m.cam_from_bone);
  const render::RenderItem hand_item{&out.posed_hand, Rigid3(), options_.hand_rgb, false,
                                     render::kHand};
  const render::RenderItem object_item{&object_mesh_, m.cam_from_object, options_.object_rgb, true,
                                       render::kObject};
  std::vector<render::RenderItem> items = {hand_item};
  if (!options_.empty_hand) items.push_back(object_item);
  render::RenderOutput rendering = renderer_->Render(items);
  std::seed_seq seeds{options_.seed, static_cast<std::uint32_t>(i)};
  std::mt19937 rng(seeds);
  out.frame = ApplySensorModel(rendering, options_.intrinsics, options_.sensor, rng);
  out.frame.index = i;
  out.frame.depth_timestamp_us = out.frame.color_timestamp_us =
      static_cast<std::int64_t>(std::llround(i * 1e6 / options_.fps));
  out.labels = std::move(rendering.labels);
  out.cam_from_object = m.cam_from_object;
  out.cam_from_bone = m.cam_from_bone;
  out.joints_mm = hand_.JointPositions(m.cam_from_bone);
  out.contact = geometry_->Measure(out.posed_hand, object_, m.cam_from_object, options_.touch_mm);
  out.held = m.held && !options_.empty_hand;
  if (options_.empty_hand) {
    for (FingertipContact& tip : out.contact.fingertips) tip.touching = false;
    out.contact.max_penetration_mm = 0;
  }
  return out;
}

SequenceSummary GenerateSequence(const SequenceOptions& options, const fs::path& out) {
  const auto started = std::chrono::steady_clock::now();
  SequenceRenderer renderer(options);
  const int count = renderer.frame_count();

  // Outputs.
  const fs::path gt = out / "gt";
  CreateGroundTruthFolder(gt);
  SensorWriters sensor(options, out);
  GroundTruth truth(renderer);
  ContactSheet sheet(count);
  for (int i = 0; i < count; ++i) {
    const RenderedFrame rendered = renderer.Render(i);
    sensor.Write(rendered.frame);
    truth.Add(i, rendered);
    const cv::Mat labels = LabelsMat(rendered);
    WriteLabels(gt, i, labels);
    sheet.Add(i, rendered, labels);
  }
  sensor.Finish();
  SequenceSummary summary = truth.summary();
  summary.frames = count;
  summary.recorded = renderer.recorded_report();

  truth.Write(gt);
  WriteFileAtomically(gt / "intrinsics.json", IntrinsicsJson(options.intrinsics).dump(2) + "\n");
  sheet.Write(out / "contact_sheet.png", options.intrinsics);
  summary.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  WriteFileAtomically(gt / "manifest.json", ManifestJson(renderer, summary).dump(2) + "\n");
  return summary;
}

}  // namespace ihs::synth
