// StageTimes: the per-stage wall clock behind `lensmith bokeh --timings`.
#include <catch2/catch.hpp>

#include <chrono>
#include <string>
#include <thread>

#include "lensmith/core/stage_times.h"

using lensmith::StageTimes;

namespace {

// A sleep of this long is at least this long on any scheduler (sleep_for never returns early).
constexpr auto kNap = std::chrono::milliseconds(2);
constexpr double kNapMs = 2.0;

}  // namespace

TEST_CASE("StageTimes keeps the stages in the order they first ran and adds up a stage lapped again", "[core][stage_times]") {
  StageTimes t;
  t.restart();
  t.lap("reading");
  t.add("layers", 1.5);
  t.add("deposit", 2.0);
  t.add("layers", 0.25);  // a second layer: the same stage
  REQUIRE(t.stages().size() == 3);
  CHECK(std::string(t.stages()[0].name) == "reading");
  CHECK(std::string(t.stages()[1].name) == "layers");
  CHECK(t.stages()[1].ms == 1.75);
  CHECK(std::string(t.stages()[2].name) == "deposit");
  // A name is matched by its text, not its address: a stage named by two equal literals is one stage.
  const std::string again = "deposit";
  t.add(again.c_str(), 1.0);
  CHECK(t.stages().size() == 3);
  CHECK(t.stages()[2].ms == 3.0);
}

TEST_CASE("A StageTimes lap charges the wall time since the last lap, none of what came before a restart", "[core][stage_times]") {
  StageTimes t;
  std::this_thread::sleep_for(kNap);
  t.restart();  // the nap before is nobody's
  t.lap("nothing");
  std::this_thread::sleep_for(kNap);
  t.lap("nap");
  REQUIRE(t.stages().size() == 2);
  // Against the steady clock's own reading of the same nap: at least its length; the lap without
  // work is shorter than a nap (a descheduled thread could make it longer, so no tighter bound).
  CHECK(t.stages()[1].ms >= kNapMs);
  CHECK(t.stages()[0].ms < t.stages()[1].ms);
  CHECK(t.total_ms() == t.stages()[0].ms + t.stages()[1].ms);
  CHECK(t.to_string().find("nap ") != std::string::npos);
  CHECK(t.to_string().find(", total ") != std::string::npos);
}
