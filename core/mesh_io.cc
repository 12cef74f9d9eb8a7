#include "core/mesh_io.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "core/atomic_file.h"
#include "core/errors.h"

namespace ihs {
namespace {

static_assert(std::endian::native == std::endian::little ||
              std::endian::native == std::endian::big);

[[noreturn]] void Fail(const std::string& name, const std::string& message) {
  throw InputError(name + ": " + message);
}

std::string Lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

// ---- Byte and text encoding ----------------------------------------------------------------

template <typename T>
void AppendLittleEndian(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(bytes, bytes + sizeof(T));
  out.append(bytes, sizeof(T));
}

template <typename T>
T LoadLittleEndian(const char* bytes) {
  char raw[sizeof(T)];
  std::memcpy(raw, bytes, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(raw, raw + sizeof(T));
  T value;
  std::memcpy(&value, raw, sizeof(T));
  return value;
}

// Shortest decimal text that reads back to exactly the same value.
template <typename T>
void AppendNumber(std::string& out, T value) {
  char text[64];
  const auto result = std::to_chars(text, text + sizeof(text), value);
  out.append(text, result.ptr);
}

// Splits a line into whitespace-separated tokens.
std::vector<std::string_view> Tokens(std::string_view line) {
  std::vector<std::string_view> tokens;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

std::optional<double> ParseDouble(std::string_view token) {
  double value = 0;
  const char* begin = token.data();
  if (!token.empty() && token.front() == '+') ++begin;
  const auto result = std::from_chars(begin, token.data() + token.size(), value);
  if (result.ec != std::errc() || result.ptr != token.data() + token.size()) return std::nullopt;
  return value;
}

std::optional<long long> ParseInteger(std::string_view token) {
  long long value = 0;
  const auto result = std::from_chars(token.data(), token.data() + token.size(), value);
  if (result.ec != std::errc() || result.ptr != token.data() + token.size()) return std::nullopt;
  return value;
}

// Iterates over the lines of a text, without their line ends (LF or CRLF).
class LineReader {
 public:
  LineReader(std::string_view text, size_t offset = 0) : text_(text), position_(offset) {}
  bool Next(std::string_view& line) {
    if (position_ >= text_.size()) return false;
    size_t end = text_.find('\n', position_);
    if (end == std::string_view::npos) end = text_.size();
    line = text_.substr(position_, end - position_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    position_ = end + 1;
    ++number_;
    return true;
  }
  size_t position() const { return std::min(position_, text_.size()); }
  int number() const { return number_; }

 private:
  std::string_view text_;
  size_t position_;
  int number_ = 0;
};

std::uint8_t ColorByte(double value, bool unit_range) {
  const double scaled = unit_range ? value * 255.0 : value;
  if (!std::isfinite(scaled)) return 0;
  return static_cast<std::uint8_t>(std::lround(std::clamp(scaled, 0.0, 255.0)));
}

// ---- PLY -----------------------------------------------------------------------------------

enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::optional<PlyType> ParsePlyType(std::string_view name) {
  if (name == "char" || name == "int8") return PlyType::kInt8;
  if (name == "uchar" || name == "uint8") return PlyType::kUint8;
  if (name == "short" || name == "int16") return PlyType::kInt16;
  if (name == "ushort" || name == "uint16") return PlyType::kUint16;
  if (name == "int" || name == "int32") return PlyType::kInt32;
  if (name == "uint" || name == "uint32") return PlyType::kUint32;
  if (name == "float" || name == "float32") return PlyType::kFloat32;
  if (name == "double" || name == "float64") return PlyType::kFloat64;
  return std::nullopt;
}

size_t PlyTypeSize(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

bool IsFloatType(PlyType type) { return type == PlyType::kFloat32 || type == PlyType::kFloat64; }

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
  // Fewest bytes one instance occupies in a binary file (lists counted as empty).
  size_t MinBinarySize() const {
    size_t size = 0;
    for (const PlyProperty& p : properties) size += PlyTypeSize(p.is_list ? p.count_type : p.type);
    return size;
  }
};

enum class PlyEncoding { kAscii, kBinaryLittle, kBinaryBig };

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::kAscii;
  std::vector<PlyElement> elements;
  size_t body_offset = 0;
};

PlyHeader ParsePlyHeader(const std::string& bytes, const std::string& name) {
  LineReader lines(bytes);
  std::string_view line;
  if (!lines.Next(line) || line != "ply") Fail(name, "not a PLY file (no 'ply' magic)");
  PlyHeader header;
  bool have_format = false;
  while (true) {
    if (!lines.Next(line)) Fail(name, "PLY header has no end_header");
    const std::vector<std::string_view> tokens = Tokens(line);
    if (tokens.empty()) continue;
    const std::string where = "PLY header line " + std::to_string(lines.number());
    if (tokens[0] == "end_header") break;
    if (tokens[0] == "comment" || tokens[0] == "obj_info") continue;
    if (tokens[0] == "format") {
      if (tokens.size() != 3) Fail(name, where + ": malformed format line");
      if (tokens[1] == "ascii") {
        header.encoding = PlyEncoding::kAscii;
      } else if (tokens[1] == "binary_little_endian") {
        header.encoding = PlyEncoding::kBinaryLittle;
      } else if (tokens[1] == "binary_big_endian") {
        header.encoding = PlyEncoding::kBinaryBig;
      } else {
        Fail(name, where + ": unknown format '" + std::string(tokens[1]) + "'");
      }
      have_format = true;
    } else if (tokens[0] == "element") {
      const auto count = tokens.size() == 3 ? ParseInteger(tokens[2]) : std::nullopt;
      if (!count || *count < 0) Fail(name, where + ": malformed element line");
      header.elements.push_back({std::string(tokens[1]), static_cast<std::uint64_t>(*count), {}});
    } else if (tokens[0] == "property") {
      if (header.elements.empty()) Fail(name, where + ": property before any element");
      PlyProperty property;
      if (tokens.size() == 5 && tokens[1] == "list") {
        const auto count_type = ParsePlyType(tokens[2]);
        const auto item_type = ParsePlyType(tokens[3]);
        if (!count_type || !item_type || IsFloatType(*count_type)) {
          Fail(name, where + ": bad list property types");
        }
        property = {std::string(tokens[4]), *item_type, true, *count_type};
      } else if (tokens.size() == 3) {
        const auto type = ParsePlyType(tokens[1]);
        if (!type) Fail(name, where + ": unknown property type '" + std::string(tokens[1]) + "'");
        property = {std::string(tokens[2]), *type, false, PlyType::kUint8};
      } else {
        Fail(name, where + ": malformed property line");
      }
      header.elements.back().properties.push_back(property);
    } else {
      Fail(name, where + ": unknown keyword '" + std::string(tokens[0]) + "'");
    }
  }
  if (!have_format) Fail(name, "PLY header has no format line");
  header.body_offset = lines.position();
  return header;
}

// Reads the values of a PLY body in order, binary or ASCII, with bounds checks.
class PlyBodyReader {
 public:
  PlyBodyReader(const std::string& bytes, size_t offset, PlyEncoding encoding,
                const std::string& name)
      : bytes_(bytes), position_(offset), encoding_(encoding), name_(name) {}

  double Read(PlyType type) {
    return encoding_ == PlyEncoding::kAscii ? ReadAscii() : ReadBinary(type);
  }

  // Sets what is being read, for error messages.
  void SetContext(const PlyElement* element, std::uint64_t index) {
    element_ = element;
    index_ = index;
  }

  size_t Remaining() const { return bytes_.size() - position_; }

  [[noreturn]] void Truncated() const {
    Fail(name_, "truncated PLY: the file ends in " + element_->name + " " + std::to_string(index_) +
                    " of " + std::to_string(element_->count));
  }

 private:
  double ReadBinary(PlyType type) {
    const size_t size = PlyTypeSize(type);
    if (bytes_.size() - position_ < size) Truncated();
    unsigned char raw[8];
    std::memcpy(raw, bytes_.data() + position_, size);
    position_ += size;
    const bool file_little = encoding_ == PlyEncoding::kBinaryLittle;
    if (file_little != (std::endian::native == std::endian::little)) std::reverse(raw, raw + size);
    switch (type) {
      case PlyType::kInt8:
        return static_cast<std::int8_t>(raw[0]);
      case PlyType::kUint8:
        return raw[0];
      case PlyType::kInt16:
        return Load<std::int16_t>(raw);
      case PlyType::kUint16:
        return Load<std::uint16_t>(raw);
      case PlyType::kInt32:
        return Load<std::int32_t>(raw);
      case PlyType::kUint32:
        return Load<std::uint32_t>(raw);
      case PlyType::kFloat32:
        return Load<float>(raw);
      case PlyType::kFloat64:
        return Load<double>(raw);
    }
    return 0;
  }

  template <typename T>
  static double Load(const unsigned char* raw) {
    T value;
    std::memcpy(&value, raw, sizeof(T));
    return static_cast<double>(value);
  }

  double ReadAscii() {
    while (position_ < bytes_.size() && std::isspace(static_cast<unsigned char>(bytes_[position_])))
      ++position_;
    const size_t start = position_;
    while (position_ < bytes_.size() &&
           !std::isspace(static_cast<unsigned char>(bytes_[position_])))
      ++position_;
    if (position_ == start) Truncated();
    const std::string_view token(bytes_.data() + start, position_ - start);
    const auto value = ParseDouble(token);
    if (!value) {
      Fail(name_, "PLY " + element_->name + " " + std::to_string(index_) + ": '" +
                      std::string(token) + "' is not a number");
    }
    return *value;
  }

  const std::string& bytes_;
  size_t position_;
  PlyEncoding encoding_;
  const std::string& name_;
  const PlyElement* element_ = nullptr;
  std::uint64_t index_ = 0;
};

std::uint64_t ReadListCount(PlyBodyReader& reader, const PlyProperty& property,
                            const std::string& name) {
  const double count = reader.Read(property.count_type);
  if (count < 0 || count != std::floor(count) || count > 1e6) {
    Fail(name, "PLY list '" + property.name + "' has an invalid length " + std::to_string(count));
  }
  return static_cast<std::uint64_t>(count);
}

void SkipProperty(PlyBodyReader& reader, const PlyProperty& property, const std::string& name) {
  if (!property.is_list) {
    reader.Read(property.type);
    return;
  }
  const std::uint64_t count = ReadListCount(reader, property, name);
  for (std::uint64_t i = 0; i < count; ++i) reader.Read(property.type);
}

TriangleMesh DecodePly(const std::string& bytes, const std::string& name) {
  const PlyHeader header = ParsePlyHeader(bytes, name);
  TriangleMesh mesh;
  PlyBodyReader reader(bytes, header.body_offset, header.encoding, name);
  bool have_vertices = false;

  for (const PlyElement& element : header.elements) {
    // A header that promises more than the file can hold is rejected before allocating.
    const bool binary = header.encoding != PlyEncoding::kAscii;
    const size_t min_size = binary ? element.MinBinarySize() : 2 * element.properties.size();
    if (min_size > 0 && element.count > reader.Remaining() / min_size) {
      Fail(name, "truncated PLY: the header declares " + std::to_string(element.count) + " " +
                     element.name + " elements, more than the file holds");
    }
    if (element.count > static_cast<std::uint64_t>(std::numeric_limits<std::int32_t>::max())) {
      Fail(name, "PLY element " + element.name + " has too many entries");
    }
    // Entries without properties occupy no bytes, so the size check above cannot bound them:
    // a vertex or face needs properties, any other such element is skipped without counting
    // through its entries (a 200-byte header declaring 2e9 of them took minutes).
    if (element.properties.empty()) {
      if (element.count > 0 && (element.name == "vertex" || element.name == "face"))
        Fail(name, "PLY element " + element.name + " has entries but no properties");
      if (element.name == "vertex") have_vertices = true;
      continue;
    }

    if (element.name == "vertex") {
      have_vertices = true;
      // Role of each property: 0-2 position, 3-5 normal, 6-8 colour, -1 ignored.
      std::vector<int> role(element.properties.size(), -1);
      static const char* kNames[9][2] = {{"x", nullptr},          {"y", nullptr},
                                         {"z", nullptr},          {"nx", nullptr},
                                         {"ny", nullptr},         {"nz", nullptr},
                                         {"red", "diffuse_red"},  {"green", "diffuse_green"},
                                         {"blue", "diffuse_blue"}};
      bool found[9] = {};
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        for (int r = 0; r < 9; ++r) {
          if (!property.is_list &&
              (property.name == kNames[r][0] || (kNames[r][1] && property.name == kNames[r][1]))) {
            role[p] = r;
            found[r] = true;
          }
        }
      }
      if (!found[0] || !found[1] || !found[2]) Fail(name, "PLY vertex element lacks x, y or z");
      const bool with_normals = found[3] && found[4] && found[5];
      const bool with_colors = found[6] && found[7] && found[8];
      mesh.vertices.resize(element.count);
      if (with_normals) mesh.normals.resize(element.count);
      if (with_colors) mesh.colors.resize(element.count);
      for (std::uint64_t i = 0; i < element.count; ++i) {
        reader.SetContext(&element, i);
        for (size_t p = 0; p < element.properties.size(); ++p) {
          const PlyProperty& property = element.properties[p];
          if (role[p] < 0) {
            SkipProperty(reader, property, name);
            continue;
          }
          const double value = reader.Read(property.type);
          if (role[p] < 3) {
            mesh.vertices[i][role[p]] = static_cast<float>(value);
          } else if (role[p] < 6) {
            if (with_normals) mesh.normals[i][role[p] - 3] = static_cast<float>(value);
          } else if (with_colors) {
            const double range = property.type == PlyType::kUint16 ? 65535.0 : 255.0;
            mesh.colors[i][role[p] - 6] = IsFloatType(property.type)
                                              ? ColorByte(value, true)
                                              : ColorByte(value * 255.0 / range, false);
          }
        }
      }
    } else if (element.name == "face") {
      int list_index = -1;
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        if (property.is_list &&
            (property.name == "vertex_indices" || property.name == "vertex_index")) {
          list_index = static_cast<int>(p);
        }
      }
      if (list_index < 0) Fail(name, "PLY face element has no vertex_indices list");
      mesh.faces.reserve(element.count);
      std::vector<std::int64_t> polygon;
      for (std::uint64_t i = 0; i < element.count; ++i) {
        reader.SetContext(&element, i);
        for (size_t p = 0; p < element.properties.size(); ++p) {
          const PlyProperty& property = element.properties[p];
          if (static_cast<int>(p) != list_index) {
            SkipProperty(reader, property, name);
            continue;
          }
          const std::uint64_t count = ReadListCount(reader, property, name);
          if (count < 3) {
            Fail(name, "PLY face " + std::to_string(i) + " has " + std::to_string(count) +
                           " vertices (at least 3 needed)");
          }
          polygon.clear();
          for (std::uint64_t k = 0; k < count; ++k) {
            const double index = reader.Read(property.type);
            if (index != std::floor(index) || index < 0 ||
                index > std::numeric_limits<std::int32_t>::max()) {
              Fail(name, "PLY face " + std::to_string(i) + " has an invalid index");
            }
            polygon.push_back(static_cast<std::int64_t>(index));
          }
          for (size_t k = 1; k + 1 < polygon.size(); ++k) {  // Fan triangulation.
            mesh.faces.push_back({static_cast<std::int32_t>(polygon[0]),
                                  static_cast<std::int32_t>(polygon[k]),
                                  static_cast<std::int32_t>(polygon[k + 1])});
          }
        }
      }
    } else {
      for (std::uint64_t i = 0; i < element.count; ++i) {
        reader.SetContext(&element, i);
        for (const PlyProperty& property : element.properties) SkipProperty(reader, property, name);
      }
    }
  }
  if (!have_vertices) Fail(name, "PLY file has no vertex element");
  return mesh;
}

std::string EncodePly(const TriangleMesh& mesh, bool binary) {
  std::string out;
  out += "ply\nformat ";
  out += binary ? "binary_little_endian 1.0\n" : "ascii 1.0\n";
  out += "comment written by inhandscan, units mm\n";
  out += "element vertex " + std::to_string(mesh.vertices.size()) + "\n";
  out += "property float x\nproperty float y\nproperty float z\n";
  if (mesh.HasNormals()) out += "property float nx\nproperty float ny\nproperty float nz\n";
  if (mesh.HasColors()) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  out += "element face " + std::to_string(mesh.faces.size()) + "\n";
  out += "property list uchar int vertex_indices\nend_header\n";

  if (binary) {
    const size_t vertex_bytes = 12 + (mesh.HasNormals() ? 12 : 0) + (mesh.HasColors() ? 3 : 0);
    out.reserve(out.size() + mesh.vertices.size() * vertex_bytes + mesh.faces.size() * 13);
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
      for (int k = 0; k < 3; ++k) AppendLittleEndian(out, mesh.vertices[i][k]);
      if (mesh.HasNormals()) {
        for (int k = 0; k < 3; ++k) AppendLittleEndian(out, mesh.normals[i][k]);
      }
      if (mesh.HasColors()) {
        for (int k = 0; k < 3; ++k) AppendLittleEndian(out, mesh.colors[i][k]);
      }
    }
    for (const TriangleMesh::Face& face : mesh.faces) {
      AppendLittleEndian(out, std::uint8_t{3});
      for (std::int32_t index : face) AppendLittleEndian(out, index);
    }
    return out;
  }
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      if (k) out += ' ';
      AppendNumber(out, mesh.vertices[i][k]);
    }
    if (mesh.HasNormals()) {
      for (int k = 0; k < 3; ++k) {
        out += ' ';
        AppendNumber(out, mesh.normals[i][k]);
      }
    }
    if (mesh.HasColors()) {
      for (int k = 0; k < 3; ++k) out += ' ' + std::to_string(mesh.colors[i][k]);
    }
    out += '\n';
  }
  for (const TriangleMesh::Face& face : mesh.faces) {
    out += "3 " + std::to_string(face[0]) + ' ' + std::to_string(face[1]) + ' ' +
           std::to_string(face[2]) + '\n';
  }
  return out;
}

