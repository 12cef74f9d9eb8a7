#include "sensor/depth_codec.h"

#include <algorithm>
#include <stdexcept>

namespace ihs::sensor {
namespace {

// Appends the 16z difference stream for samples[1..count) (the first sample is stored by the
// caller). Differences d = prev − cur in [−6, 6] go in nibbles (code d + 6), two per byte; pairs
// of "no change" become run bytes 0xE1..0xEF; larger differences escape with 0xF (or 0xFF) and
// then one byte (|d| ≤ 63) or a 15-bit big-endian absolute value.
void AppendDifferences(const std::uint16_t* samples, std::size_t count, std::string& out) {
  int pending = -1;
  int zero_pairs = 0;
  auto flush_zero_pairs = [&] {
    if (zero_pairs) out.push_back(static_cast<char>(0xE0 + zero_pairs));
    zero_pairs = 0;
  };
  std::uint16_t prev = samples[0];
  for (std::size_t i = 1; i < count; ++i) {
    const std::uint16_t cur = samples[i];
    const int d = static_cast<std::int16_t>(static_cast<std::uint16_t>(prev - cur));
    if (d >= -6 && d <= 6) {
      const int code = d + 6;
      if (pending < 0) {
        pending = code;
      } else {
        const int byte = pending * 16 + code;
        pending = -1;
        if (byte == 0x66) {
          if (++zero_pairs == 15) flush_zero_pairs();
        } else {
          flush_zero_pairs();
          out.push_back(static_cast<char>(byte));
        }
      }
    } else {
      flush_zero_pairs();
      out.push_back(static_cast<char>(pending < 0 ? 0xFF : pending * 16 + 0xF));
      pending = -1;
      if (d >= -63 && d <= 63) {
        out.push_back(static_cast<char>(d + 192));
      } else {
        if (cur >= 0x8000)
          throw std::invalid_argument("16z cannot store a jump to a value >= 32768");
        out.push_back(static_cast<char>(cur >> 8));
        out.push_back(static_cast<char>(cur & 0xFF));
      }
    }
    prev = cur;
  }
  // The zero run came before the pending nibble, so it goes first (OpenNI's own encoder swaps
  // these, which its decoder then reads wrongly when the pending difference is not zero).
  flush_zero_pairs();
  if (pending >= 0) out.push_back(static_cast<char>(pending * 16 + 0xD));
}

void AppendU16(std::string& out, std::uint16_t value) {
  out.push_back(static_cast<char>(value & 0xFF));
  out.push_back(static_cast<char>(value >> 8));
}

// Decodes a difference stream starting from `first`; appends to `out` (which holds `first`).
bool DecodeDifferences(const std::uint8_t* data, std::size_t size, std::size_t max_samples,
                       std::vector<std::uint16_t>& out) {
  std::uint16_t last = out.back();
  std::size_t i = 0;
  auto emit = [&](std::uint16_t value) {
    if (out.size() >= max_samples) return false;
    out.push_back(value);
    last = value;
    return true;
  };
  auto escape = [&]() {
    if (i >= size) return false;
    const std::uint8_t e = data[i++];
    if (e & 0x80) return emit(static_cast<std::uint16_t>(last - (e - 192)));
    if (i >= size) return false;
    return emit(static_cast<std::uint16_t>((e << 8) | data[i++]));
  };
  while (i < size) {
    const std::uint8_t b = data[i++];
    if (b < 0xE0) {
      const int high = b >> 4, low = b & 0xF;
      if (high > 12 || !emit(static_cast<std::uint16_t>(last - (high - 6)))) return false;
      if (low == 0xF) {
        if (!escape()) return false;
      } else if (low != 0xD) {
        if (low > 12 || !emit(static_cast<std::uint16_t>(last - (low - 6)))) return false;
      }
    } else if (b == 0xFF) {
      if (!escape()) return false;
    } else {
      const int repeats = 2 * (b - 0xE0);
      if (out.size() + repeats > max_samples) return false;
      out.insert(out.end(), repeats, last);
    }
  }
  return true;
}

}  // namespace

std::string Encode16z(const std::uint16_t* samples, std::size_t count) {
  std::string out;
  if (count == 0) return out;
  out.reserve(count);
  AppendU16(out, samples[0]);
  AppendDifferences(samples, count, out);
  return out;
}

std::string Encode16zTable(const std::uint16_t* samples, std::size_t count) {
  std::vector<std::uint16_t> table(samples, samples + count);
  std::sort(table.begin(), table.end());
  table.erase(std::unique(table.begin(), table.end()), table.end());
  if (table.size() >= 0x8000) {
    throw std::invalid_argument("16zT cannot store a frame with " + std::to_string(table.size()) +
                                " distinct values (at most 32767)");
  }
  std::vector<std::uint16_t> index_of(65536, 0);
  for (std::size_t k = 0; k < table.size(); ++k) index_of[table[k]] = static_cast<std::uint16_t>(k);
  std::vector<std::uint16_t> indices(count);
  for (std::size_t i = 0; i < count; ++i) indices[i] = index_of[samples[i]];
  std::string out;
  out.reserve(count + 2 * table.size() + 4);
  AppendU16(out, static_cast<std::uint16_t>(table.size()));
  for (std::uint16_t value : table) AppendU16(out, value);
  if (count == 0) return out;
  AppendU16(out, indices[0]);
  AppendDifferences(indices.data(), count, out);
  return out;
}

bool Decode16z(const std::uint8_t* data, std::size_t size, std::size_t max_samples,
               std::vector<std::uint16_t>& out) {
  out.clear();
  if (size == 0) return true;
  if (size < 2 || max_samples == 0) return false;
  out.reserve(max_samples);
  out.push_back(static_cast<std::uint16_t>(data[0] | (data[1] << 8)));
  return DecodeDifferences(data + 2, size - 2, max_samples, out);
}

bool Decode16zTable(const std::uint8_t* data, std::size_t size, std::size_t max_samples,
                    std::vector<std::uint16_t>& out) {
  out.clear();
  if (size < 2) return false;
  const std::size_t entries = data[0] | (data[1] << 8);
  if (size < 2 + 2 * entries) return false;
  const std::uint8_t* table = data + 2;
  const std::size_t rest = size - 2 - 2 * entries;
  if (!Decode16z(table + 2 * entries, rest, max_samples, out)) return false;
  for (std::uint16_t& index : out) {
    if (index >= entries) return false;
    index = static_cast<std::uint16_t>(table[2 * index] | (table[2 * index + 1] << 8));
  }
  return true;
}

}  // namespace ihs::sensor
