// LocatedJson: positions of values and errors in JSON text, so lens-file errors say file:line:col.
#include <catch2/catch.hpp>

#include "lensmith/core/located_json.h"

using lensmith::JsonObjectReader;
using lensmith::FileError;
using lensmith::LocatedJson;

TEST_CASE("located JSON: a value's position is the line and column where it starts", "[core]") {
  const std::string text = "{\n  \"a\": 1,\n  \"b\": [true, \"x\\\"y\", 2.5e3],\n  \"c\": {\"d\": null}\n}\n";
  auto doc = LocatedJson::parse(text, "t.json");
  CHECK(doc.where("/a").to_string() == "t.json:2:8");
  CHECK(doc.where("/b").to_string() == "t.json:3:8");
  CHECK(doc.where("/b/0").to_string() == "t.json:3:9");
  CHECK(doc.where("/b/1").to_string() == "t.json:3:15");
  CHECK(doc.where("/b/2").to_string() == "t.json:3:23");
  CHECK(doc.where("/c/d").to_string() == "t.json:4:14");
  CHECK(doc.root()["b"][1] == "x\"y");
}

TEST_CASE("located JSON: a syntax error names its line", "[core]") {
  const std::string text = "{\n  \"a\": 1,\n  \"b\": tru\n}\n";
  try {
    LocatedJson::parse(text, "bad.json");
    FAIL("expected an error");
  } catch (const FileError& e) {
    CHECK(e.where().file == "bad.json");
    CHECK(e.where().line == 3);
  }
}

TEST_CASE("located JSON: duplicate keys are errors", "[core]") {
  CHECK_THROWS_WITH(LocatedJson::parse("{\"a\": 1, \"a\": 2}", "d.json"), Catch::Contains("duplicate key \"a\""));
}

TEST_CASE("located JSON: nesting beyond the limit is an error, not a stack overflow", "[core]") {
  std::string deep(10000, '[');
  CHECK_THROWS_WITH(LocatedJson::parse(deep, "deep.json"), Catch::Contains("nesting deeper"));
}

TEST_CASE("strict object reader: an unknown key is an error listing the allowed keys", "[core]") {
  auto doc = LocatedJson::parse("{\n \"name\": \"x\",\n \"nmae\": 2\n}", "k.json");
  JsonObjectReader r(doc, "", "");
  CHECK(r.get_string("name") == "x");
  CHECK_THROWS_WITH(r.finish({"name"}), Catch::Contains("k.json:3:10: nmae: unknown key; allowed keys here: name"));
}

TEST_CASE("strict object reader: a wrong type names the key, the expected type and the position", "[core]") {
  auto doc = LocatedJson::parse("{\"surfaces\": {\"t\": \"5\"}}", "w.json");
  JsonObjectReader r(doc, "/surfaces", "surfaces");
  CHECK_THROWS_WITH(r.get_number("t"), Catch::Contains("w.json:1:20: surfaces.t: expected a number, got a string"));
}
