#include "core/data_lines.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "tests/test_util.h"

namespace ihs {
namespace {

TEST(DataLinesTest, SkipsBlankAndCommentLinesAndKeepsNumbers) {
  test::TempDir dir;
  test::WriteBytes(dir / "list.txt", "# header\r\n\r\n1.0 a\r\n   # indented comment\n  \t\n2.0 b");
  const std::vector<DataLine> lines = ReadDataLines(dir / "list.txt");
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].number, 3);
  EXPECT_EQ(lines[0].text, "1.0 a");  // CRLF stripped.
  EXPECT_EQ(lines[1].number, 6);
  EXPECT_EQ(lines[1].text, "2.0 b");  // Last line without a line end.
  EXPECT_THROW(ReadDataLines(dir / "missing.txt"), InputError);
}

}  // namespace
}  // namespace ihs
