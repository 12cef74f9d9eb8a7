#include "sensor/depth_codec.h"

#include <gtest/gtest.h>

#include <random>

#include "tests/frame_fixtures.h"
#include "tests/test_util.h"

namespace ihs::sensor {
namespace {

std::vector<std::uint16_t> Decode(const std::string& bytes, bool table, std::size_t max) {
  std::vector<std::uint16_t> out;
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
  const bool ok = table ? Decode16zTable(data, bytes.size(), max, out)
                        : Decode16z(data, bytes.size(), max, out);
  EXPECT_TRUE(ok);
  return out;
}

TEST(DepthCodecTest, KnownBytesFromTheFormatDescription) {
  // 5,5,5,7: first value, a run of one "no change" pair, then −2 as a padded half-byte.
  const std::vector<std::uint16_t> samples = {5, 5, 5, 7};
  const std::string bytes = Encode16z(samples.data(), samples.size());
  EXPECT_EQ(bytes, std::string("\x05\x00\xE1\x4D", 4));
  EXPECT_EQ(Decode(bytes, false, 10), samples);
  // OpenNI's own encoder swaps the last two bytes; its decoder (and ours) then read 5,7,7,7.
  EXPECT_EQ(Decode(std::string("\x05\x00\x4D\xE1", 4), false, 10),
            (std::vector<std::uint16_t>{5, 7, 7, 7}));
}

TEST(DepthCodecTest, RoundTripsDepthImagesAndRandomSequences) {
  std::mt19937 rng = test::Rng(3);
  std::vector<std::vector<std::uint16_t>> cases = {test::MakePatternFrame(2).depth_mm, {0}, {}};
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<std::uint16_t> samples(1 + rng() % 3000);
    std::uint16_t value = rng() % 32768;
    for (auto& sample : samples) {
      switch (rng() % 5) {
        case 0:
          value = rng() % 32768;
          break;  // absolute jump
        case 1:
          value = static_cast<std::uint16_t>(value + rng() % 127 - 63) & 0x7FFF;
          break;
        case 2:
          value = static_cast<std::uint16_t>(value + rng() % 13 - 6) & 0x7FFF;
          break;
        default:
          break;  // runs
      }
      sample = value;
    }
    cases.push_back(samples);
  }
  for (const auto& samples : cases) {
    EXPECT_EQ(Decode(Encode16z(samples.data(), samples.size()), false, samples.size()), samples);
    EXPECT_EQ(Decode(Encode16zTable(samples.data(), samples.size()), true, samples.size()),
              samples);
  }
}

TEST(DepthCodecTest, TableCodecStoresAnyValueAndCompressesDepth) {
  const std::vector<std::uint16_t> high = {65535, 65535, 40000, 0, 12};
  EXPECT_EQ(Decode(Encode16zTable(high.data(), high.size()), true, 5), high);
  const auto depth = test::MakePatternFrame(0).depth_mm;
  const std::string bytes = Encode16zTable(depth.data(), depth.size());
  EXPECT_LT(bytes.size(), depth.size() * 2 / 2);  // At least 2x smaller than raw.
  std::vector<std::uint16_t> many(40000);
  for (std::size_t i = 0; i < many.size(); ++i) many[i] = static_cast<std::uint16_t>(i);
  EXPECT_THROW(Encode16zTable(many.data(), many.size()), std::invalid_argument);
}

TEST(DepthCodecTest, DecoderRejectsOverflowAndGarbageWithoutOverrun) {
  const std::vector<std::uint16_t> samples(1000, 7);
  const std::string bytes = Encode16z(samples.data(), samples.size());
  std::vector<std::uint16_t> out;
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
  EXPECT_FALSE(Decode16z(data, bytes.size(), 999, out));  // More samples than allowed.
  std::mt19937 rng = test::Rng(4);
  int accepted = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<std::uint8_t> garbage(rng() % 64);
    for (auto& b : garbage) b = static_cast<std::uint8_t>(rng());
    if (Decode16zTable(garbage.data(), garbage.size(), 4096, out)) {
      ++accepted;
      EXPECT_LE(out.size(), 4096u);
    }
    Decode16z(garbage.data(), garbage.size(), 4096, out);
    EXPECT_LE(out.size(), 4096u);
  }
  EXPECT_LT(accepted, 2000);
}

}  // namespace
}  // namespace ihs::sensor
