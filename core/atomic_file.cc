#include "core/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <system_error>

#include "core/errors.h"

namespace ihs {
namespace fs = std::filesystem;

void WriteFileAtomically(const fs::path& path, const std::function<void(std::ostream&)>& write) {
  static std::atomic<unsigned> counter{0};
  const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) {
    throw OutputError("cannot write " + path.string() + ": folder " + folder.string() +
                      " does not exist");
  }
  std::ostringstream temporary_name;
  temporary_name << "." << path.filename().string() << ".tmp-" << ::getpid() << "-"
                 << counter.fetch_add(1);
  const fs::path temporary = folder / temporary_name.str();
  auto discard = [&] { fs::remove(temporary, ec); };
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) {
      throw OutputError("cannot write " + path.string() + ": " + std::strerror(errno));
    }
    try {
      write(out);
    } catch (...) {
      out.close();
      discard();
      throw;
    }
    out.flush();
    out.close();
    if (out.fail()) {
      discard();
      throw OutputError("cannot write " + path.string() + ": writing failed (disk full?)");
    }
  }
  fs::rename(temporary, path, ec);
  if (ec) {
    discard();
    throw OutputError("cannot write " + path.string() + ": " + ec.message());
  }
}

void WriteFileAtomically(const fs::path& path, const std::string& contents) {
  WriteFileAtomically(path,
                      [&](std::ostream& out) { out.write(contents.data(), contents.size()); });
}

std::string ReadFileToString(const fs::path& path, std::uintmax_t max_bytes) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path.string() + ": no such file");
  if (!fs::is_regular_file(path, ec)) throw InputError(path.string() + ": not a regular file");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (!ec && size > max_bytes) {
    throw InputError(path.string() + ": " + std::to_string(size) + " bytes, more than the " +
                     std::to_string(max_bytes) + " such a file may have");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open: " + std::strerror(errno));
  // Read in pieces up to one byte past the bound: a file that grew since does not grow the
  // memory past it.
  std::string contents;
  char piece[1 << 16];
  while (in && contents.size() <= max_bytes) {
    in.read(piece, sizeof piece);
    contents.append(piece, static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) throw InputError(path.string() + ": read error");
  if (contents.size() > max_bytes) {
    throw InputError(path.string() + ": more than the " + std::to_string(max_bytes) +
                     " bytes such a file may have");
  }
  return contents;
}

}  // namespace ihs
