#pragma once
// Reading and writing triangle meshes: PLY (binary little-endian and ASCII; big-endian read),
// OBJ, and STL (binary written; binary and ASCII read). Writes are atomic (temporary file, then
// rename). Malformed input throws ihs::InputError naming the file and the problem; an unwritable
// output throws ihs::OutputError.

#include <filesystem>
#include <string>

#include "core/triangle_mesh.h"

namespace ihs {

/// File formats for meshes.
enum class MeshFormat {
  kPlyBinary,  ///< PLY, binary little-endian: vertices, normals, colours, faces.
  kPlyAscii,   ///< PLY, ASCII: the same content, human-readable.
  kObj,        ///< Wavefront OBJ: vertices (with colour as the common `v x y z r g b`), normals.
  kStl,        ///< Binary STL: triangles only (no colour, per-face normals).
};

/// The format for a file name's extension: .ply → binary PLY, .obj, .stl (case-insensitive).
/// Throws std::invalid_argument for any other extension.
MeshFormat MeshFormatFromPath(const std::filesystem::path& path);

/// The usual extension of a format, with the dot (".ply", ".obj", ".stl").
std::string MeshFormatExtension(MeshFormat format);

/// Writes `mesh` to `path` in `format`, atomically. Throws ihs::InputError if the mesh fails
/// TriangleMesh::Check, ihs::OutputError if the file cannot be written.
void WriteMesh(const std::filesystem::path& path, const TriangleMesh& mesh, MeshFormat format);

/// Writes `mesh` in the format its extension names (see MeshFormatFromPath).
void WriteMesh(const std::filesystem::path& path, const TriangleMesh& mesh);

/// Reads a PLY, OBJ or STL file, chosen by extension. Polygons are split into triangles.
/// The result passes TriangleMesh::Check.
TriangleMesh ReadMesh(const std::filesystem::path& path);

/// Serialises `mesh` into the bytes of a file of `format` (what WriteMesh writes).
std::string EncodeMesh(const TriangleMesh& mesh, MeshFormat format);

/// Parses the bytes of a PLY, OBJ or STL file (`format` kPlyBinary and kPlyAscii both accept any
/// PLY). `name` is used in error messages.
TriangleMesh DecodeMesh(const std::string& bytes, MeshFormat format, const std::string& name);

}  // namespace ihs
