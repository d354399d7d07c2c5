// The table writer's Python json.dump imitation (values checked against CPython 3.11).
#include <gtest/gtest.h>

#include "py_json.h"

namespace nsg::synth {
namespace {

TEST(WorldPyJson, FloatsAreWrittenLikePythonRepr) {
  EXPECT_EQ(python_float_repr(1.0), "1.0");
  EXPECT_EQ(python_float_repr(-2.5), "-2.5");
  EXPECT_EQ(python_float_repr(0.1), "0.1");
  EXPECT_EQ(python_float_repr(1e-4), "0.0001");
  EXPECT_EQ(python_float_repr(1e-5), "1e-05");
  EXPECT_EQ(python_float_repr(1.5e-7), "1.5e-07");
  EXPECT_EQ(python_float_repr(1e15), "1000000000000000.0");
  EXPECT_EQ(python_float_repr(1e16), "1e+16");
  EXPECT_EQ(python_float_repr(2.0 / 3.0), "0.6666666666666666");
  EXPECT_EQ(python_float_repr(1266.417203046554), "1266.417203046554");
  EXPECT_EQ(python_float_repr(0.0), "0.0");
}

TEST(WorldPyJson, Indent0AndCompactStyles) {
  const PyJson rec = PyJson::array(
      {PyJson{{"token", "a"}, {"n", 3}, {"v", PyJson::array({1.0, 0.5})}, {"e", PyJson::array()}, {"b", true}}});
  EXPECT_EQ(py_json_dump(rec, PyJsonStyle::kIndent0),
            "[\n{\n\"token\": \"a\",\n\"n\": 3,\n\"v\": [\n1.0,\n0.5\n],\n\"e\": [],\n\"b\": true\n}\n]");
  EXPECT_EQ(py_json_dump(rec, PyJsonStyle::kCompact),
            "[{\"token\": \"a\", \"n\": 3, \"v\": [1.0, 0.5], \"e\": [], \"b\": true}]");
}

}  // namespace
}  // namespace nsg::synth
