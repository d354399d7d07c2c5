// numpy's default argsort reproduced, ties included: every case of
// tests/data/golden/numpy_argsort (numpy 1.24.2's own output, made by make_golden.py there)
// — many ties, signed zeros, NaN, and adversarial arrays that reach numpy's heapsort.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>

#include "nsg/core/files.h"
#include "nsg/metrics/numpy_order.h"
#include "test_support.h"

namespace nsg::metrics {
namespace {

using nlohmann::json;

TEST(NumpyOrder, EveryGoldenCaseInNumpysOrder) {
  const json doc = json::parse(read_file(test::source_dir() / "tests/data/golden/numpy_argsort/cases.json"));
  int unstable_cases = 0;
  for (const json& c : doc.at("cases")) {
    SCOPED_TRACE(c.at("name").get<std::string>());
    std::vector<double> values;
    for (const json& v : c.at("values"))
      values.push_back(v.is_null() ? std::numeric_limits<double>::quiet_NaN() : v.get<double>());
    const std::vector<size_t> want = c.at("numpy_argsort").get<std::vector<size_t>>();
    EXPECT_EQ(numpy_argsort(values), want);
    unstable_cases += c.at("differs_from_stable").get<bool>() ? 1 : 0;
  }
  // The cases exercise ties where numpy's order is not a stable sort's.
  EXPECT_GE(unstable_cases, 50);
}

TEST(NumpyOrder, UpToSixteenEqualValuesKeepTheirOrderAndSeventeenDoNot) {
  // Insertion sort alone below 17 values: stable. 17 equal values are partitioned once.
  for (size_t n = 0; n <= 16; ++n) {
    std::vector<size_t> identity(n);
    for (size_t i = 0; i < n; ++i) identity[i] = i;
    EXPECT_EQ(numpy_argsort_descending(std::vector<double>(n, 0.9)), identity);
  }
  // np.argsort(-np.full(17, 0.9)) in numpy 1.24.2.
  const std::vector<size_t> want = {0, 14, 13, 12, 11, 10, 9, 15, 8, 6, 5, 4, 3, 2, 1, 7, 16};
  EXPECT_EQ(numpy_argsort_descending(std::vector<double>(17, 0.9)), want);
}

TEST(NumpyOrder, DescendingIsTheArgsortOfTheNegatedValues) {
  const std::vector<double> v = {0.3, 0.9, 0.1, 0.9, 0.5};
  const std::vector<size_t> want = {1, 3, 4, 0, 2};
  EXPECT_EQ(numpy_argsort_descending(v), want);
}

}  // namespace
}  // namespace nsg::metrics
