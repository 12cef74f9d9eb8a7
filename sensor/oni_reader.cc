#include "sensor/oni_reader.h"

#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/check.h"
#include "core/errors.h"
#include "sensor/depth_codec.h"
#include "sensor/jpeg_decoder.h"

namespace ihs::sensor {
namespace {

constexpr std::uint32_t kRecordMagic = 0x0052494E;  // "NIR\0"
constexpr std::size_t kFileHeaderSize = 24;
// No real frame is larger than this (1600·1200·3 is OpenNI's own limit); it bounds allocations.
constexpr std::size_t kMaxFrameBytes = 64u << 20;
constexpr int kMaxImageSide = 8192;
// A record's fields are a name and a few numbers, or a property's value (the largest real ones,
// depth-to-colour tables, are tens of kB); it bounds what indexing reads at once.
constexpr std::size_t kMaxFieldsBytes = 16u << 20;

enum RecordType : std::uint32_t {
  kNodeAdded_1_0_0_4 = 2,
  kIntProperty = 3,
  kRealProperty = 4,
  kStringProperty = 5,
  kGeneralProperty = 6,
  kNodeRemoved = 7,
  kNodeDataBegin = 8,
  kNodeStateReady = 9,
  kNewData = 10,
  kEnd = 11,
  kNodeAdded_1_0_0_5 = 12,
  kNodeAdded = 13,
  kSeekTable = 14,
};

template <typename T>
T Load(const char* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

// Reads fields of one record with bounds checks; any overrun sets `ok` to false.
class FieldReader {
 public:
  FieldReader(const char* data, std::size_t size) : data_(data), size_(size) {}
  template <typename T>
  T Get() {
    if (!ok || size_ - position_ < sizeof(T)) {
      ok = false;
      return T{};
    }
    const T value = Load<T>(data_ + position_);
    position_ += sizeof(T);
    return value;
  }
  std::string String() {
    const std::uint32_t length = Get<std::uint32_t>();
    if (!ok || length == 0 || length > 4096 || size_ - position_ < length) {
      ok = false;
      return {};
    }
    std::string text(data_ + position_, length);
    position_ += length;
    if (!text.empty() && text.back() == '\0') text.pop_back();
    return text;
  }
  std::string_view Bytes(std::size_t count) {
    if (!ok || size_ - position_ < count) {
      ok = false;
      return {};
    }
    std::string_view bytes(data_ + position_, count);
    position_ += count;
    return bytes;
  }
  bool ok = true;

 private:
  const char* data_;
  std::size_t size_;
  std::size_t position_ = 0;
};

// Byte ranges of a recording: all of it in memory, or a file read a piece at a time.
class OniBytes {
 public:
  virtual ~OniBytes() = default;
  virtual std::uint64_t Size() const = 0;
  // The `count` bytes at `offset` (offset + count <= Size()), valid until the next Read.
  virtual std::string_view Read(std::uint64_t offset, std::size_t count) = 0;
};

class MemoryBytes final : public OniBytes {
 public:
  explicit MemoryBytes(std::string_view bytes) : bytes_(bytes) {}
  std::uint64_t Size() const override { return bytes_.size(); }
  std::string_view Read(std::uint64_t offset, std::size_t count) override {
    return bytes_.substr(static_cast<std::size_t>(offset), count);
  }

 private:
  std::string_view bytes_;
};

// The record types whose fields the index reads.
bool ReadsFields(std::uint32_t type) {
  switch (type) {
    case kNodeAdded:
    case kNodeAdded_1_0_0_5:
    case kNodeAdded_1_0_0_4:
    case kIntProperty:
    case kRealProperty:
    case kStringProperty:
    case kGeneralProperty:
    case kNewData:
      return true;
    default:
      return false;
  }
}

OniNode* FindNode(std::vector<OniNode>& nodes, std::uint32_t id) {
  for (OniNode& node : nodes) {
    if (node.id == id) return &node;
  }
  return nullptr;
}

void ApplyProperty(OniNode& node, std::uint32_t type, const std::string& name,
                   std::string_view value) {
  if (type == kGeneralProperty && name == "xnMapOutputMode" && value.size() == 12) {
    node.width = static_cast<int>(Load<std::uint32_t>(value.data()));
    node.height = static_cast<int>(Load<std::uint32_t>(value.data() + 4));
    node.fps = static_cast<int>(Load<std::uint32_t>(value.data() + 8));
  } else if (type == kGeneralProperty && name == "xnFOV" && value.size() >= 16) {
    node.horizontal_fov_rad = Load<double>(value.data());
    node.vertical_fov_rad = Load<double>(value.data() + 8);
  } else if (type == kIntProperty && value.size() >= 8) {
    const auto number = static_cast<std::int64_t>(Load<std::uint64_t>(value.data()));
    if (name == "oniPixelFormat") {
      node.pixel_format = static_cast<int>(number);
    } else if (name == "xnPixelFormat" && node.type != static_cast<int>(OniNodeType::kDepth)) {
      static const int kFromOpenNi1[] = {0, 200, 201, 202, 203, 204};
      if (number >= 1 && number <= 5) node.pixel_format = kFromOpenNi1[number];
    }
  }
}

// Whether the node has a plausible image size and the record's payload lies inside the file.
bool FrameFits(std::string_view bytes, const OniNode& node, const OniFrameRecord& record) {
  return node.width > 0 && node.height > 0 && node.width <= kMaxImageSide &&
         node.height <= kMaxImageSide && record.payload_size <= kMaxFrameBytes &&
         record.payload_offset <= bytes.size() &&
         record.payload_size <= bytes.size() - record.payload_offset;
}

}  // namespace

const OniNode* OniIndex::FirstOfType(OniNodeType type) const {
  for (const OniNode& node : nodes) {
    if (node.type == static_cast<std::int32_t>(type)) return &node;
  }
  return nullptr;
}

namespace {

// Checks the file header and fills the index's version; returns the size of a record header
// (24 bytes up to version 1.0.0.5, 28 from 1.0.1.0).
std::size_t ReadFileHeader(OniBytes& bytes, const std::string& name, OniIndex& index) {
  const std::string_view header =
      bytes.Size() < kFileHeaderSize ? std::string_view() : bytes.Read(0, kFileHeaderSize);
  if (header.size() < kFileHeaderSize || std::memcmp(header.data(), "NI10", 4) != 0) {
    throw InputError(name + ": not an .oni recording (no NI10 header)");
  }
  const auto major = static_cast<std::uint8_t>(header[4]);
  const auto minor = static_cast<std::uint8_t>(header[5]);
  const auto maintenance = Load<std::uint16_t>(header.data() + 6);
  const auto build = Load<std::uint32_t>(header.data() + 8);
  index.version = std::to_string(major) + "." + std::to_string(minor) + "." +
                  std::to_string(maintenance) + "." + std::to_string(build);
  const auto version = std::make_tuple(major, minor, maintenance, build);
  if (version < std::make_tuple(1, 0, 0, 4) || version > std::make_tuple(1, 0, 1, 0)) {
    throw InputError(name + ": unsupported .oni version " + index.version);
  }
  return version >= std::make_tuple(1, 0, 1, 0) ? 28 : 24;
}

// One record's header.
struct RecordHeader {
  std::uint32_t magic = 0;
  std::uint32_t type = 0;
  std::uint32_t node_id = 0;
  std::uint32_t fields_size = 0;
  std::uint32_t payload_size = 0;
};

// Adds what one record says to the index (its fields in `fields`, its payload at
// `payload_offset`). Returns false for a record type the reader does not know.
bool ApplyRecord(const RecordHeader& record, FieldReader& fields, std::uint64_t payload_offset,
                 OniIndex& index) {
  switch (record.type) {
    case kNodeAdded:
    case kNodeAdded_1_0_0_5:
    case kNodeAdded_1_0_0_4: {
      OniNode node;
      node.id = record.node_id;
      node.name = fields.String();
      node.type = fields.Get<std::int32_t>();
      node.codec = fields.Get<std::uint32_t>();
      if (record.type != kNodeAdded_1_0_0_4) node.declared_frames = fields.Get<std::uint32_t>();
      if (node.type == static_cast<std::int32_t>(OniNodeType::kDepth)) node.pixel_format = 100;
      if (node.type == static_cast<std::int32_t>(OniNodeType::kImage)) node.pixel_format = 200;
      if (node.type == static_cast<std::int32_t>(OniNodeType::kIr)) node.pixel_format = 203;
      if (fields.ok) {
        if (OniNode* existing = FindNode(index.nodes, record.node_id)) {
          // OpenNI rewrites NODE_ADDED at close; a repeated one (after looping) keeps the frames.
          node.frames = std::move(existing->frames);
          *existing = std::move(node);
        } else {
          index.nodes.push_back(std::move(node));
        }
      }
      return true;
    }
    case kIntProperty:
    case kRealProperty:
    case kStringProperty:
    case kGeneralProperty: {
      const std::string property = fields.String();
      const std::uint32_t value_size = fields.Get<std::uint32_t>();
      const std::string_view value = fields.Bytes(value_size);
      if (OniNode* node = FindNode(index.nodes, record.node_id); node && fields.ok) {
        ApplyProperty(*node, record.type, property, value);
      }
      return true;
    }
    case kNewData: {
      OniFrameRecord frame;
      frame.timestamp_us = fields.Get<std::uint64_t>();
      frame.frame_number = fields.Get<std::uint32_t>();
      frame.payload_offset = payload_offset;
      frame.payload_size = record.payload_size;
      OniNode* node = FindNode(index.nodes, record.node_id);
      if (fields.ok && node) node->frames.push_back(frame);
      return true;
    }
    case kNodeRemoved:
    case kNodeDataBegin:
    case kNodeStateReady:
    case kSeekTable:
      return true;
    case kEnd:
      index.complete = true;
      return true;
    default:
      return false;
  }
}

// Indexes the records of `bytes`, reading each record's header and, where they matter, its
// fields; payloads are only stepped over.
OniIndex IndexRecords(OniBytes& bytes, const std::string& name) {
  OniIndex index;
  const std::size_t header_size = ReadFileHeader(bytes, name, index);
  const std::uint64_t size = bytes.Size();
  std::uint64_t position = kFileHeaderSize;
  auto stop = [&](const std::string& why) {
    index.damage = why + " at byte " + std::to_string(position);
  };
  while (!index.complete) {
    if (position == size) {
      stop("the file ends without an END record");
      break;
    }
    if (size - position < header_size) {
      stop("the file ends inside a record header");
      break;
    }
    const char* data = bytes.Read(position, header_size).data();
    const RecordHeader record{Load<std::uint32_t>(data), Load<std::uint32_t>(data + 4),
                              Load<std::uint32_t>(data + 8), Load<std::uint32_t>(data + 12),
                              Load<std::uint32_t>(data + 16)};
    if (record.magic != kRecordMagic || record.fields_size < header_size) {
      stop("invalid record header");
      break;
    }
    const std::uint64_t available = size - position;
    if (record.fields_size > available || record.payload_size > available - record.fields_size) {
      stop("the file ends inside a record");
      break;
    }
    const std::size_t fields_bytes = record.fields_size - header_size;
    if (ReadsFields(record.type) && fields_bytes > kMaxFieldsBytes) {
      stop("a record of type " + std::to_string(record.type) + " with " +
           std::to_string(fields_bytes) + " bytes of fields");
      break;
    }
    const std::string_view field_view = ReadsFields(record.type)
                                            ? bytes.Read(position + header_size, fields_bytes)
                                            : std::string_view();
    FieldReader fields(field_view.data(), field_view.size());
    if (!ApplyRecord(record, fields, position + record.fields_size, index)) {
      stop("unknown record type " + std::to_string(record.type));
      break;
    }
    if (!fields.ok) {
      stop("malformed record of type " + std::to_string(record.type));
      break;
    }
    position += static_cast<std::uint64_t>(record.fields_size) + record.payload_size;
  }
  return index;
}

}  // namespace

OniIndex IndexOni(std::string_view bytes, const std::string& name) {
  MemoryBytes memory(bytes);
  return IndexRecords(memory, name);
}

bool DecodeOniDepth(std::string_view bytes, const OniNode& node, const OniFrameRecord& record,
                    std::vector<std::uint16_t>& depth_mm) {
  if (!FrameFits(bytes, node, record)) return false;
  const std::size_t pixels = static_cast<std::size_t>(node.width) * node.height;
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data() + record.payload_offset);
  bool ok = false;
  switch (node.codec) {
    case kOniCodecNone:
      ok = record.payload_size == pixels * 2;
      if (ok) {
        depth_mm.resize(pixels);
        std::memcpy(depth_mm.data(), data, pixels * 2);
      }
      break;
    case kOniCodec16z:
      ok = Decode16z(data, record.payload_size, pixels, depth_mm);
      break;
    case kOniCodec16zT:
      ok = Decode16zTable(data, record.payload_size, pixels, depth_mm);
      break;
    default:
      return false;
  }
  if (!ok || depth_mm.size() != pixels) return false;
  if (node.pixel_format == 101) {  // DEPTH_100_UM: tenths of a millimetre.
    for (std::uint16_t& d : depth_mm) d = static_cast<std::uint16_t>((d + 5) / 10);
  }
  return true;
}

bool DecodeOniColor(std::string_view bytes, const OniNode& node, const OniFrameRecord& record,
                    std::vector<std::uint8_t>& rgb) {
  if (!FrameFits(bytes, node, record) || node.pixel_format != 200) return false;
  const std::size_t size = static_cast<std::size_t>(node.width) * node.height * 3;
  const char* data = bytes.data() + record.payload_offset;
  if (node.codec == kOniCodecNone) {
    if (record.payload_size != size) return false;
    rgb.assign(data, data + size);
    return true;
  }
  if (node.codec != kOniCodecJpeg) return false;
  std::string problem;  // The caller skips the colour frame; libjpeg's reason is not needed.
  const cv::Mat bgr = DecodeJpeg(std::string_view(data, record.payload_size),
                                 static_cast<std::uint64_t>(node.width) * node.height, &problem);
  if (bgr.empty() || bgr.cols != node.width || bgr.rows != node.height) return false;
  rgb.resize(size);
  cv::Mat out(node.height, node.width, CV_8UC3, rgb.data());
  cv::cvtColor(bgr, out, cv::COLOR_BGR2RGB);
  return true;
}

// The recording read a piece at a time, never mapped: memory stays bounded by one frame whatever
// the file's size, and a file that shrinks while it plays is an input error (a mapping's read
// past the new end is SIGBUS).
class OniFileSource::File final : public OniBytes {
 public:
  explicit File(std::string name) : name_(std::move(name)) {
    fd_ = ::open(name_.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) throw InputError(name_ + ": cannot open: " + std::strerror(errno));
    struct stat status {};
    if (fstat(fd_, &status) != 0 || !S_ISREG(status.st_mode)) {
      throw InputError(name_ + ": not a regular file");
    }
    size_ = static_cast<std::uint64_t>(status.st_size);
    if (size_ == 0) throw InputError(name_ + ": the file is empty");
  }
  ~File() override {
    if (fd_ >= 0) ::close(fd_);
  }
  File(const File&) = delete;
  File& operator=(const File&) = delete;