// ---- OBJ -----------------------------------------------------------------------------------

std::string EncodeObj(const TriangleMesh& mesh) {
  std::string out = "# written by inhandscan, units mm\n";
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    out += 'v';
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      AppendNumber(out, mesh.vertices[i][k]);
    }
    if (mesh.HasColors()) {  // The widespread `v x y z r g b` extension, colours in [0, 1].
      for (int k = 0; k < 3; ++k) {
        out += ' ';
        AppendNumber(out, mesh.colors[i][k] / 255.0);
      }
    }
    out += '\n';
  }
  for (const Eigen::Vector3f& normal : mesh.normals) {
    out += "vn";
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      AppendNumber(out, normal[k]);
    }
    out += '\n';
  }
  for (const TriangleMesh::Face& face : mesh.faces) {
    out += 'f';
    for (std::int32_t index : face) {
      const std::string one_based = std::to_string(index + 1);
      out += ' ' + one_based;
      if (mesh.HasNormals()) out += "//" + one_based;
    }
    out += '\n';
  }
  return out;
}

TriangleMesh DecodeObj(const std::string& bytes, const std::string& name) {
  TriangleMesh mesh;
  std::vector<Eigen::Vector3f> normals;
  std::vector<TriangleMesh::Color> colors;
  size_t colored_vertices = 0;
  bool normals_follow_vertices = true;  // Every corner's normal index equals its vertex index.
  bool any_corner_normal = false;
  LineReader lines(bytes);
  std::string_view line;
  std::vector<std::int64_t> polygon;
  while (lines.Next(line)) {
    const std::vector<std::string_view> tokens = Tokens(line);
    if (tokens.empty() || tokens[0].front() == '#') continue;
    const std::string where = "OBJ line " + std::to_string(lines.number());
    auto number = [&](size_t i) {
      const auto value = ParseDouble(tokens[i]);
      if (!value) Fail(name, where + ": '" + std::string(tokens[i]) + "' is not a number");
      return *value;
    };
    if (tokens[0] == "v") {
      if (tokens.size() != 4 && tokens.size() != 5 && tokens.size() != 7) {
        Fail(name, where + ": a vertex needs 3 coordinates (optionally w or r g b)");
      }
      mesh.vertices.emplace_back(number(1), number(2), number(3));
      TriangleMesh::Color color = {0, 0, 0};
      if (tokens.size() == 7) {
        for (int k = 0; k < 3; ++k) color[k] = ColorByte(number(4 + k), true);
        ++colored_vertices;
      }
      colors.push_back(color);
    } else if (tokens[0] == "vn") {
      if (tokens.size() != 4) Fail(name, where + ": a normal needs 3 components");
      normals.emplace_back(number(1), number(2), number(3));
    } else if (tokens[0] == "f") {
      if (tokens.size() < 4) Fail(name, where + ": a face needs at least 3 vertices");
      polygon.clear();
      for (size_t i = 1; i < tokens.size(); ++i) {
        const std::string_view corner = tokens[i];
        const size_t slash = corner.find('/');
        auto resolve = [&](std::string_view text, size_t count) -> std::int64_t {
          const auto value = ParseInteger(text);
          if (!value || *value == 0) {
            Fail(name, where + ": bad index '" + std::string(corner) + "'");
          }
          // Negative indices count back from the latest element.
          const std::int64_t index =
              *value > 0 ? *value - 1 : static_cast<std::int64_t>(count) + *value;
          if (index < 0 || index >= static_cast<std::int64_t>(count)) {
            Fail(name, where + ": index '" + std::string(corner) + "' out of range");
          }
          return index;
        };
        const std::int64_t vertex = resolve(corner.substr(0, slash), mesh.vertices.size());
        polygon.push_back(vertex);
        const size_t second = slash == std::string_view::npos ? slash : corner.find('/', slash + 1);
        if (second != std::string_view::npos && second + 1 < corner.size()) {
          any_corner_normal = true;
          if (resolve(corner.substr(second + 1), normals.size()) != vertex) {
            normals_follow_vertices = false;
          }
        } else {
          normals_follow_vertices = false;
        }
      }
      for (size_t k = 1; k + 1 < polygon.size(); ++k) {
        mesh.faces.push_back({static_cast<std::int32_t>(polygon[0]),
                              static_cast<std::int32_t>(polygon[k]),
                              static_cast<std::int32_t>(polygon[k + 1])});
      }
    }
    // Other statements (vt, o, g, s, usemtl, mtllib, l, p) carry nothing a mesh keeps.
  }
  if (mesh.vertices.empty()) Fail(name, "OBJ file has no vertices");
  if (colored_vertices == mesh.vertices.size()) mesh.colors = std::move(colors);
  // Per-vertex normals survive only when they are indexed like the vertices.
  if (any_corner_normal && normals_follow_vertices && normals.size() == mesh.vertices.size()) {
    mesh.normals = std::move(normals);
  }
  return mesh;
}

