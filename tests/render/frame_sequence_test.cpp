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

#include "lensmith/render/camera_metadata.h"

TEST_CASE("camera metadata: OpenEXR's standard attributes and Unreal's keys, Unreal winning, bad values ignored", "[render][metadata]") {
  const lensmith::CameraMetadata exr = lensmith::camera_metadata_from(
      {{"focus", "2.5"}, {"FNumber", "2.8"}, {"focalLength", "35"}, {"pinholeFocalLength", "36"}, {"entrancePupilOffset", "-12"},
       {"sensorOverallDimensions", "24.9, 18.7"}});
  CHECK(exr.focus_from_image_plane_m == 2.5);
  CHECK(exr.f_number == 2.8);
  CHECK(exr.focal_length_mm == 36.0);  // pinholeFocalLength is the framing's
  CHECK(exr.entrance_pupil_offset_mm == -12.0);
  CHECK(exr.sensor_width_mm == 24.9);
  CHECK_FALSE(exr.focus_from_pupil_m.has_value());
  const lensmith::CameraMetadata both = lensmith::camera_metadata_from(
      {{"focus", "2.5"}, {"FNumber", "2.8"}, {"unreal/camera/FinalImage/focalDistance", "300"}, {"unreal/camera/FinalImage/fstop", "4"},
       {"unreal/camera/FinalImage/dofDiaphragmBladeCount", "7"}, {"unreal/camera/FinalImage/sensorWidth", "23.76"}});
  CHECK(both.focus_from_pupil_m == 3.0);  // cm
  CHECK_FALSE(both.focus_from_image_plane_m.has_value());
  CHECK(both.f_number == 4.0);
  CHECK(both.blades == 7);
  CHECK(both.sensor_width_mm == 23.76);
  const lensmith::CameraMetadata bad = lensmith::camera_metadata_from(
      {{"focus", "-1"}, {"FNumber", "nan"}, {"unreal/camera/FinalImage/dofDiaphragmBladeCount", "2"}, {"focalLength", "abc"}});
  CHECK(bad.empty());
}