  std::uint64_t Size() const override { return size_; }
  std::string_view Read(std::uint64_t offset, std::size_t count) override {
    buffer_.resize(count);
    std::size_t done = 0;
    while (done < count) {
      const ssize_t n =
          ::pread(fd_, buffer_.data() + done, count - done, static_cast<off_t>(offset + done));
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) throw InputError(name_ + ": cannot read: " + std::strerror(errno));
      if (n == 0) {
        throw InputError(name_ + ": the file ends at byte " + std::to_string(offset + done) +
                         " though it had " + std::to_string(size_) +
                         " when the scan opened it: it was cut while it was read");
      }
      done += static_cast<std::size_t>(n);
    }
    return {buffer_.data(), count};
  }

  // A frame record's payload, and the record as it lies in that payload. False when it is too
  // large to be a frame (DecodeOni* would refuse it).
  bool Payload(const OniFrameRecord& record, std::string_view& bytes, OniFrameRecord& at) {
    if (record.payload_size > kMaxFrameBytes) return false;
    bytes = Read(record.payload_offset, record.payload_size);
    at = record;
    at.payload_offset = 0;
    return true;
  }

 private:
  const std::string name_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
  std::vector<char> buffer_;
};

OniFileSource::OniFileSource(std::filesystem::path path, std::int64_t max_color_offset_us)
    : path_(std::move(path)), max_color_offset_us_(max_color_offset_us) {
  IHS_CHECK_ARG(max_color_offset_us_ >= 0, "max_color_offset_us must not be negative");
}

