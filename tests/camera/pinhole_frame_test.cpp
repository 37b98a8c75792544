// The framing of an all-in-focus picture (pinhole_frame.h): pixels and directions.
#include "lensmith/camera/pinhole_frame.h"

#include <catch2/catch.hpp>

#include "lensmith/core/errors.h"

using Catch::Matchers::WithinAbs;
using namespace lensmith;

TEST_CASE("a pinhole frame looks along its axis through its centre and tan = offset / focal length elsewhere", "[camera][pinhole]") {
  const PinholeFrame frame(640, 360, 800.0);
  const Tangents centre = frame.tangents_at({320.0, 180.0});
  CHECK(centre.x == 0.0);
  CHECK(centre.y == 0.0);
  const Tangents corner = frame.tangents_at({0.0, 0.0});  // top left: left and up
  CHECK_THAT(corner.x, WithinAbs(-320.0 / 800.0, 1e-15));
  CHECK_THAT(corner.y, WithinAbs(180.0 / 800.0, 1e-15));
  const PixelPoint back = frame.pixel_at(corner);
  CHECK_THAT(back.x, WithinAbs(0.0, 1e-12));
  CHECK_THAT(back.y, WithinAbs(0.0, 1e-12));
}

TEST_CASE("a window of a frame looks where the frame's pixels under it look, its axis off its centre", "[camera][pinhole]") {
  // An OpenEXR data window of 630 x 360 from x = 10 of a 640 x 360 frame.
  const PinholeFrame frame(640, 360, 800.0);
  const PinholeFrame part = frame.window(10, 0, 630, 360);
  CHECK(part.width_px() == 630);
  CHECK(part.focal_length_px() == 800.0);
  for (const PixelPoint p : {PixelPoint{0.5, 0.5}, PixelPoint{310.0, 180.0}, PixelPoint{629.5, 359.5}}) {
    const Tangents a = part.tangents_at(p), b = frame.tangents_at({p.x + 10.0, p.y});
    CHECK(a.x == b.x);
    CHECK(a.y == b.y);
  }
  CHECK(part.pixel_at({0.0, 0.0}).x == 310.0);  // the axis, 10 px left of the frame's centre in the window
  CHECK(part.to_string().find("axis at (310, 180) px") != std::string::npos);
  CHECK(frame.to_string().find("axis") == std::string::npos);
  CHECK_THROWS_AS(frame.window(0, 0, 0, 10), OptionsError);
}
