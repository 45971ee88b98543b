#include "terrain/example/ridge.h"

#include <gtest/gtest.h>

TEST(ExampleStage, TheRidgeStandsInTheMiddle) {
  const auto field = drift::example::ridge(9, 10.0);
  EXPECT_GT(field(4, 4), field(4, 0));
}