OniFileSource::~OniFileSource() = default;

void OniFileSource::Start() {
  const std::string name = path_.string();
  auto file = std::make_unique<File>(name);
  index_ = IndexRecords(*file, name);
  depth_ = index_.FirstOfType(OniNodeType::kDepth);
  color_ = index_.FirstOfType(OniNodeType::kImage);
  if (!depth_) throw InputError(name + ": the recording has no depth stream");
  if (depth_->frames.empty()) {
    throw InputError(name + ": the recording holds no complete depth frame" +
                     (index_.damage.empty() ? "" : " (" + index_.damage + ")"));
  }
  if (depth_->width <= 0 || depth_->height <= 0) {
    throw InputError(name + ": the depth stream has no image size (xnMapOutputMode)");
  }
  if (!index_.complete) {
    spdlog::warn("{}: damaged recording ({}); recovered {} complete depth frames", name,
                 index_.damage, depth_->frames.size());
  }
  const OniNode& geometry = color_ && color_->horizontal_fov_rad > 0.1 ? *color_ : *depth_;
  if (geometry.horizontal_fov_rad > 0.1 && geometry.horizontal_fov_rad < 3.0 &&
      geometry.vertical_fov_rad > 0.1 && geometry.vertical_fov_rad < 3.0) {
    intrinsics_ = CameraIntrinsics::FromFieldOfView(
        depth_->width, depth_->height, geometry.horizontal_fov_rad, geometry.vertical_fov_rad);
  } else {
    intrinsics_ = CameraIntrinsics::Carmine109().Scaled(depth_->width, depth_->height);
  }
  file_ = std::move(file);
  next_ = 0;
  color_cursor_ = 0;
  delivered_ = 0;
  skipped_ = 0;
}

