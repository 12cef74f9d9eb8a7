#include "sensor/oni_writer.h"

#include <spdlog/spdlog.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "core/check.h"
#include "core/errors.h"
#include "sensor/depth_codec.h"
#include "sensor/oni_reader.h"

namespace ihs::sensor {
namespace {

constexpr std::uint32_t kRecordMagic = 0x0052494E;
constexpr std::size_t kRecordHeaderSize = 28;
constexpr std::uint32_t kDepthId = 1, kColorId = 2;
constexpr std::uint32_t kUnknownCount = 0xFFFFFFFF;
constexpr std::uint64_t kUnknownTimestamp = 0xFFFFFFFFFFFFFFFFull;

template <typename T>
void Put(std::string& out, T value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

void PutString(std::string& out, const std::string& text) {
  Put<std::uint32_t>(out, static_cast<std::uint32_t>(text.size() + 1));
  out.append(text);
  out.push_back('\0');
}

// A record: header (28 bytes) + fields, with `payload_size` bytes of payload to follow.
std::string Record(std::uint32_t type, std::uint32_t node_id, const std::string& fields,
                   std::uint32_t payload_size, std::uint64_t undo_position) {
  std::string out;
  Put<std::uint32_t>(out, kRecordMagic);
  Put<std::uint32_t>(out, type);
  Put<std::uint32_t>(out, node_id);
  Put<std::uint32_t>(out, static_cast<std::uint32_t>(kRecordHeaderSize + fields.size()));
  Put<std::uint32_t>(out, payload_size);
  Put<std::uint64_t>(out, undo_position);
  out += fields;
  return out;
}

std::string Property(std::uint32_t type, std::uint32_t node_id, const std::string& name,
                     const std::string& value) {
  std::string fields;
  PutString(fields, name);
  Put<std::uint32_t>(fields, static_cast<std::uint32_t>(value.size()));
  fields += value;
  return Record(type, node_id, fields, 0, 0);
}

template <typename T>
std::string Value(T value) {
  std::string bytes;
  Put(bytes, value);
  return bytes;
}

std::string FileHeader() {
  std::string header = "NI10";
  Put<std::uint8_t>(header, 1);
  Put<std::uint8_t>(header, 0);
  Put<std::uint16_t>(header, 1);
  Put<std::uint32_t>(header, 0);
  Put<std::uint64_t>(header, kUnknownTimestamp);  // Frames may come in any time order.
  // Both node ids from the start, so that even a file cut off by a crash opens in OpenNI2.
  Put<std::uint32_t>(header, kColorId);
  return header;
}

}  // namespace

void OniWriterOptions::Check() const {
  intrinsics.Check();
  IHS_CHECK_ARG(fps > 0 && fps <= 1000, "oni.fps must be in [1, 1000], got " << fps);
  IHS_CHECK_ARG(static_cast<std::size_t>(intrinsics.width) * intrinsics.height * 3 <= 5'760'000,
                "frames of " << intrinsics.width << "x" << intrinsics.height
                             << " are larger than OpenNI2's player accepts (1600x1200 RGB)");
}

OniWriter::OniWriter(std::filesystem::path path, OniWriterOptions options)
    : path_(std::move(path)), options_(std::move(options)) {
  options_.Check();
  file_ = std::fopen(path_.string().c_str(), "wb");
  if (!file_) {
    throw OutputError("cannot write " + path_.string() + ": " + std::strerror(errno));
  }
  depth_ = {kDepthId,
            0,
            0,
            {},
            "Depth",
            static_cast<std::int32_t>(OniNodeType::kDepth),
            options_.depth_codec == OniDepthCodec::k16zTable ? kOniCodec16zT : kOniCodecNone};
  color_ = {kColorId,     0, 0, {}, "Image", static_cast<std::int32_t>(OniNodeType::kImage),
            kOniCodecNone};
  Emit(FileHeader());
  depth_.node_added_position = position_;
  WriteNodeAdded(depth_, kUnknownCount, kUnknownTimestamp, 0);
  WriteStreamProperties(depth_, 2, 100, 4);
  color_.node_added_position = position_;
  WriteNodeAdded(color_, kUnknownCount, kUnknownTimestamp, 0);
  WriteStreamProperties(color_, 3, 200, 1);
  std::string data_begin;
  Put<std::uint32_t>(data_begin, kUnknownCount);
  Put<std::uint64_t>(data_begin, kUnknownTimestamp);
  for (const Stream* stream : {&depth_, &color_}) {
    Emit(Record(9, stream->id, "", 0, 0));  // NODE_STATE_READY
  }
  for (const Stream* stream : {&depth_, &color_}) {
    Emit(Record(8, stream->id, data_begin, 0, 0));  // NODE_DATA_BEGIN
  }
  std::fflush(file_);
}

OniWriter::~OniWriter() {
  if (closed_) return;
  try {
    Close();
  } catch (const std::exception& error) {
    spdlog::error("{}", error.what());
  }
}

void OniWriter::Emit(const std::string& bytes) {
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
    throw OutputError("cannot write " + path_.string() + ": " + std::strerror(errno) +
                      " (disk full?)");
  }
  position_ += bytes.size();
}

void OniWriter::WriteNodeAdded(const Stream& stream, std::uint32_t frames,
                               std::uint64_t max_timestamp, std::uint64_t seek_table_position) {
  std::string fields;
  PutString(fields, stream.name);
  Put<std::int32_t>(fields, stream.type);
  Put<std::uint32_t>(fields, stream.codec);
  Put<std::uint32_t>(fields, frames);
  Put<std::uint64_t>(fields, 0);
  Put<std::uint64_t>(fields, max_timestamp);
  Put<std::uint64_t>(fields, seek_table_position);
  Emit(Record(13, stream.id, fields, 0, 0));
}

void OniWriter::WriteStreamProperties(const Stream& stream, int bytes_per_pixel, int pixel_format,
                                      int openni1_pixel_format) {
  const CameraIntrinsics& k = options_.intrinsics;
  const auto width = static_cast<std::uint32_t>(k.width);
  const auto height = static_cast<std::uint32_t>(k.height);
  std::string mode;
  Put<std::uint32_t>(mode, width);
  Put<std::uint32_t>(mode, height);
  Put<std::uint32_t>(mode, static_cast<std::uint32_t>(options_.fps));
  std::string fov;
  Put<double>(fov, k.HorizontalFovRad());
  Put<double>(fov, k.VerticalFovRad());
  std::string cropping;
  Put<std::int32_t>(cropping, 0);
  for (int i = 0; i < 4; ++i) Put<std::uint16_t>(cropping, 0);
  const std::uint32_t id = stream.id;
  constexpr std::uint32_t kInt = 3, kGeneral = 6;
  Emit(Property(kInt, id, "oniRequiredFrameSize",
                Value<std::uint64_t>(std::uint64_t{width} * height * bytes_per_pixel)));
  Emit(Property(kInt, id, "xnIsGenerating", Value<std::uint64_t>(1)));
  if (stream.type == static_cast<std::int32_t>(OniNodeType::kDepth)) {
    Emit(Property(kInt, id, "xnDeviceMaxDepth", Value<std::uint64_t>(10000)));
  }
  Emit(Property(kInt, id, "xnSupportedMapOutputModesCount", Value<std::uint64_t>(1)));
  Emit(Property(kGeneral, id, "xnSupportedMapOutputModes", mode));
  Emit(Property(kGeneral, id, "xnMapOutputMode", mode));
  Emit(Property(kGeneral, id, "xnSupportedPixelFormats",
                Value<std::uint32_t>(openni1_pixel_format == 4 ? 0x08 : 0x01)));
  Emit(Property(kInt, id, "xnPixelFormat", Value<std::uint64_t>(openni1_pixel_format)));
  Emit(Property(kInt, id, "oniPixelFormat", Value<std::uint64_t>(pixel_format)));
  Emit(Property(kGeneral, id, "xnFOV", fov));
  Emit(Property(kInt, id, "Cropping", Value<std::uint64_t>(1)));
  Emit(Property(kGeneral, id, "xnCropping", cropping));
  Emit(Property(kInt, id, "Mirror", Value<std::uint64_t>(1)));
  Emit(Property(kInt, id, "xnMirror", Value<std::uint64_t>(0)));
}

void OniWriter::WriteFrame(Stream& stream, std::uint64_t timestamp_us, const std::string& payload) {
  std::string fields;
  Put<std::uint64_t>(fields, timestamp_us);
  Put<std::uint32_t>(fields, static_cast<std::uint32_t>(stream.entries.size() + 1));
  const std::uint64_t position = position_;
  Emit(Record(10, stream.id, fields, static_cast<std::uint32_t>(payload.size()),
              stream.last_frame_position));
  Emit(payload);
  stream.entries.push_back({timestamp_us, position});
  stream.last_frame_position = position;
}

void OniWriter::Write(const Frame& frame) {
  IHS_CHECK(!closed_, "OniWriter::Write after Close");
  frame.Check();
  IHS_CHECK_ARG(
      frame.width == options_.intrinsics.width && frame.height == options_.intrinsics.height,
      "frame " << frame.index << " is " << frame.width << "x" << frame.height
               << ", the recording is " << options_.intrinsics.width << "x"
               << options_.intrinsics.height);
  const std::size_t pixels = frame.depth_mm.size();
  std::string depth;
  if (options_.depth_codec == OniDepthCodec::k16zTable) {
    depth = Encode16zTable(frame.depth_mm.data(), pixels);
  } else {
    depth.assign(reinterpret_cast<const char*>(frame.depth_mm.data()), pixels * 2);
  }
  auto timestamp = [](std::int64_t us) {
    return static_cast<std::uint64_t>(std::max<std::int64_t>(0, us));
  };
  WriteFrame(depth_, timestamp(frame.depth_timestamp_us), depth);
  if (frame.HasColor()) {
    WriteFrame(color_, timestamp(frame.color_timestamp_us),
               std::string(reinterpret_cast<const char*>(frame.rgb.data()), frame.rgb.size()));
  }
  std::fflush(file_);
}

void OniWriter::Close() {
  if (closed_) return;
  closed_ = true;
  try {
    std::uint64_t seek_positions[2] = {0, 0};
    Stream* streams[2] = {&depth_, &color_};
    for (int s = 0; s < 2; ++s) {
      Stream& stream = *streams[s];
      Emit(Record(7, stream.id, "", 0, stream.node_added_position));  // NODE_REMOVED
      seek_positions[s] = position_;
      std::string table;
      for (int k = 0; k < 20; ++k) table.push_back('\0');  // entry[0]: frame numbers start at 1.
      for (const SeekEntry& entry : stream.entries) {
        Put<std::uint64_t>(table, entry.timestamp_us);
        Put<std::uint32_t>(table, 0);
        Put<std::uint64_t>(table, entry.position);
      }
      Emit(Record(14, stream.id, "", static_cast<std::uint32_t>(table.size()), 0));
      Emit(table);
    }
    Emit(Record(11, 0, "", 0, 0));  // END
    const std::uint64_t end = position_;
    for (int s = 0; s < 2; ++s) {
      Stream& stream = *streams[s];
      std::uint64_t max_timestamp = 0;
      for (const SeekEntry& entry : stream.entries)
        max_timestamp = std::max(max_timestamp, entry.timestamp_us);
      if (std::fseek(file_, static_cast<long>(stream.node_added_position), SEEK_SET) != 0) {
        throw OutputError("cannot write " + path_.string() + ": seek failed");
      }
      position_ = stream.node_added_position;
      WriteNodeAdded(stream, static_cast<std::uint32_t>(stream.entries.size()), max_timestamp,
                     seek_positions[s]);
    }
    position_ = end;
    const bool failed = std::fflush(file_) != 0;
    const bool close_failed = std::fclose(file_) != 0;
    file_ = nullptr;
    if (failed || close_failed) {
      throw OutputError("cannot write " + path_.string() + ": " + std::strerror(errno));
    }
  } catch (...) {
    if (file_) std::fclose(file_);
    file_ = nullptr;
    throw;
  }
}

}  // namespace ihs::sensor
