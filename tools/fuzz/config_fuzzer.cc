// libFuzzer target for the config parser (app/option_registry.h): arbitrary text as a config
// file over fields of every option type. The only failures it may report are
// std::invalid_argument (a bad line) — nothing else, no crash, no unbounded memory.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "app/option_registry.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  double weight = 15;
  int iterations = 4;
  std::uint32_t seed = 1;
  bool color = true;
  std::string name = "procedural";
  Eigen::Vector3d corner(-100, -140, 400);
  ihs::app::OptionRegistry registry;
  registry.Add("fusion.pairwise.contact_weight", &weight, "a double");
  registry.Add("tracker.fit.outer_iterations", &iterations, "an int");
  registry.Add("fusion.pairwise.seed", &seed, "an unsigned");
  registry.Add("fusion.tsdf.color", &color, "a bool");
  registry.Add("scan.hand_template", &name, "a string");
  registry.Add("tracker.segmentation.crop_min_mm", &corner, "a vector");
  try {
    registry.LoadText(std::string(reinterpret_cast<const char*>(data), size), "fuzz.conf");
    registry.Describe();
  } catch (const std::invalid_argument&) {
    // A bad line: the one failure the parser may report.
  }
  return 0;
}
