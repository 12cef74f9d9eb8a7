// The shared main of every test binary: seeds the random generators and runs GoogleTest.

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

#include "tests/test_util.h"

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  std::srand(ihs::test::Seed());
  std::printf("random seed: %u (set IHS_TEST_SEED to change)\n", ihs::test::Seed());
  return RUN_ALL_TESTS();
}
