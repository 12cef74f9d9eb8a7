#pragma once
// Writes RGB-D frames as an OpenNI .oni recording that OpenNI2's own player opens (format:
// docs/oni-format.md): a depth stream (16zT-compressed or raw, 1 mm units) and an RGB888 colour
// stream, with the properties the player needs, seek tables and an END record.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"

namespace ihs::sensor {

/// How depth frames are stored.
enum class OniDepthCodec {
  k16zTable,      ///< Lossless "16zT", what OpenNI's recorders use (about 4–6× smaller).
  kUncompressed,  ///< Raw 16-bit samples ("NONE").
};

/// Options of the .oni writer.
struct OniWriterOptions {
  /// Camera of the frames; written as the streams' fields of view.
  CameraIntrinsics intrinsics;
  /// Frame rate recorded in the streams' video mode, Hz.
  int fps = 30;
  /// Depth codec.
  OniDepthCodec depth_codec = OniDepthCodec::k16zTable;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// Streams frames into an .oni file. Frames are written as they come, so a recording cut off by
/// a crash keeps every complete frame (our reader recovers them); Close() adds the seek tables
/// and END record and patches the frame counts.
class OniWriter {
 public:
  /// Creates (truncates) `path`. Throws ihs::OutputError if it cannot be created.
  OniWriter(std::filesystem::path path, OniWriterOptions options);
  /// Closes the file if Close() was not called (errors are then only logged).
  ~OniWriter();
  OniWriter(const OniWriter&) = delete;
  OniWriter& operator=(const OniWriter&) = delete;

  /// Appends a frame (its depth, and its colour when present). All frames must have the size of
  /// the intrinsics. Throws std::invalid_argument for a frame that does not fit, ihs::OutputError
  /// when writing fails.
  void Write(const Frame& frame);
  /// Finishes the file. Throws ihs::OutputError when writing fails.
  void Close();

  /// Depth frames written so far.
  std::int64_t frames_written() const { return static_cast<std::int64_t>(depth_.entries.size()); }

 private:
  struct SeekEntry {
    std::uint64_t timestamp_us;
    std::uint64_t position;
  };
  struct Stream {
    std::uint32_t id;
    std::uint64_t node_added_position = 0;
    std::uint64_t last_frame_position = 0;
    std::vector<SeekEntry> entries;
    std::string name;
    std::int32_t type;
    std::uint32_t codec;
  };

  void Emit(const std::string& bytes);
  void WriteNodeAdded(const Stream& stream, std::uint32_t frames, std::uint64_t max_timestamp,
                      std::uint64_t seek_table_position);
  void WriteStreamProperties(const Stream& stream, int bytes_per_pixel, int pixel_format,
                             int openni1_pixel_format);
  void WriteFrame(Stream& stream, std::uint64_t timestamp_us, const std::string& payload);

  const std::filesystem::path path_;
  const OniWriterOptions options_;
  std::FILE* file_ = nullptr;
  std::uint64_t position_ = 0;
  Stream depth_;
  Stream color_;
  bool closed_ = false;
};

}  // namespace ihs::sensor
