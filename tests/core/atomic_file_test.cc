#include "core/atomic_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>

#include "core/errors.h"
#include "tests/test_util.h"

namespace ihs {
namespace {

size_t FilesIn(const std::filesystem::path& folder) {
  size_t count = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(folder)) ++count;
  return count;
}

TEST(AtomicFileTest, WritesAndReplacesWholeFiles) {
  test::TempDir dir;
  WriteFileAtomically(dir / "a.txt", std::string("first"));
  EXPECT_EQ(ReadFileToString(dir / "a.txt"), "first");
  WriteFileAtomically(dir / "a.txt", std::string("second, longer"));
  EXPECT_EQ(ReadFileToString(dir / "a.txt"), "second, longer");
  EXPECT_EQ(FilesIn(dir.path()), 1u);  // No temporary file left behind.
}

TEST(AtomicFileTest, AFailingWriterLeavesTheOldFileAndNoTemporary) {
  test::TempDir dir;
  WriteFileAtomically(dir / "mesh.ply", std::string("old"));
  EXPECT_THROW(WriteFileAtomically(dir / "mesh.ply",
                                   [](std::ostream& out) {
                                     out << "partial";
                                     throw std::runtime_error("disk full");
                                   }),
               std::runtime_error);
  EXPECT_EQ(ReadFileToString(dir / "mesh.ply"), "old");
  EXPECT_EQ(FilesIn(dir.path()), 1u);
}

TEST(AtomicFileTest, MissingFolderIsAnOutputError) {
  test::TempDir dir;
  EXPECT_THROW(WriteFileAtomically(dir / "no" / "such" / "file", std::string("x")), OutputError);
}

TEST(AtomicFileTest, ReadingAMissingOrNonRegularFileIsAnInputError) {
  test::TempDir dir;
  EXPECT_THROW(ReadFileToString(dir / "missing"), InputError);
  EXPECT_THROW(ReadFileToString(dir.path()), InputError);
  WriteFileAtomically(dir / "empty", std::string());
  EXPECT_EQ(ReadFileToString(dir / "empty"), "");
}

}  // namespace
}  // namespace ihs
