#include "sensor/tum_directory.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <tuple>
#include <utility>

#include "core/atomic_file.h"
#include "core/check.h"
#include "core/data_lines.h"
#include "core/errors.h"
#include "sensor/jpeg_decoder.h"
#include "sensor/png_decoder.h"

namespace ihs::sensor {
namespace fs = std::filesystem;
namespace {

struct Stamped {
  double time_s;
  std::string path;
};

// Images of a recording are at most this large, in bytes and in pixels (a 4096 x 4096 frame;
// no depth camera's is larger): a small file that decodes to gigabytes (a 780 KB PNG of
// 20000 x 20000 pixels) is refused before decoding.
constexpr std::uintmax_t kMaxImageBytes = 128ull << 20;
constexpr std::uint64_t kMaxImagePixels = 4096ull * 4096ull;

std::uint32_t BigEndian(const std::string& bytes, size_t at, int count) {
  std::uint32_t value = 0;
  for (int i = 0; i < count; ++i) value = value << 8 | static_cast<unsigned char>(bytes[at + i]);
  return value;
}

// The width and height a PNG or JPEG header declares; {0, 0} for other formats (OpenCV's own
// limits apply to them) or a header too short to say.
std::pair<std::uint64_t, std::uint64_t> DeclaredSize(const std::string& bytes) {
  if (bytes.size() >= 24 && bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0 &&
      bytes.compare(12, 4, "IHDR") == 0) {
    return {BigEndian(bytes, 16, 4), BigEndian(bytes, 20, 4)};
  }
  if (bytes.size() >= 4 && static_cast<unsigned char>(bytes[0]) == 0xFF &&
      static_cast<unsigned char>(bytes[1]) == 0xD8) {
    // JPEG: walk the segments to the first start-of-frame marker (C0-CF but C4, C8, CC).
    size_t at = 2;
    while (at + 9 < bytes.size() && static_cast<unsigned char>(bytes[at]) == 0xFF) {
      const unsigned marker = static_cast<unsigned char>(bytes[at + 1]);
      const size_t length = BigEndian(bytes, at + 2, 2);
      if (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC)
        return {BigEndian(bytes, at + 7, 2), BigEndian(bytes, at + 5, 2)};
      at += 2 + length;
    }
  }
  return {0, 0};
}

// Reads an image of the folder; empty with `*problem` said when it is not a regular file, too
// large, or does not decode.
cv::Mat ReadImage(const fs::path& path, int flags, std::string* problem) {
  std::string bytes;
  try {
    bytes = ReadFileToString(path, kMaxImageBytes);
  } catch (const InputError& error) {
    *problem = error.what();
    return {};
  }
  const auto [width, height] = DeclaredSize(bytes);
  if (width * height > kMaxImagePixels) {
    *problem = path.filename().string() + " declares " + std::to_string(width) + "x" +
               std::to_string(height) + " pixels, more than a depth camera's frame can have";
    return {};
  }
  if (IsPng(bytes)) return DecodePng(bytes, flags == cv::IMREAD_ANYDEPTH, kMaxImagePixels, problem);
  // A JPEG is never a depth image: as colour, it fails the depth check by its type.
  if (IsJpeg(bytes)) return DecodeJpeg(bytes, kMaxImagePixels, problem);
  cv::Mat image;
  if (!bytes.empty()) {
    try {
      image =
          cv::imdecode(cv::Mat(1, static_cast<int>(bytes.size()), CV_8UC1, bytes.data()), flags);
    } catch (const cv::Exception&) {
      image.release();  // A decoder that throws on damaged data: the frame is skipped.
    }
  }
  if (image.empty()) *problem = "cannot decode " + path.filename().string();
  return image;
}

// A timestamp a frame can carry: finite, and within ±1e11 s (3000 years; TUM's are Unix
// seconds, about 1.3e9) so that it fits in microseconds as a 64-bit integer.
bool UsableTime(double time_s) { return std::isfinite(time_s) && std::abs(time_s) <= 1e11; }

// Parses a TUM list: lines "timestamp path [...]", '#' comments, blank lines ignored.
std::vector<Stamped> ReadList(const fs::path& file) {
  std::vector<Stamped> list;
  for (const DataLine& line : ReadDataLines(file)) {
    std::istringstream fields(line.text);
    Stamped entry;
    if (!(fields >> entry.time_s >> entry.path) || !UsableTime(entry.time_s)) {
      throw InputError(file.string() + ": line " + std::to_string(line.number) +
                       " is not 'timestamp path' (a timestamp within ±1e11 s)");
    }
    list.push_back(entry);
  }
  return list;
}

bool LooksLikeDepth(const std::string& path) { return path.rfind("depth", 0) == 0; }

std::vector<TumEntry> ReadAssociations(const fs::path& file) {
  std::vector<TumEntry> entries;
  for (const DataLine& line : ReadDataLines(file)) {
    std::istringstream fields(line.text);
    double t1, t2;
    std::string p1, p2;
    if (!(fields >> t1 >> p1 >> t2 >> p2) || !UsableTime(t1) || !UsableTime(t2)) {
      throw InputError(file.string() + ": line " + std::to_string(line.number) +
                       " is not 'time path time path' (timestamps within ±1e11 s)");
    }
    // associate.py writes the pair in the order of its arguments: usually rgb, then depth.
    if (LooksLikeDepth(p1) && !LooksLikeDepth(p2)) {
      entries.push_back({t1, p1, t2, p2});
    } else {
      entries.push_back({t2, p2, t1, p1});
    }
  }
  return entries;
}

// The colour folder of Open3D's layout, or empty.
fs::path Open3dColorFolder(const fs::path& folder) {
  for (const char* name : {"color", "image", "rgb"}) {
    if (fs::is_directory(folder / name)) return folder / name;
  }
  return {};
}

// The image files of `folder` (PNG or JPEG), sorted by name, relative to its parent.
std::vector<std::string> SortedImages(const fs::path& folder) {
  std::vector<std::string> names;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    std::string extension = entry.path().extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    if (entry.is_regular_file() &&
        (extension == ".png" || extension == ".jpg" || extension == ".jpeg")) {
      names.push_back((folder.filename() / entry.path().filename()).string());
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

// Open3D's layout: the n-th depth image with the n-th colour image, 30 frames per second.
std::vector<TumEntry> ListOpen3dFolder(const fs::path& folder, int* unmatched) {
  const std::vector<std::string> depth = SortedImages(folder / "depth");
  const std::vector<std::string> color = SortedImages(Open3dColorFolder(folder));
  if (depth.size() != color.size()) {
    spdlog::warn("{}: {} depth and {} colour images: pairing the first {} by name", folder.string(),
                 depth.size(), color.size(), std::min(depth.size(), color.size()));
  }
  std::vector<TumEntry> entries;
  for (size_t i = 0; i < std::min(depth.size(), color.size()); ++i) {
    const double time_s = static_cast<double>(i) / 30.0;
    entries.push_back({time_s, depth[i], time_s, color[i]});
  }
  if (unmatched && depth.size() > color.size()) {
    *unmatched = static_cast<int>(depth.size() - color.size());
  }
  return entries;
}

// Open3D's PinholeCameraIntrinsic JSON: width, height and the column-major 3x3 matrix.
CameraIntrinsics ParseOpen3dIntrinsics(const std::string& text, const fs::path& path) {
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
  const bool valid = json.is_object() && json.contains("width") && json["width"].is_number() &&
                     json.contains("height") && json["height"].is_number() &&
                     json.contains("intrinsic_matrix") && json["intrinsic_matrix"].is_array() &&
                     json["intrinsic_matrix"].size() == 9 &&
                     std::all_of(json["intrinsic_matrix"].begin(), json["intrinsic_matrix"].end(),
                                 [](const nlohmann::json& v) { return v.is_number(); });
  if (!valid) {
    throw InputError(path.string() +
                     ": expected Open3D's intrinsics JSON (width, height, intrinsic_matrix of 9 "
                     "numbers)");
  }
  const auto& m = json["intrinsic_matrix"];
  CameraIntrinsics intrinsics;
  intrinsics.width = json["width"].get<int>();
  intrinsics.height = json["height"].get<int>();
  intrinsics.fx = m[0].get<double>();
  intrinsics.fy = m[4].get<double>();
  intrinsics.cx = m[6].get<double>();
  intrinsics.cy = m[7].get<double>();
  return intrinsics;
}

std::string FormatTime(std::int64_t timestamp_us) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6f", timestamp_us / 1e6);
  return text;
}

}  // namespace

void TumOptions::Check() const {
  IHS_CHECK_ARG(depth_scale_per_m > 0 && std::isfinite(depth_scale_per_m),
                "depth_scale_per_m must be positive, got " << depth_scale_per_m);
  IHS_CHECK_ARG(open3d_depth_scale_per_m > 0 && std::isfinite(open3d_depth_scale_per_m),
                "open3d_depth_scale_per_m must be positive, got " << open3d_depth_scale_per_m);
  IHS_CHECK_ARG(max_time_difference_s >= 0,
                "max_time_difference_s must not be negative, got " << max_time_difference_s);
  if (intrinsics) intrinsics->Check();
}

std::vector<TumEntry> ListTumDirectory(const fs::path& folder, const TumOptions& options,
                                       int* unmatched) {
  if (unmatched) *unmatched = 0;
  if (!fs::is_directory(folder)) throw InputError(folder.string() + ": not a folder");
  if (fs::exists(folder / "associations.txt")) {
    return ReadAssociations(folder / "associations.txt");
  }
  if (IsOpen3dFolder(folder)) return ListOpen3dFolder(folder, unmatched);
  if (!fs::exists(folder / "depth.txt") || !fs::exists(folder / "rgb.txt")) {
    throw InputError(folder.string() +
                     ": not a TUM RGB-D folder (needs depth.txt and rgb.txt, or associations.txt) "
                     "nor one of Open3D's (depth/ and color/)");
  }
  std::vector<Stamped> depth = ReadList(folder / "depth.txt");
  std::vector<Stamped> color = ReadList(folder / "rgb.txt");
  auto by_time = [](const Stamped& a, const Stamped& b) { return a.time_s < b.time_s; };
  std::sort(depth.begin(), depth.end(), by_time);
  std::sort(color.begin(), color.end(), by_time);

  // As associate.py: every pair within the tolerance, closest first, each image used once.
  std::vector<std::tuple<double, size_t, size_t>> candidates;
  for (size_t d = 0; d < depth.size(); ++d) {
    auto it =
        std::lower_bound(color.begin(), color.end(),
                         Stamped{depth[d].time_s - options.max_time_difference_s, ""}, by_time);
    for (; it != color.end() && it->time_s <= depth[d].time_s + options.max_time_difference_s;
         ++it) {
      candidates.emplace_back(std::abs(it->time_s - depth[d].time_s), d,
                              static_cast<size_t>(it - color.begin()));
    }
  }
  std::sort(candidates.begin(), candidates.end());
  std::vector<int> partner(depth.size(), -1);
  std::vector<bool> color_used(color.size(), false);
  for (const auto& [difference, d, c] : candidates) {
    if (partner[d] >= 0 || color_used[c]) continue;
    partner[d] = static_cast<int>(c);
    color_used[c] = true;
  }
  std::vector<TumEntry> entries;
  for (size_t d = 0; d < depth.size(); ++d) {
    if (partner[d] < 0) {
      if (unmatched) ++*unmatched;
      continue;
    }
    const Stamped& c = color[partner[d]];
    entries.push_back({depth[d].time_s, depth[d].path, c.time_s, c.path});
  }
  return entries;
}

bool IsOpen3dFolder(const fs::path& folder) {
  return !fs::exists(folder / "associations.txt") && !fs::exists(folder / "depth.txt") &&
         fs::is_directory(folder / "depth") && !Open3dColorFolder(folder).empty();
}

CameraIntrinsics ReadIntrinsicsFile(const fs::path& path) {
  const std::string text = ReadFileToString(path);
  const size_t first = text.find_first_not_of(" \t\r\n");
  CameraIntrinsics intrinsics;
  if (first != std::string::npos && text[first] == '{') {
    intrinsics = ParseOpen3dIntrinsics(text, path);
  } else {
    std::istringstream fields(text);
    if (!(fields >> intrinsics.fx >> intrinsics.fy >> intrinsics.cx >> intrinsics.cy >>
          intrinsics.width >> intrinsics.height)) {
      throw InputError(path.string() +
                       ": expected 'fx fy cx cy width height' or Open3D's intrinsics JSON");
    }
  }
  try {
    intrinsics.Check();
  } catch (const std::invalid_argument& error) {
    throw InputError(path.string() + ": " + error.what());
  }
  return intrinsics;
}

std::string Open3dIntrinsicsJson(const CameraIntrinsics& k) {
  const nlohmann::json json = {
      {"width", k.width},
      {"height", k.height},
      {"intrinsic_matrix", {k.fx, 0.0, 0.0, 0.0, k.fy, 0.0, k.cx, k.cy, 1.0}}};
  return json.dump(1) + "\n";
}

CameraIntrinsics ParseIntrinsics(const std::string& text) {
  std::vector<double> values;
  std::stringstream fields(text);
  std::string field;
  while (std::getline(fields, field, ',')) {
    size_t used = 0;
    double value = 0;
    try {
      value = std::stod(field, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != field.size()) {
      throw std::invalid_argument("intrinsics '" + text + "': '" + field + "' is not a number");
    }
    values.push_back(value);
  }
  IHS_CHECK_ARG(values.size() == 4 || values.size() == 6,
                "intrinsics '" << text << "' must be fx,fy,cx,cy or fx,fy,cx,cy,width,height");
  CameraIntrinsics intrinsics;
  intrinsics.fx = values[0];
  intrinsics.fy = values[1];
  intrinsics.cx = values[2];
  intrinsics.cy = values[3];
  if (values.size() == 6) {
    intrinsics.width = static_cast<int>(values[4]);
    intrinsics.height = static_cast<int>(values[5]);
  }
  intrinsics.Check();
  return intrinsics;
}

TumDirectorySource::TumDirectorySource(fs::path folder, TumOptions options)
    : folder_(std::move(folder)), options_(std::move(options)) {
  options_.Check();
}

void TumDirectorySource::Start() {
  entries_ = ListTumDirectory(folder_, options_, &unmatched_);
  if (entries_.empty()) {
    throw InputError(folder_.string() + ": no depth image has a colour image within " +
                     std::to_string(options_.max_time_difference_s) + " s");
  }
  if (unmatched_ > 0) {
    spdlog::warn("{}: {} depth images have no colour image within {} s and are left out",
                 folder_.string(), unmatched_, options_.max_time_difference_s);
  }
  depth_scale_per_m_ =
      IsOpen3dFolder(folder_) ? options_.open3d_depth_scale_per_m : options_.depth_scale_per_m;
  if (options_.intrinsics) {
    intrinsics_ = *options_.intrinsics;
  } else if (fs::exists(folder_ / "intrinsics.txt")) {
    intrinsics_ = ReadIntrinsicsFile(folder_ / "intrinsics.txt");
  } else if (fs::exists(folder_ / "camera_intrinsic.json")) {
    intrinsics_ = ReadIntrinsicsFile(folder_ / "camera_intrinsic.json");
  } else {
    spdlog::warn(
        "{}: no intrinsics (no intrinsics.txt or camera_intrinsic.json, no --intrinsics): "
        "assuming a Carmine 1.09's; give the camera's with --intrinsics FILE",
        folder_.string());
    intrinsics_ = CameraIntrinsics::Carmine109();
    std::string problem;
    const cv::Mat first =
        ReadImage(folder_ / entries_.front().depth_path, cv::IMREAD_ANYDEPTH, &problem);
    if (!first.empty() && (first.cols != intrinsics_.width || first.rows != intrinsics_.height)) {
      intrinsics_ = intrinsics_.Scaled(first.cols, first.rows);
    }
  }
  next_ = 0;
  delivered_ = 0;
  skipped_ = 0;
}

SourceRead TumDirectorySource::Next(std::chrono::milliseconds) {
  while (next_ < entries_.size()) {
    const TumEntry& entry = entries_[next_++];
    std::string depth_problem, color_problem, problem;
    const cv::Mat depth =
        ReadImage(folder_ / entry.depth_path, cv::IMREAD_ANYDEPTH, &depth_problem);
    const cv::Mat bgr =
        depth.empty() ? cv::Mat()
                      : ReadImage(folder_ / entry.color_path, cv::IMREAD_COLOR, &color_problem);
    if (depth.empty()) {
      problem = "cannot read depth image " + entry.depth_path + ": " + depth_problem;
    } else if (depth.type() != CV_16UC1) {
      problem = "depth image " + entry.depth_path + " is not a 16-bit single-channel image";
    } else if (bgr.empty()) {
      problem = "cannot read colour image " + entry.color_path + ": " + color_problem;
    } else if (bgr.size() != depth.size()) {
      problem = "colour image " + entry.color_path + " differs in size from its depth image";
    } else if (depth.cols != intrinsics_.width || depth.rows != intrinsics_.height) {
      problem = "depth image " + entry.depth_path + " is " + std::to_string(depth.cols) + "x" +
                std::to_string(depth.rows) + ", the intrinsics say " +
                std::to_string(intrinsics_.width) + "x" + std::to_string(intrinsics_.height);
    }
    if (!problem.empty()) {
      ++skipped_;
      spdlog::warn("{}: skipping a frame: {}", folder_.string(), problem);
      continue;
    }
    auto frame = std::make_shared<Frame>(Frame::Blank(depth.cols, depth.rows));
    const double mm_per_unit = 1000.0 / depth_scale_per_m_;
    for (int v = 0; v < depth.rows; ++v) {
      const auto* row = depth.ptr<std::uint16_t>(v);
      for (int u = 0; u < depth.cols; ++u) {
        const double mm = std::round(row[u] * mm_per_unit);
        frame->depth_mm[v * depth.cols + u] = mm > 65535.0 ? 0 : static_cast<std::uint16_t>(mm);
      }
    }
    cv::Mat rgb(depth.rows, depth.cols, CV_8UC3, frame->rgb.data());
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    frame->depth_timestamp_us = std::llround(entry.depth_time_s * 1e6);
    frame->color_timestamp_us = std::llround(entry.color_time_s * 1e6);
    frame->index = delivered_++;
    return {SourceStatus::kFrame, std::move(frame), ""};
  }
  return {SourceStatus::kEndOfStream, nullptr, "end of " + folder_.string()};
}

std::optional<std::int64_t> TumDirectorySource::FrameCount() const {
  return static_cast<std::int64_t>(entries_.size());
}

TumWriter::TumWriter(fs::path folder, const CameraIntrinsics& intrinsics, TumOptions options)
    : folder_(std::move(folder)), intrinsics_(intrinsics), options_(std::move(options)) {
  options_.Check();
  intrinsics_.Check();
  std::error_code ec;
  fs::create_directories(folder_ / "depth", ec);
  fs::create_directories(folder_ / "rgb", ec);
  if (!fs::is_directory(folder_ / "depth") || !fs::is_directory(folder_ / "rgb")) {
    throw OutputError("cannot create the TUM folder " + folder_.string() +
                      (ec ? ": " + ec.message() : ""));
  }
}

TumWriter::~TumWriter() {
  if (finished_) return;
  try {
    Finish();
  } catch (const std::exception& error) {
    spdlog::error("{}", error.what());
  }
}

void TumWriter::Write(const Frame& frame) {
  frame.Check();
  const double units_per_mm = options_.depth_scale_per_m / 1000.0;
  cv::Mat depth(frame.height, frame.width, CV_16UC1);
  for (int v = 0; v < frame.height; ++v) {
    auto* row = depth.ptr<std::uint16_t>(v);
    for (int u = 0; u < frame.width; ++u) {
      const double units = std::round(frame.DepthAt(u, v) * units_per_mm);
      row[u] = units > 65535.0 ? 0 : static_cast<std::uint16_t>(units);
    }
  }
  TumEntry entry;
  entry.depth_time_s = frame.depth_timestamp_us / 1e6;
  entry.depth_path = "depth/" + FormatTime(frame.depth_timestamp_us) + ".png";
  std::vector<std::uint8_t> bytes;
  cv::imencode(".png", depth, bytes);
  WriteFileAtomically(folder_ / entry.depth_path, std::string(bytes.begin(), bytes.end()));
  if (frame.HasColor()) {
    const cv::Mat rgb(frame.height, frame.width, CV_8UC3,
                      const_cast<std::uint8_t*>(frame.rgb.data()));
    cv::Mat bgr;
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    entry.color_time_s = frame.color_timestamp_us / 1e6;
    entry.color_path = "rgb/" + FormatTime(frame.color_timestamp_us) + ".png";
    cv::imencode(".png", bgr, bytes);
    WriteFileAtomically(folder_ / entry.color_path, std::string(bytes.begin(), bytes.end()));
  }
  entries_.push_back(entry);
}

void TumWriter::Finish() {
  finished_ = true;
  std::ostringstream depth_list, color_list, associations;
  const char* header = "# written by inhandscan\n# timestamp filename\n";
  depth_list << header;
  color_list << header;
  associations << "# timestamp rgb timestamp depth\n";
  char line[256];
  for (const TumEntry& entry : entries_) {
    std::snprintf(line, sizeof(line), "%.6f %s\n", entry.depth_time_s, entry.depth_path.c_str());
    depth_list << line;
    if (entry.color_path.empty()) continue;
    std::snprintf(line, sizeof(line), "%.6f %s\n", entry.color_time_s, entry.color_path.c_str());
    color_list << line;
    std::snprintf(line, sizeof(line), "%.6f %s %.6f %s\n", entry.color_time_s,
                  entry.color_path.c_str(), entry.depth_time_s, entry.depth_path.c_str());
    associations << line;
  }
  WriteFileAtomically(folder_ / "depth.txt", depth_list.str());
  WriteFileAtomically(folder_ / "rgb.txt", color_list.str());
  WriteFileAtomically(folder_ / "associations.txt", associations.str());
  std::ostringstream intrinsics;
  intrinsics.precision(17);
  intrinsics << intrinsics_.fx << ' ' << intrinsics_.fy << ' ' << intrinsics_.cx << ' '
             << intrinsics_.cy << ' ' << intrinsics_.width << ' ' << intrinsics_.height << '\n';
  WriteFileAtomically(folder_ / "intrinsics.txt", intrinsics.str());
}

}  // namespace ihs::sensor
