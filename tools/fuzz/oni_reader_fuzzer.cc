// libFuzzer target for the .oni reader: indexes arbitrary bytes and decodes every frame found.
// Built and run by tools/fuzz.sh (clang, -DIHS_FUZZ=ON, in build-fuzz):
// tools/fuzz.sh 60 oni_reader_fuzzer, or build-fuzz/tools/fuzz/oni_reader_fuzzer CORPUS.

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "core/errors.h"
#include "sensor/oni_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    const ihs::sensor::OniIndex index = ihs::sensor::IndexOni(bytes, "fuzz");
    std::vector<std::uint16_t> depth;
    std::vector<std::uint8_t> rgb;
    for (const ihs::sensor::OniNode& node : index.nodes) {
      for (const ihs::sensor::OniFrameRecord& record : node.frames) {
        if (node.type == static_cast<std::int32_t>(ihs::sensor::OniNodeType::kDepth)) {
          ihs::sensor::DecodeOniDepth(bytes, node, record, depth);
        } else {
          ihs::sensor::DecodeOniColor(bytes, node, record, rgb);
        }
      }
    }
  } catch (const ihs::InputError&) {
    // The one failure the reader may report.
  }
  return 0;
}
