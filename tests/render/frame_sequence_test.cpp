// Image-sequence patterns and frame lists (lensmith/imageio/frame_sequence.h).
#include <catch2/catch.hpp>

#include "lensmith/core/errors.h"
#include "lensmith/imageio/frame_sequence.h"

using lensmith::FramePattern;

TEST_CASE("sequence patterns as Nuke, OpenImageIO and printf write them", "[imageio][sequence]") {
  CHECK(FramePattern::find("shot.####.exr")->path(7) == "shot.0007.exr");
  CHECK(FramePattern::find("shot.####.exr")->path(1001) == "shot.1001.exr");
  CHECK(FramePattern::find("shot.#.exr")->path(7) == "shot.0007.exr");  // OpenImageIO: one '#' is four digits
  CHECK(FramePattern::find("shot.@@@.exr")->path(7) == "shot.007.exr");
  CHECK(FramePattern::find("shot.%04d.exr")->path(7) == "shot.0007.exr");
  CHECK(FramePattern::find("shot.%d.exr")->path(7) == "shot.7.exr");
  CHECK(FramePattern::find("shot.####.exr")->path(123456) == "shot.123456.exr");  // wider than the padding
  CHECK(FramePattern::find("shot.%04d.exr")->path(-5) == "shot.-005.exr");         // as printf pads it
  CHECK(FramePattern::find("renders#2/shot.####.exr")->path(3) == "renders#2/shot.0003.exr");  // folders are not patterns
  CHECK_FALSE(FramePattern::find("shot.1001.exr").has_value());
  CHECK_FALSE(FramePattern::find("100%.exr").has_value());
  CHECK_THROWS_AS(FramePattern::find("a.##.b.##.exr"), lensmith::OptionsError);
}

TEST_CASE("frame lists: ranges, steps, lists, negative frames", "[imageio][sequence]") {
  using V = std::vector<long>;
  CHECK(lensmith::parse_frame_list("1001-1004") == V{1001, 1002, 1003, 1004});
  CHECK(lensmith::parse_frame_list("1001-1007x3") == V{1001, 1004, 1007});
  CHECK(lensmith::parse_frame_list("1,5,10-12") == V{1, 5, 10, 11, 12});
  CHECK(lensmith::parse_frame_list("-3--1") == V{-3, -2, -1});
  CHECK(lensmith::parse_frame_list("7") == V{7});
  for (const char* bad : {"", "a", "1-", "5-1", "1-5x0", "1,,2", "1-5x", "1.5"}) {
    INFO(bad);
    CHECK_THROWS_AS(lensmith::parse_frame_list(bad), lensmith::OptionsError);
  }
  CHECK_THROWS_AS(lensmith::parse_frame_list("0-100000000"), lensmith::OptionsError);
}

TEST_CASE("chunks cover every frame once, in order, in near-equal parts", "[imageio][sequence]") {
  const std::vector<long> frames = lensmith::parse_frame_list("1-10");
  std::vector<long> all;
  for (int i = 0; i < 3; ++i) {
    const auto chunk = lensmith::frame_chunk(frames, i, 3);
    CHECK(chunk.size() >= 3);
    CHECK(chunk.size() <= 4);
    all.insert(all.end(), chunk.begin(), chunk.end());
  }
  CHECK(all == frames);
  CHECK(lensmith::frame_chunk(frames, 4, 20).size() <= 1);
  CHECK_THROWS_AS(lensmith::frame_chunk(frames, 3, 3), lensmith::OptionsError);
}
