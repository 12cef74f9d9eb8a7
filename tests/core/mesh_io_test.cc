#include "core/mesh_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "tests/mesh_fixtures.h"
#include "tests/test_util.h"

namespace ihs {
namespace {

// A sphere with random normals' perturbations and random colours, so every attribute is
// exercised with values that are not round numbers.
TriangleMesh ColouredSphere() {
  TriangleMesh mesh = test::MakeUvSphere(35.123f, 12, 24, {1.5f, -2.25f, 600.125f});
  std::mt19937 rng = test::Rng(7);
  std::uniform_int_distribution<int> byte(0, 255);
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    mesh.colors.push_back({static_cast<std::uint8_t>(byte(rng)),
                           static_cast<std::uint8_t>(byte(rng)),
                           static_cast<std::uint8_t>(byte(rng))});
  }
  return mesh;
}

void ExpectIdentical(const TriangleMesh& a, const TriangleMesh& b) {
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  ASSERT_EQ(a.faces.size(), b.faces.size());
  ASSERT_EQ(a.normals.size(), b.normals.size());
  ASSERT_EQ(a.colors.size(), b.colors.size());
  for (size_t i = 0; i < a.vertices.size(); ++i) ASSERT_EQ(a.vertices[i], b.vertices[i]) << i;
  for (size_t i = 0; i < a.normals.size(); ++i) ASSERT_EQ(a.normals[i], b.normals[i]) << i;
  for (size_t i = 0; i < a.colors.size(); ++i) ASSERT_EQ(a.colors[i], b.colors[i]) << i;
  for (size_t i = 0; i < a.faces.size(); ++i) ASSERT_EQ(a.faces[i], b.faces[i]) << i;
}

class MeshIoRoundTripTest : public testing::TestWithParam<MeshFormat> {};

TEST_P(MeshIoRoundTripTest, ReadsBackExactlyWhatWasWritten) {
  test::TempDir dir;
  const TriangleMesh mesh = ColouredSphere();
  const auto path = dir / ("mesh" + MeshFormatExtension(GetParam()));
  WriteMesh(path, mesh, GetParam());
  ExpectIdentical(ReadMesh(path), mesh);
}

INSTANTIATE_TEST_SUITE_P(Formats, MeshIoRoundTripTest,
                         testing::Values(MeshFormat::kPlyBinary, MeshFormat::kPlyAscii,
                                         MeshFormat::kObj));

TEST(MeshIoTest, StlKeepsEveryTriangleExactlyAndRejoinsSharedCorners) {
  test::TempDir dir;
  const TriangleMesh mesh = ColouredSphere();
  WriteMesh(dir / "mesh.stl", mesh);
  const TriangleMesh read = ReadMesh(dir / "mesh.stl");
  EXPECT_FALSE(read.HasColors());
  EXPECT_EQ(read.vertices.size(), mesh.vertices.size());
  ASSERT_EQ(read.faces.size(), mesh.faces.size());
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(read.vertices[read.faces[f][c]], mesh.vertices[mesh.faces[f][c]]);
    }
  }
  EXPECT_TRUE(read.IsWatertight());
  EXPECT_NEAR(read.Volume(), mesh.Volume(), 1e-6 * mesh.Volume());
  // 84-byte header + 50 bytes per triangle.
  EXPECT_EQ(std::filesystem::file_size(dir / "mesh.stl"), 84 + 50 * mesh.faces.size());
}

TEST(MeshIoTest, RandomFloatsSurviveAsciiFormatsBitForBit) {
  std::mt19937 rng = test::Rng(11);
  std::uniform_real_distribution<float> exponent(-20, 20);
  std::uniform_real_distribution<float> mantissa(-1, 1);
  TriangleMesh mesh;
  for (int i = 0; i < 300; ++i) {
    mesh.vertices.emplace_back(mantissa(rng) * std::exp2(exponent(rng)),
                               mantissa(rng) * std::exp2(exponent(rng)), mantissa(rng));
    mesh.normals.emplace_back(mantissa(rng), mantissa(rng), mantissa(rng));
  }
  for (int i = 0; i + 2 < 300; i += 3) mesh.faces.push_back({i, i + 1, i + 2});
  for (MeshFormat format : {MeshFormat::kPlyAscii, MeshFormat::kObj}) {
    ExpectIdentical(DecodeMesh(EncodeMesh(mesh, format), format, "random"), mesh);
  }
}

