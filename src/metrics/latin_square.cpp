#include "vrdeform/metrics/latin_square.h"

#include <algorithm>

#include "vrdeform/error.h"

namespace vrd {

std::size_t latinSquareRows(std::size_t conditions) { return conditions % 2 == 0 ? conditions : 2 * conditions; }

std::vector<std::size_t> latinSquareOrder(std::size_t conditions, std::size_t participant) {
  if (conditions == 0) throw Error("latin square: a study needs at least one condition");
  const std::size_t n = conditions, row = participant % latinSquareRows(n);
  // Williams' first row 0, 1, n-1, 2, n-2, ...; row r adds r to each (mod n); for odd n the
  // second n rows are the first n reversed.
  std::vector<std::size_t> order(n);
  for (std::size_t j = 0, low = 1, high = n - 1; j < n; ++j) {
    const std::size_t first = j == 0 ? 0 : j % 2 == 1 ? low++ : high--;
    order[j] = (first + row) % n;
  }
  if (row >= n) std::reverse(order.begin(), order.end());
  return order;
}

}  // namespace vrd
