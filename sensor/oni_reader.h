#pragma once
// The project's own reader of OpenNI .oni recordings (format: docs/oni-format.md). Unlike
// OpenNI2's player it recovers every complete frame of a recording cut off by a crash or a full
// disk, and it never trusts a size in the file beyond the bytes that are really there.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "sensor/frame_source.h"

namespace ihs::sensor {

/// Node types of .oni files.
enum class OniNodeType : std::int32_t { kDevice = 1, kDepth = 2, kImage = 3, kIr = 5 };

/// Codec FourCCs of .oni files.
inline constexpr std::uint32_t kOniCodecNone = 0x454E4F4E;  // "NONE"
inline constexpr std::uint32_t kOniCodec16z = 0x507A3631;   // "16zP"
inline constexpr std::uint32_t kOniCodec16zT = 0x547A3631;  // "16zT"
inline constexpr std::uint32_t kOniCodecJpeg = 0x4745504A;  // "JPEG"

/// One frame record of a node: where its encoded bytes lie in the file.
struct OniFrameRecord {
  std::uint64_t timestamp_us = 0;
  std::uint32_t frame_number = 0;
  std::uint64_t payload_offset = 0;
  std::uint32_t payload_size = 0;
};

/// A stream (node) of a recording as far as the reader understood it.
struct OniNode {
  std::uint32_t id = 0;
  std::string name;
  std::int32_t type = 0;
  std::uint32_t codec = 0;
  int width = 0;
  int height = 0;
  int fps = 0;
  /// OpenNI2 pixel format (100 depth mm, 101 depth 0.1 mm, 200 RGB888, 202 GRAY8, …).
  int pixel_format = 0;
  double horizontal_fov_rad = 0;
  double vertical_fov_rad = 0;
  /// Frame count declared by the file (0xFFFFFFFF in an unfinished OpenNI2 recording).
  std::uint32_t declared_frames = 0;
  /// Complete frame records, in file order.
  std::vector<OniFrameRecord> frames;
};

/// The structure of a recording.
struct OniIndex {
  /// File version "1.0.1.0" etc.
  std::string version;
  std::vector<OniNode> nodes;
  /// Whether the END record was reached (the file is complete).
  bool complete = false;
  /// Why reading stopped early (empty when complete).
  std::string damage;

  /// The first node of the given type, or null.
  const OniNode* FirstOfType(OniNodeType type) const;
};

/// Indexes the records of an .oni file held in `bytes`. Stops at the first damaged or missing
/// record and keeps everything complete before it. Throws ihs::InputError (starting with
/// `name`) when the bytes are not an .oni recording at all.
OniIndex IndexOni(std::string_view bytes, const std::string& name);

/// Decodes one depth frame of `node` into millimetres (width·height values). Returns false when
/// the payload is damaged or does not match the node's size.
bool DecodeOniDepth(std::string_view bytes, const OniNode& node, const OniFrameRecord& record,
                    std::vector<std::uint16_t>& depth_mm);

/// Decodes one colour frame of `node` into RGB8 (width·height·3 bytes). Returns false when the
/// payload is damaged, not RGB888/JPEG, or does not match the node's size.
bool DecodeOniColor(std::string_view bytes, const OniNode& node, const OniFrameRecord& record,
                    std::vector<std::uint8_t>& rgb);

/// Plays an .oni file with the project's reader: each depth frame with the colour frame nearest
/// in time (within `max_color_offset_us`), in file order. A damaged file plays every complete
/// frame, logs how many were recovered, and reports Recovered().
class OniFileSource : public FrameSource {
 public:
  explicit OniFileSource(std::filesystem::path path, std::int64_t max_color_offset_us = 34'000);
  ~OniFileSource() override;

  /// Indexes the file (read a piece at a time, never mapped whole: memory stays bounded by one
  /// frame). Throws ihs::InputError naming the file when it is missing, not an .oni recording,
  /// or holds no complete depth frame.
  void Start() override;
  void Stop() override;
  /// Throws ihs::InputError when the file can no longer be read (cut short while it plays).
  SourceRead Next(std::chrono::milliseconds timeout) override;
  CameraIntrinsics Intrinsics() const override { return intrinsics_; }
  std::string Description() const override {
    return "recording " + path_.string() + " (built-in reader)";
  }
  std::optional<std::int64_t> FrameCount() const override;
  bool IsLive() const override { return false; }
  std::int64_t SkippedFrames() const override { return skipped_; }
  bool Recovered() const override { return !index_.complete; }

  /// The index of the file (valid after Start()).
  const OniIndex& index() const { return index_; }
  /// Whether this reader decodes the depth stream's codec (NONE, 16zP, 16zT; valid after Start()).
  bool DecodesDepthCodec() const;

 private:
  class File;
  const std::filesystem::path path_;
  const std::int64_t max_color_offset_us_;
  std::unique_ptr<File> file_;
  OniIndex index_;
  const OniNode* depth_ = nullptr;
  const OniNode* color_ = nullptr;
  CameraIntrinsics intrinsics_;
  std::size_t next_ = 0;
  std::size_t color_cursor_ = 0;
  std::int64_t delivered_ = 0;
  std::int64_t skipped_ = 0;
};

}  // namespace ihs::sensor
