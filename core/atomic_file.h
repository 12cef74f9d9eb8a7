#pragma once
// Atomic file writing: readers see either the old file or the complete new one, never a part.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>

namespace ihs {

/// Writes `path` atomically: `write` fills a binary stream for a temporary file in the same folder,
/// which then replaces `path` by rename. Throws ihs::OutputError (naming the path) when the folder
/// is missing or unwritable or the data cannot be written completely (e.g. a full disk); the
/// temporary file is removed and an existing `path` is left untouched. Exceptions thrown by
/// `write` propagate after the same clean-up.
void WriteFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& write);

/// Convenience: writes `contents` to `path` atomically.
void WriteFileAtomically(const std::filesystem::path& path, const std::string& contents);

/// Reads a whole file into a string. Throws ihs::InputError naming the path when it is missing,
/// not a regular file (a folder, a FIFO, a device such as /dev/zero: never read, so never a
/// hang), larger than `max_bytes`, or unreadable.
inline constexpr std::uintmax_t kDefaultMaxReadBytes = 256ull << 20;
std::string ReadFileToString(const std::filesystem::path& path,
                             std::uintmax_t max_bytes = kDefaultMaxReadBytes);

}  // namespace ihs