TEST(MeshIoTest, ReadsPlyFromOtherWriters) {
  // Big-endian doubles, a quad, an extra element and a face list named vertex_index.
  std::string big =
      "ply\r\nformat binary_big_endian 1.0\r\ncomment other tool\r\n"
      "element vertex 4\r\nproperty double x\r\nproperty double y\r\n"
      "property double z\r\nproperty float confidence\r\n"
      "element face 1\r\nproperty list uchar uint vertex_index\r\n"
      "element edge 1\r\nproperty int vertex1\r\nproperty int vertex2\r\nend_header\r\n";
  auto append_be = [&](const void* data, size_t size) {
    const char* bytes = static_cast<const char*>(data);
    for (size_t i = 0; i < size; ++i) big.push_back(bytes[size - 1 - i]);
  };
  const double xyz[4][3] = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0.5}};
  for (const auto& v : xyz) {
    for (double c : v) append_be(&c, 8);
    const float confidence = 0.5f;
    append_be(&confidence, 4);
  }
  big.push_back(4);
  for (std::uint32_t index : {0u, 1u, 2u, 3u}) append_be(&index, 4);
  for (std::int32_t index : {0, 1}) append_be(&index, 4);
  const TriangleMesh mesh = DecodeMesh(big, MeshFormat::kPlyBinary, "big.ply");
  ASSERT_EQ(mesh.vertices.size(), 4u);
  EXPECT_EQ(mesh.vertices[3], Eigen::Vector3f(0, 10, 0.5f));
  ASSERT_EQ(mesh.faces.size(), 2u);  // The quad as a fan of two triangles.
  EXPECT_EQ(mesh.faces[1], (TriangleMesh::Face{0, 2, 3}));
  EXPECT_NEAR(mesh.SurfaceArea(), 100.0, 0.2);
}

TEST(MeshIoTest, ReadsObjWithTextureIndicesNegativeIndicesAndPolygons) {
  const std::string obj =
      "# other tool\nmtllib x.mtl\no thing\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
      "vt 0 0\nvn 0 0 1\ng side\nusemtl red\nf 1/1/1 2/1/1 3/1/1 4/1/1\nf -4 -2 -1\n";
  const TriangleMesh mesh = DecodeMesh(obj, MeshFormat::kObj, "x.obj");
  EXPECT_EQ(mesh.vertices.size(), 4u);
  ASSERT_EQ(mesh.faces.size(), 3u);
  EXPECT_EQ(mesh.faces[2], (TriangleMesh::Face{0, 2, 3}));
  EXPECT_FALSE(mesh.HasNormals());  // One normal shared by four vertices is not per-vertex.
  EXPECT_FALSE(mesh.HasColors());
}

TEST(MeshIoTest, ReadsAsciiStl) {
  const std::string stl =
      "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n"
      "   vertex 0 1 0\n  endloop\n endfacet\n facet normal 0 0 1\n  outer loop\n"
      "   vertex 1 0 0\n   vertex 1 1 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid x\n";
  const TriangleMesh mesh = DecodeMesh(stl, MeshFormat::kStl, "x.stl");
  EXPECT_EQ(mesh.vertices.size(), 4u);
  EXPECT_EQ(mesh.faces.size(), 2u);
  EXPECT_NEAR(mesh.SurfaceArea(), 1.0, 1e-9);
}

// Every malformed input must give an InputError naming the file, never a crash or a hang.
void ExpectInputError(const std::string& bytes, MeshFormat format, const std::string& needle) {
  try {
    DecodeMesh(bytes, format, "bad-file");
    ADD_FAILURE() << "no error for input expecting '" << needle << "'";
  } catch (const InputError& error) {
    const std::string text = error.what();
    EXPECT_EQ(text.rfind("bad-file: ", 0), 0u) << text;
    EXPECT_NE(text.find(needle), std::string::npos) << "'" << needle << "' not in: " << text;
  }
}

TEST(MeshIoTest, TruncatedBinaryPlyIsAnErrorAtEveryCutPoint) {
  const std::string bytes = EncodeMesh(ColouredSphere(), MeshFormat::kPlyBinary);
  const size_t header_end = bytes.find("end_header\n") + 11;
  int errors = 0, cuts = 0;
  for (size_t cut = 0; cut < bytes.size(); cut += 37) {
    ++cuts;
    try {
      DecodeMesh(bytes.substr(0, cut), MeshFormat::kPlyBinary, "cut.ply");
    } catch (const InputError&) {
      ++errors;
    }
  }
  EXPECT_EQ(errors, cuts);
  ExpectInputError(bytes.substr(0, header_end + 100), MeshFormat::kPlyBinary, "truncated");
  ExpectInputError(bytes.substr(0, bytes.size() - 1), MeshFormat::kPlyBinary, "truncated");
}

