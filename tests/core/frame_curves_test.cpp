// Keyframed per-frame curves of a shot (frame_curves.h).
#include <catch2/catch.hpp>

#include "lensmith/core/errors.h"
#include "lensmith/core/frame_curves.h"

using lensmith::FrameCurves;

namespace {
const std::vector<std::string> kNames{"focus_m", "fstop"};
// A value between keys is one linear interpolation a + t (b - a) in double: a few ulps (2.2e-16) of values ~1.
constexpr double kLerpRounding = 1e-15;
}

TEST_CASE("a curve is linear between its keys and held before the first and after the last", "[core][curves]") {
  const FrameCurves c = FrameCurves::parse_json(R"({"focus_m": [[1010, 4.0], [1000, 2.0]], "fstop": [[1000, 2.8]]})", "c.json", kNames);
  CHECK(c.value("focus_m", 990) == 2.0);
  CHECK(c.value("focus_m", 1000) == 2.0);
  CHECK(*c.value("focus_m", 1005) == Approx(3.0).epsilon(kLerpRounding));
  CHECK(c.value("focus_m", 1010) == 4.0);
  CHECK(c.value("focus_m", 2000) == 4.0);
  CHECK(c.value("fstop", 1234) == 2.8);
  CHECK_FALSE(c.value("zoom", 1000).has_value());
}

TEST_CASE("CSV curves: a header, one row per key, empty cells without a key, comments", "[core][curves]") {
  const FrameCurves c = FrameCurves::parse_csv("# pull\r\nframe, focus_m, fstop\n1001,1.5,\n1011,2.5,4\n", "c.csv", kNames);
  CHECK(*c.value("focus_m", 1006) == Approx(2.0).epsilon(kLerpRounding));
  CHECK(c.value("fstop", 1001) == 4.0);  // its only key, held
}

TEST_CASE("malformed curve files name the file, the line and what was expected", "[core][curves]") {
  using Catch::Matchers::Contains;
  CHECK_THROWS_WITH(FrameCurves::parse_json("{\n  \"focus\": [[1, 2]]\n}", "c.json", kNames), Contains("c.json:2:") && Contains("focus_m, fstop"));
  CHECK_THROWS_WITH(FrameCurves::parse_json(R"({"focus_m": [[1.5, 2]]})", "c.json", kNames), Contains("not a whole number"));
  CHECK_THROWS_WITH(FrameCurves::parse_json(R"({"focus_m": [[1, 2], [1, 3]]})", "c.json", kNames), Contains("keys frame 1 twice"));
  CHECK_THROWS_WITH(FrameCurves::parse_json(R"({"focus_m": []})", "c.json", kNames), Contains("no keys"));
  CHECK_THROWS_WITH(FrameCurves::parse_json(R"({"focus_m": [[1, "a"]]})", "c.json", kNames), Contains("[frame, value]"));
  CHECK_THROWS_WITH(FrameCurves::parse_csv("frame,focus_m\n1,x\n", "c.csv", kNames), Contains("c.csv:2") && Contains("not a finite number"));
  CHECK_THROWS_WITH(FrameCurves::parse_csv("frame,focus_m\n1,2,3\n", "c.csv", kNames), Contains("c.csv:2") && Contains("3 cells"));
  CHECK_THROWS_WITH(FrameCurves::parse_csv("focus_m\n1\n", "c.csv", kNames), Contains("c.csv:1") && Contains("header"));
  CHECK_THROWS_WITH(FrameCurves::parse_csv("frame,focus_m,focus_m\n", "c.csv", kNames), Contains("twice"));
  CHECK_THROWS_AS(FrameCurves::parse_csv("", "c.csv", kNames), lensmith::FileError);
}