// ---- STL -----------------------------------------------------------------------------------

std::string EncodeStl(const TriangleMesh& mesh) {
  std::string out(80, ' ');
  const std::string title = "binary STL written by inhandscan, units mm";
  out.replace(0, title.size(), title);
  AppendLittleEndian(out, static_cast<std::uint32_t>(mesh.faces.size()));
  out.reserve(out.size() + mesh.faces.size() * 50);
  for (const TriangleMesh::Face& face : mesh.faces) {
    const Eigen::Vector3f& a = mesh.vertices[face[0]];
    Eigen::Vector3f normal = (mesh.vertices[face[1]] - a).cross(mesh.vertices[face[2]] - a);
    if (normal.norm() > 0) normal.normalize();
    for (int k = 0; k < 3; ++k) AppendLittleEndian(out, normal[k]);
    for (std::int32_t index : face) {
      for (int k = 0; k < 3; ++k) AppendLittleEndian(out, mesh.vertices[index][k]);
    }
    AppendLittleEndian(out, std::uint16_t{0});
  }
  return out;
}

// STL repeats each corner; corners with bit-identical coordinates become one vertex again.
class VertexMerger {
 public:
  explicit VertexMerger(TriangleMesh& mesh) : mesh_(mesh) {}
  std::int32_t Add(const Eigen::Vector3f& point) {
    std::uint32_t bits[3];
    std::memcpy(bits, point.data(), sizeof(bits));
    const std::string key(reinterpret_cast<const char*>(bits), sizeof(bits));
    const auto [it, inserted] =
        index_.try_emplace(key, static_cast<std::int32_t>(mesh_.vertices.size()));
    if (inserted) mesh_.vertices.push_back(point);
    return it->second;
  }