TEST(MeshIoTest, MalformedPlyGivesAClearError) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  ExpectInputError("", MeshFormat::kPlyAscii, "not a PLY file");
  ExpectInputError("solid x\n", MeshFormat::kPlyAscii, "not a PLY file");
  ExpectInputError("ply\nformat ascii 1.0\nelement vertex 3\n", MeshFormat::kPlyAscii,
                   "no end_header");
  ExpectInputError("ply\nformat ebcdic 1.0\nend_header\n", MeshFormat::kPlyAscii, "unknown format");
  ExpectInputError("ply\nformat ascii 1.0\nelement vertex -3\nend_header\n", MeshFormat::kPlyAscii,
                   "malformed element");
  ExpectInputError("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n",
                   MeshFormat::kPlyAscii, "lacks x, y or z");
  ExpectInputError(head + "0 0 0\n1 0 0\n", MeshFormat::kPlyAscii, "truncated");
  ExpectInputError(head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", MeshFormat::kPlyAscii,
                   "refers to vertex 3");
  ExpectInputError(head + "0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", MeshFormat::kPlyAscii, "non-finite");
  ExpectInputError(head + "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n", MeshFormat::kPlyAscii,
                   "'zero' is not a number");
  ExpectInputError(head + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n", MeshFormat::kPlyAscii,
                   "at least 3 needed");
  // A header that promises a billion vertices must not allocate them.
  ExpectInputError(
      "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\n"
      "property float x\nproperty float y\nproperty float z\nend_header\n",
      MeshFormat::kPlyBinary, "more than the file holds");
  // Found by tools/fuzz.sh (mesh_reader_fuzzer): entries without properties occupy no bytes, so
  // no size bounds them; 2e9 of them were counted through one by one for minutes.
  ExpectInputError("ply\nformat ascii 1.0\nelement vertex 2049172401\nend_header\n",
                   MeshFormat::kPlyAscii, "no properties");
  const TriangleMesh skipped =
      DecodeMesh("ply\nformat ascii 1.0\nelement junk 2049172401\n" +
                     head.substr(head.find("element vertex")) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                 MeshFormat::kPlyAscii, "junk.ply");
  EXPECT_EQ(skipped.faces.size(), 1u);
}

TEST(MeshIoTest, MalformedObjAndStlGiveAClearError) {
  ExpectInputError("", MeshFormat::kObj, "no vertices");
  ExpectInputError("v 0 0\n", MeshFormat::kObj, "OBJ line 1");
  ExpectInputError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", MeshFormat::kObj, "out of range");
  ExpectInputError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", MeshFormat::kObj, "bad index");
  ExpectInputError("v 0 0 0\nv 1 inf 0\nv 0 1 0\nf 1 2 3\n", MeshFormat::kObj, "non-finite");
  ExpectInputError("", MeshFormat::kStl, "not an STL");
  const std::string stl = EncodeMesh(test::MakeCube(5), MeshFormat::kStl);
  ExpectInputError(stl.substr(0, stl.size() - 10), MeshFormat::kStl, "truncated");
}

TEST(MeshIoTest, FileErrorsNameThePath) {
  test::TempDir dir;
  EXPECT_THROW(ReadMesh(dir / "missing.ply"), InputError);
  EXPECT_THROW(ReadMesh(dir / "mesh.xyz"), std::invalid_argument);
  EXPECT_THROW(WriteMesh(dir / "no-folder" / "mesh.ply", test::MakeCube(1)), OutputError);
  TriangleMesh broken = test::MakeCube(1);
  broken.faces[0][0] = 42;
  EXPECT_THROW(WriteMesh(dir / "broken.ply", broken), InputError);
  EXPECT_FALSE(std::filesystem::exists(dir / "broken.ply"));
}

// A real client must read our files: assimp (Debian assimp-utils) reports the counts we wrote.
TEST(MeshIoTest, AssimpReadsOurFilesWithTheRightCounts) {
  if (std::system("command -v assimp >/dev/null 2>&1") != 0) {
    GTEST_SKIP() << "assimp (Debian assimp-utils) is not installed";
  }
  test::TempDir dir;
  const TriangleMesh mesh = ColouredSphere();
  for (const char* name : {"mesh.ply", "mesh_ascii.ply", "mesh.obj", "mesh.stl"}) {
    const auto path = dir / name;
    WriteMesh(
        path, mesh,
        std::string(name) == "mesh_ascii.ply" ? MeshFormat::kPlyAscii : MeshFormatFromPath(path));
    const std::string command = "assimp info '" + path.string() + "' 2>&1";
    FILE* pipe = popen(command.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::string output;
    char buffer[4096];
    while (size_t n = fread(buffer, 1, sizeof(buffer), pipe)) output.append(buffer, n);
    ASSERT_EQ(pclose(pipe), 0) << output;
    auto number_after = [&](const std::string& label) {
      const size_t at = output.find(label);
      return at == std::string::npos ? -1L : std::stol(output.substr(at + label.size()));
    };
    EXPECT_EQ(number_after("Faces:"), static_cast<long>(mesh.faces.size())) << name;
    if (std::string(name) != "mesh.stl") {
      EXPECT_EQ(number_after("Vertices:"), static_cast<long>(mesh.vertices.size())) << name;
    }
    // STL has no shared vertices (assimp re-joins them by position and normal), so compare
    // the geometry through the bounds assimp reports instead.
    const auto [lo, hi] = mesh.Bounds();
    float min_point[3], max_point[3];
    ASSERT_EQ(std::sscanf(output.c_str() + output.find("Minimum point"), "Minimum point (%f %f %f)",
                          &min_point[0], &min_point[1], &min_point[2]),
              3)
        << output;
    ASSERT_EQ(std::sscanf(output.c_str() + output.find("Maximum point"), "Maximum point (%f %f %f)",
                          &max_point[0], &max_point[1], &max_point[2]),
              3);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(min_point[k], lo[k], 1e-3) << name;
      EXPECT_NEAR(max_point[k], hi[k], 1e-3) << name;
    }
  }
}

}  // namespace
}  // namespace ihs