void OniFileSource::Stop() { file_.reset(); }

bool OniFileSource::DecodesDepthCodec() const {
  return depth_ && (depth_->codec == kOniCodecNone || depth_->codec == kOniCodec16z ||
                    depth_->codec == kOniCodec16zT);
}

SourceRead OniFileSource::Next(std::chrono::milliseconds) {
  IHS_CHECK(file_ != nullptr, "OniFileSource::Next called before Start");
  std::string_view payload;
  OniFrameRecord at;
  while (next_ < depth_->frames.size()) {
    const OniFrameRecord& record = depth_->frames[next_++];
    auto frame = std::make_shared<Frame>();
    frame->width = depth_->width;
    frame->height = depth_->height;
    if (!file_->Payload(record, payload, at) ||
        !DecodeOniDepth(payload, *depth_, at, frame->depth_mm)) {
      ++skipped_;
      spdlog::warn("{}: skipping depth frame {}: its data cannot be decoded", path_.string(),
                   record.frame_number);
      continue;
    }
    frame->depth_timestamp_us = static_cast<std::int64_t>(record.timestamp_us);
    if (color_ && !color_->frames.empty()) {
      // Colour frames are in time order: advance while the next one is at least as close.
      const auto& colors = color_->frames;
      auto offset = [&](std::size_t k) {
        return std::llabs(static_cast<std::int64_t>(colors[k].timestamp_us) -
                          frame->depth_timestamp_us);
      };
      while (color_cursor_ + 1 < colors.size() &&
             offset(color_cursor_ + 1) <= offset(color_cursor_)) {
        ++color_cursor_;
      }
      if (offset(color_cursor_) <= max_color_offset_us_ &&
          file_->Payload(colors[color_cursor_], payload, at) &&
          DecodeOniColor(payload, *color_, at, frame->rgb)) {
        frame->color_timestamp_us = static_cast<std::int64_t>(colors[color_cursor_].timestamp_us);
      } else {
        frame->rgb.clear();
      }
    }
    frame->index = delivered_++;
    return {SourceStatus::kFrame, std::move(frame), ""};
  }
  return {SourceStatus::kEndOfStream, nullptr, "end of " + path_.string()};
}

std::optional<std::int64_t> OniFileSource::FrameCount() const {
  if (!depth_) return std::nullopt;
  return static_cast<std::int64_t>(depth_->frames.size());
}

}  // namespace ihs::sensor
