// libFuzzer target for the mesh readers (core/mesh_io.h): arbitrary bytes parsed as PLY, OBJ
// and STL (the first byte picks which), and a parsed mesh checked and measured. The only failure
// they may report is ihs::InputError.

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/errors.h"
#include "core/mesh_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const ihs::MeshFormat formats[] = {ihs::MeshFormat::kPlyBinary, ihs::MeshFormat::kObj,
                                     ihs::MeshFormat::kStl};
  const ihs::MeshFormat format = formats[data[0] % 3];
  try {
    const ihs::TriangleMesh mesh = ihs::DecodeMesh(
        std::string(reinterpret_cast<const char*>(data + 1), size - 1), format, "fuzz");
    mesh.Check();
    if (mesh.IsWatertight()) mesh.Volume();
  } catch (const ihs::InputError&) {
    // The one failure the readers may report.
  }
  return 0;
}
