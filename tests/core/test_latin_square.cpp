// Balanced Latin squares (Williams' design) by their defining properties, for 1 to 8 conditions:
// each participant's order is a permutation; over one complete square every condition takes
// every position equally often and directly follows every other condition equally often.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <utility>

#include "test_support.h"
#include "vrdeform/metrics/latin_square.h"

namespace vrd {
namespace {

TEST(LatinSquare, BalancedOverPositionsAndImmediateSuccessors) {
  for (std::size_t n = 1; n <= 8; ++n) {
    SCOPED_TRACE(n);
    const std::size_t rows = latinSquareRows(n);
    EXPECT_EQ(rows, n % 2 == 0 ? n : 2 * n);
    std::map<std::pair<std::size_t, std::size_t>, int> atPosition, follows;
    for (std::size_t k = 0; k < rows; ++k) {
      const std::vector<std::size_t> order = latinSquareOrder(n, k);
      std::vector<std::size_t> sorted = order;
      std::sort(sorted.begin(), sorted.end());
      std::vector<std::size_t> all(n);
      std::iota(all.begin(), all.end(), 0);
      ASSERT_EQ(sorted, all) << "participant " << k;
      for (std::size_t j = 0; j < n; ++j) ++atPosition[{order[j], j}];
      for (std::size_t j = 0; j + 1 < n; ++j) ++follows[{order[j], order[j + 1]}];
      EXPECT_EQ(latinSquareOrder(n, k + rows), order);  // the next set of participants repeats it
    }
    for (std::size_t c = 0; c < n; ++c) {
      for (std::size_t j = 0; j < n; ++j) EXPECT_EQ(atPosition[std::pair(c, j)], int(rows / n)) << c << " at " << j;
    }
    for (std::size_t a = 0; a < n; ++a)
      for (std::size_t b = 0; b < n; ++b) {
        if (a == b) continue;
        EXPECT_EQ(follows[std::pair(a, b)], int(rows / n)) << b << " after " << a;
      }
  }
  EXPECT_EQ(latinSquareOrder(2, 0), (std::vector<std::size_t>{0, 1}));  // A then B,
  EXPECT_EQ(latinSquareOrder(2, 1), (std::vector<std::size_t>{1, 0}));  // then B then A
  EXPECT_NE(testing::errorOf([] { latinSquareOrder(0, 0); }).find("at least one condition"), std::string::npos);
}

}  // namespace
}  // namespace vrd
