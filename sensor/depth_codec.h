#pragma once
// OpenNI's lossless depth codecs as stored in .oni files: "16zP" (delta + run-length coding of
// 16-bit samples) and "16zT" (the same over indices into a table of the values a frame holds).
// Written from the format description in docs/oni-format.md.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace ihs::sensor {

/// Encodes samples with 16zP. Values must be < 32768 where the difference to the previous sample
/// exceeds 63 (absolute escapes carry 15 bits); throws std::invalid_argument otherwise.
std::string Encode16z(const std::uint16_t* samples, std::size_t count);

/// Encodes samples with 16zT (table of distinct values, then 16z over indices). Throws
/// std::invalid_argument when a frame holds 32768 or more distinct values.
std::string Encode16zTable(const std::uint16_t* samples, std::size_t count);

/// Decodes a 16zP payload into `out` (replaced). Returns false — leaving `out` unspecified — when
/// the payload is malformed or would produce more than `max_samples` samples. Never reads past
/// `size` bytes.
bool Decode16z(const std::uint8_t* data, std::size_t size, std::size_t max_samples,
               std::vector<std::uint16_t>& out);

/// Decodes a 16zT payload; same contract as Decode16z.
bool Decode16zTable(const std::uint8_t* data, std::size_t size, std::size_t max_samples,
                    std::vector<std::uint16_t>& out);

}  // namespace ihs::sensor
