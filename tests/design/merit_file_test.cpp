// The merit file (docs/optimize.md): what it says becomes variables and operands, and what is wrong with it
// is reported with file:line:column and what was expected.
#include <catch2/catch.hpp>

#include "lensmith/core/errors.h"
#include "lensmith/design/merit_function.h"

using namespace lensmith;

TEST_CASE("A merit file's variables and operands are read as written", "[design][merit-file]") {
  const MeritFunction m = parse_merit_function(R"({
    "comment": "a triplet",
    "field_angle_deg": 20,
    "variables": [
      {"surface": 1, "parameter": "curvature"},
      {"surface": 2, "parameter": "thickness", "min": 0.5, "max": 12},
      {"surface": 3, "parameter": "a6"},
      {"surface": 3, "parameter": "glass"}
    ],
    "operands": [
      {"type": "efl", "target": 50, "weight": 100},
      {"type": "spot_rms", "fields": [0, 1], "wavelengths_nm": [486.1, 656.3], "rings": 3, "reference": "chief",
       "field_weights": [1, 2], "wavelength_weights": [1, 0.5]},
      {"type": "edge_thickness", "surface": 1, "min": 1, "height_mm": 9},
      {"type": "seidel", "term": "S4", "max": 0.01},
      {"type": "distortion", "field": 1, "min": -1, "max": 1}
    ]
  })", "m.json");
  CHECK(m.field_angle_deg == 20.0);
  REQUIRE(m.variables.size() == 5);  // "glass" is nd and Vd
  CHECK(m.variables[1].kind == DesignVariable::Kind::Thickness);
  CHECK(m.variables[1].min == 0.5);
  CHECK(m.variables[1].max == 12.0);
  CHECK(m.variables[2].kind == DesignVariable::Kind::Asphere);
  CHECK(m.variables[2].asphere_power == 6);
  CHECK(m.variables[3].kind == DesignVariable::Kind::GlassIndex);
  CHECK(m.variables[4].kind == DesignVariable::Kind::GlassAbbe);
  CHECK(m.variables[3].min.has_value());  // the glass map's extent by default
  REQUIRE(m.operands.size() == 5);
  CHECK(m.operands[0].target == 50.0);
  CHECK(m.operands[0].weight == 100.0);
  CHECK(m.operands[1].relative_fields == std::vector<double>{0.0, 1.0});
  CHECK(m.operands[1].wavelengths_nm == std::vector<double>{486.1, 656.3});
  CHECK(m.operands[1].rings == 3);
  CHECK(m.operands[1].field_weights == std::vector<double>{1.0, 2.0});
  CHECK(m.operands[1].wavelength_weights == std::vector<double>{1.0, 0.5});
  CHECK_FALSE(m.operands[1].centroid_reference);
  CHECK(m.operands[2].height_mm == 9.0);
  CHECK(m.operands[3].term == "S4");
  CHECK(m.operands[3].max == 0.01);
  CHECK(m.operands[4].relative_fields == std::vector<double>{1.0});
}

TEST_CASE("A wrong merit file is refused at the line and column of the mistake", "[design][merit-file]") {
  const auto message = [](const std::string& text) {
    try {
      parse_merit_function(text, "m.json");
    } catch (const FileError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  CHECK_THAT(message("{\"variables\": [{\"surface\": 1, \"parameter\": \"radius\"}], \"operands\": [{\"type\": \"efl\", \"target\": 1}]}"),
             Catch::Contains("m.json:1:") && Catch::Contains("variables[0].parameter") && Catch::Contains("expected curvature"));
  CHECK_THAT(message("{\"variables\": [{\"surface\": 1, \"parameter\": \"curvature\"}],\n \"operands\": [{\"type\": \"efl\"}]}"),
             Catch::Contains("m.json:2:") && Catch::Contains("target or a limit"));
  CHECK_THAT(message("{\"variables\": [{\"surface\": 1, \"parameter\": \"curvature\"}],\n \"operands\": [{\"type\": \"spot_rms\", \"target\": 0}]}"),
             Catch::Contains("operands[0]") && Catch::Contains("target"));
  CHECK_THAT(message("{\"variables\": [{\"surface\": 0.5, \"parameter\": \"curvature\"}], \"operands\": [{\"type\": \"efl\", \"target\": 1}]}"),
             Catch::Contains("variables[0].surface") && Catch::Contains("whole number"));
  CHECK_THAT(message("{\"variables\": [{\"surface\": 1, \"parameter\": \"a5\"}], \"operands\": [{\"type\": \"efl\", \"target\": 1}]}"),
             Catch::Contains("a4, a6"));
  CHECK_THAT(message("{\"variables\": [], \"operands\": [{\"type\": \"efl\", \"target\": 1}]}"), Catch::Contains("at least one variable"));
  CHECK_THAT(message("{\"variables\": [{\"surface\": 1, \"parameter\": \"curvature\"}], \"operands\": [{\"type\": \"mtf\", \"target\": 1}]}"),
             Catch::Contains("expected one of efl"));
  CHECK_THAT(message("{\"variables\": [{\"surface\": 1, \"parameter\": \"curvature\"}], \"operands\": [{\"type\": \"efl\", \"target\": 1, \"surface\": 2}]}"),
             Catch::Contains("surface"));
  CHECK_THAT(message("{\"variables\": [{\"surface\": 1, \"parameter\": \"curvature\"}], \"operands\": [{\"type\": \"efl\", \"target\": 1, \"weight\": 0}]}"),
             Catch::Contains("weight > 0"));
  CHECK_THAT(message("[1, 2]"), Catch::Contains("m.json:1:1"));
  CHECK_THAT(message("{\"variables\": "), Catch::Contains("m.json:1:"));
}