 private:
  TriangleMesh& mesh_;
  std::unordered_map<std::string, std::int32_t> index_;
};

TriangleMesh DecodeStl(const std::string& bytes, const std::string& name) {
  TriangleMesh mesh;
  VertexMerger merger(mesh);
  if (bytes.size() >= 84) {
    const auto count = LoadLittleEndian<std::uint32_t>(bytes.data() + 80);
    if (84 + 50ull * count == bytes.size()) {
      mesh.faces.reserve(count);
      for (std::uint32_t f = 0; f < count; ++f) {
        const char* record = bytes.data() + 84 + 50ull * f + 12;  // Skips the stored normal.
        TriangleMesh::Face face;
        for (int c = 0; c < 3; ++c) {
          const char* corner = record + 12 * c;
          face[c] = merger.Add(Eigen::Vector3f(LoadLittleEndian<float>(corner),
                                               LoadLittleEndian<float>(corner + 4),
                                               LoadLittleEndian<float>(corner + 8)));
        }
        mesh.faces.push_back(face);
      }
      return mesh;
    }
  }
  const std::vector<std::string_view> head = Tokens(std::string_view(bytes).substr(0, 256));
  if (head.empty() || head[0] != "solid" || bytes.find("facet") == std::string::npos) {
    if (bytes.size() >= 84) {
      Fail(name, "not a valid STL: binary size does not match its triangle count (truncated?)");
    }
    Fail(name, "not an STL file");
  }
  LineReader lines(bytes);
  std::string_view line;
  std::vector<std::int32_t> corners;
  while (lines.Next(line)) {
    const std::vector<std::string_view> tokens = Tokens(line);
    if (tokens.empty() || tokens[0] != "vertex") continue;
    if (tokens.size() != 4)
      Fail(name, "STL line " + std::to_string(lines.number()) + ": bad vertex");
    float xyz[3];
    for (int k = 0; k < 3; ++k) {
      const auto value = ParseDouble(tokens[1 + k]);
      if (!value) Fail(name, "STL line " + std::to_string(lines.number()) + ": bad number");
      xyz[k] = static_cast<float>(*value);
    }
    corners.push_back(merger.Add(Eigen::Vector3f(xyz[0], xyz[1], xyz[2])));
  }
  if (corners.size() % 3 != 0) Fail(name, "ASCII STL has an incomplete facet");
  for (size_t i = 0; i < corners.size(); i += 3) {
    mesh.faces.push_back({corners[i], corners[i + 1], corners[i + 2]});
  }
  return mesh;
}

}  // namespace

MeshFormat MeshFormatFromPath(const std::filesystem::path& path) {
  const std::string extension = Lowercase(path.extension().string());
  if (extension == ".ply") return MeshFormat::kPlyBinary;
  if (extension == ".obj") return MeshFormat::kObj;
  if (extension == ".stl") return MeshFormat::kStl;
  throw std::invalid_argument(path.string() +
                              ": unknown mesh format (use a .ply, .obj or .stl file name)");
}

std::string MeshFormatExtension(MeshFormat format) {
  switch (format) {
    case MeshFormat::kPlyBinary:
    case MeshFormat::kPlyAscii:
      return ".ply";
    case MeshFormat::kObj:
      return ".obj";
    case MeshFormat::kStl:
      return ".stl";
  }
  return "";
}

std::string EncodeMesh(const TriangleMesh& mesh, MeshFormat format) {
  mesh.Check();
  switch (format) {
    case MeshFormat::kPlyBinary:
      return EncodePly(mesh, true);
    case MeshFormat::kPlyAscii:
      return EncodePly(mesh, false);
    case MeshFormat::kObj:
      return EncodeObj(mesh);
    case MeshFormat::kStl:
      return EncodeStl(mesh);
  }
  return "";
}

TriangleMesh DecodeMesh(const std::string& bytes, MeshFormat format, const std::string& name) {
  TriangleMesh mesh;
  switch (format) {
    case MeshFormat::kPlyBinary:
    case MeshFormat::kPlyAscii:
      mesh = DecodePly(bytes, name);
      break;
    case MeshFormat::kObj:
      mesh = DecodeObj(bytes, name);
      break;
    case MeshFormat::kStl:
      mesh = DecodeStl(bytes, name);
      break;
  }
  try {
    mesh.Check();
  } catch (const InputError& error) {
    Fail(name, error.what());
  }
  return mesh;
}

void WriteMesh(const std::filesystem::path& path, const TriangleMesh& mesh, MeshFormat format) {
  const std::string bytes = EncodeMesh(mesh, format);
  WriteFileAtomically(path, bytes);
}

void WriteMesh(const std::filesystem::path& path, const TriangleMesh& mesh) {
  WriteMesh(path, mesh, MeshFormatFromPath(path));
}

TriangleMesh ReadMesh(const std::filesystem::path& path) {
  const MeshFormat format = MeshFormatFromPath(path);
  return DecodeMesh(ReadFileToString(path), format, path.string());
}

}  // namespace ihs
