// Writes examples/bokeh-scene.exr, the bundled all-in-focus input for `lensmith bokeh`: a 640 x 360
// pinhole view (36 mm wide sensor, 50 mm focal length) of fronto-parallel planes at known depths with
// HDR point lights, as linear half RGB plus a float planar-depth channel Z in metres (as Blender writes).
// Build and run from the repository root (examples/README.md describes the scene):
//   g++ -O2 -std=c++20 tools/make_bokeh_example.cpp $(pkg-config --cflags --libs OpenEXR) -o /tmp/make_bokeh_example
//   /tmp/make_bokeh_example examples/bokeh-scene.exr
// Everything is deterministic: textures come from an integer hash of their coordinates, not an RNG.
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <Imath/half.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <limits>
#include <string>
#include <vector>

namespace {

constexpr int kWidthPx = 640;
constexpr int kHeightPx = 360;
constexpr double kSensorWidthMm = 36.0;
constexpr double kFocalLengthMm = 50.0;
constexpr double kFocalPx = kWidthPx * kFocalLengthMm / kSensorWidthMm;  // 888.9 px

// Planar depths of the layers, metres.
constexpr double kForegroundM = 1.2;
constexpr double kWallM = 3.0;
constexpr double kFarM = 20.0;
constexpr double kSkyM = std::numeric_limits<double>::infinity();

constexpr int kSupersample = 4;  // 4 x 4 texture samples per pixel; layer coverage is decided at the centre

struct Rgb {
  double r = 0.0, g = 0.0, b = 0.0;
};
Rgb operator*(const Rgb& c, double s) { return {c.r * s, c.g * s, c.b * s}; }
Rgb operator+(const Rgb& a, const Rgb& b) { return {a.r + b.r, a.g + b.g, a.b + b.b}; }
Rgb mix(const Rgb& a, const Rgb& b, double t) { return a * (1.0 - t) + b * t; }

// Chris Wellons' lowbias32 integer hash: a fixed, portable source of texture variation.
std::uint32_t hash32(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}
double hash01(int a, int b, int salt) {
  const std::uint32_t h = hash32(static_cast<std::uint32_t>(a) * 73856093U ^ static_cast<std::uint32_t>(b) * 19349663U ^
                                 static_cast<std::uint32_t>(salt) * 83492791U);
  return static_cast<double>(h) / 4294967296.0;
}
// Smooth value noise in [0, 1] on a unit lattice.
double value_noise(double u, double v, int salt) {
  const double fu = std::floor(u), fv = std::floor(v);
  const int iu = static_cast<int>(fu), iv = static_cast<int>(fv);
  double su = u - fu, sv = v - fv;
  su = su * su * (3.0 - 2.0 * su);
  sv = sv * sv * (3.0 - 2.0 * sv);
  const double a = hash01(iu, iv, salt), b = hash01(iu + 1, iv, salt);
  const double c = hash01(iu, iv + 1, salt), d = hash01(iu + 1, iv + 1, salt);
  return (a * (1 - su) + b * su) * (1 - sv) + (c * (1 - su) + d * su) * sv;
}

// Scene coordinates on a plane at planar depth z_m seen through continuous pixel (px, py): metres,
// x to the right, y up, origin on the optical axis.
struct PlanePoint {
  double x_m, y_m;
};
PlanePoint on_plane(double px, double py, double z_m) {
  return {(px - 0.5 * kWidthPx) / kFocalPx * z_m, (0.5 * kHeightPx - py) / kFocalPx * z_m};
}

// --- Sky (infinitely far): a dusk gradient. ---
Rgb sky(double py) {
  const double t = std::clamp(py / 90.0, 0.0, 1.0);
  return mix(Rgb{0.035, 0.06, 0.16}, Rgb{0.30, 0.17, 0.10}, t * t);
}

// --- Far plane at 20 m: a row of buildings with a stepped roofline and lit windows. ---
// Roof height above the optical axis (m) of the building at x_m.
double roof_y_m(double x_m) {
  const int building = static_cast<int>(std::floor(x_m / 3.1));
  return 2.35 + 0.9 * hash01(building, 0, 11);
}
bool far_covers(double px, double py) {
  const PlanePoint p = on_plane(px, py, kFarM);
  return p.y_m <= roof_y_m(p.x_m);
}
Rgb far_texture(double px, double py) {
  const PlanePoint p = on_plane(px, py, kFarM);
  const int building = static_cast<int>(std::floor(p.x_m / 3.1));
  const Rgb facade = mix(Rgb{0.025, 0.028, 0.04}, Rgb{0.05, 0.04, 0.035}, hash01(building, 1, 12));
  // Windows 0.7 x 0.9 m on a 1.3 x 1.6 m grid; some lit warm, some dark.
  const double gx = p.x_m / 1.3, gy = p.y_m / 1.6;
  const double fx = gx - std::floor(gx), fy = gy - std::floor(gy);
  if (fx > 0.2 && fx < 0.74 && fy > 0.2 && fy < 0.76 && p.y_m < roof_y_m(p.x_m) - 0.4) {
    const int wx = static_cast<int>(std::floor(gx)), wy = static_cast<int>(std::floor(gy));
    const double lit = hash01(wx, wy, 13);
    if (lit > 0.45) return mix(Rgb{0.9, 0.55, 0.25}, Rgb{1.2, 1.0, 0.7}, hash01(wx, wy, 14));
    return Rgb{0.015, 0.018, 0.03};
  }
  return facade * (0.8 + 0.4 * value_noise(p.x_m * 4.0, p.y_m * 4.0, 15));
}

// --- Brick wall at 3 m, its top edge at y = 0.25 m (row 106); a checker target hangs on it. ---
constexpr double kWallTopM = 0.25;
bool wall_covers(double px, double py) { return on_plane(px, py, kWallM).y_m <= kWallTopM; }
Rgb wall_texture(double x_m, double y_m) {
  // Checker target: 5 cm squares, 6 x 4 of them, centred at (0.62 m, -0.05 m).
  const double cx = (x_m - 0.47) / 0.05, cy = (y_m + 0.15) / 0.05;
  if (cx >= 0.0 && cx < 6.0 && cy >= 0.0 && cy < 4.0) {
    return ((static_cast<int>(cx) + static_cast<int>(cy)) % 2 == 0) ? Rgb{0.75, 0.75, 0.72} : Rgb{0.03, 0.03, 0.03};
  }
  if (cx >= -0.3 && cx < 6.3 && cy >= -0.3 && cy < 4.3) return Rgb{0.4, 0.4, 0.38};  // the target's border
  // Bricks 215 x 65 mm with 10 mm mortar, running bond.
  const double course_m = 0.075, length_m = 0.225, mortar_m = 0.010;
  const double row = std::floor(y_m / course_m);
  const int irow = static_cast<int>(row);
  const double shifted = x_m + ((irow % 2 == 0) ? 0.0 : 0.5 * length_m);
  const int icol = static_cast<int>(std::floor(shifted / length_m));
  const double in_x = shifted - icol * length_m, in_y = y_m - row * course_m;
  const double grain = value_noise(x_m * 180.0, y_m * 180.0, 3);  // ~5 mm grain
  if (in_x < mortar_m || in_y < mortar_m) return Rgb{0.30, 0.29, 0.27} * (0.85 + 0.3 * grain);
  // Brick colours: mostly reds and browns, some orange, a few grey-blue engineering bricks.
  static const std::array<Rgb, 6> kBricks = {
      Rgb{0.36, 0.11, 0.06}, Rgb{0.42, 0.16, 0.08}, Rgb{0.28, 0.12, 0.07},
      Rgb{0.48, 0.24, 0.10}, Rgb{0.33, 0.09, 0.07}, Rgb{0.16, 0.16, 0.19}};
  const double pick = hash01(icol, irow, 4);
  const Rgb base = kBricks[static_cast<std::size_t>(std::min(5.0, std::floor(pick * 6.0)))];
  const double tone = 0.8 + 0.4 * hash01(icol, irow, 5);
  // A soft lamp pool lights the wall from the upper right.
  const double dx = x_m - 0.6, dy = y_m - 0.1;
  const double light = 0.55 + 0.6 * std::exp(-(dx * dx + dy * dy) / 0.35);
  return base * (tone * (0.8 + 0.4 * grain) * light);
}

// --- Foreground at 1.2 m: a dark post and a plant of elliptical leaves rising from the bottom right. ---
constexpr double kPostLeftPx = 150.0, kPostRightPx = 206.0;
struct Leaf {
  double cx_px, cy_px, half_length_px, half_width_px, angle_rad;
};
const std::array<Leaf, 7> kLeaves = {{
    {560, 330, 95, 22, -1.05},
    {600, 300, 80, 18, -1.45},
    {505, 345, 85, 20, -0.55},
    {625, 250, 70, 16, -1.75},
    {470, 300, 60, 14, -0.35},
    {545, 265, 75, 17, -1.20},
    {590, 215, 55, 12, -1.60},
}};
bool in_leaf(const Leaf& l, double px, double py, double* along) {
  const double dx = px - l.cx_px, dy = py - l.cy_px;
  const double u = dx * std::cos(l.angle_rad) + dy * std::sin(l.angle_rad);
  const double v = -dx * std::sin(l.angle_rad) + dy * std::cos(l.angle_rad);
  const double uu = u / l.half_length_px;
  // A pointed leaf: the half width tapers as (1 - u^2).
  const double width = l.half_width_px * (1.0 - uu * uu);
  if (along) *along = uu;
  return std::abs(uu) <= 1.0 && std::abs(v) <= width;
}
int leaf_at(double px, double py) {
  for (std::size_t i = 0; i < kLeaves.size(); ++i)
    if (in_leaf(kLeaves[i], px, py, nullptr)) return static_cast<int>(i);
  return -1;
}
bool post_covers(double px) { return px >= kPostLeftPx && px < kPostRightPx; }
Rgb post_texture(double px, double py) {
  const PlanePoint p = on_plane(px, py, kForegroundM);
  // Dark painted wood, vertical grain, with a slight rounded-edge shading.
  const double grain = value_noise(p.x_m * 300.0, p.y_m * 12.0, 21);
  const double across = (px - 0.5 * (kPostLeftPx + kPostRightPx)) / (0.5 * (kPostRightPx - kPostLeftPx));
  const double shade = 1.0 - 0.45 * across * across;
  return Rgb{0.045, 0.032, 0.024} * ((0.75 + 0.5 * grain) * shade);
}
Rgb leaf_texture(int leaf, double px, double py) {
  double along = 0.0;
  in_leaf(kLeaves[static_cast<std::size_t>(leaf)], px, py, &along);
  const Rgb base = mix(Rgb{0.02, 0.07, 0.015}, Rgb{0.05, 0.13, 0.03}, hash01(leaf, 0, 31));
  return base * (0.7 + 0.5 * (1.0 - std::abs(along)));
}

enum class Layer { Sky, Far, Wall, Foreground };
struct Hit {
  Layer layer;
  int leaf;  // for Foreground: leaf index, or -1 for the post
};
Hit layer_at(double px, double py) {
  const int leaf = leaf_at(px, py);
  if (leaf >= 0) return {Layer::Foreground, leaf};
  if (post_covers(px)) return {Layer::Foreground, -1};
  if (wall_covers(px, py)) return {Layer::Wall, -1};
  if (far_covers(px, py)) return {Layer::Far, -1};
  return {Layer::Sky, -1};
}
double depth_of(Layer layer) {
  switch (layer) {
    case Layer::Sky: return kSkyM;
    case Layer::Far: return kFarM;
    case Layer::Wall: return kWallM;
    case Layer::Foreground: return kForegroundM;
  }
  return kSkyM;
}
Rgb texture_of(const Hit& hit, double px, double py) {
  switch (hit.layer) {
    case Layer::Sky: return sky(py);
    case Layer::Far: return far_texture(px, py);
    case Layer::Wall: {
      const PlanePoint p = on_plane(px, py, kWallM);
      return wall_texture(p.x_m, p.y_m);
    }
    case Layer::Foreground: return hit.leaf >= 0 ? leaf_texture(hit.leaf, px, py) : post_texture(px, py);
  }
  return {};
}

// A point light: a disc of radius_px at (x_px, y_px), radiance `rgb`, on the layer at that point.
struct Highlight {
  double x_px, y_px, radius_px;
  Rgb rgb;
  Layer layer;
};

std::vector<Highlight> highlights() {
  std::vector<Highlight> out;
  // String lights on the far plane: a catenary across the frame, alternating colours.
  const std::array<Rgb, 5> kBulbs = {Rgb{120, 80, 35}, Rgb{150, 20, 12}, Rgb{25, 110, 30}, Rgb{20, 45, 160},
                                     Rgb{180, 120, 40}};
  for (int i = 0; i < 21; ++i) {
    const double x = 15.0 + 30.5 * i;
    const double t = (x - 320.0) / 320.0;
    const double y = 101.0 - 21.0 * (std::cosh(1.2 * t) - 1.0) / (std::cosh(1.2) - 1.0);
    // Bulbs behind the post stay hidden.
    if (layer_at(x, y).layer != Layer::Far) continue;
    out.push_back({x, y, 1.2, kBulbs[static_cast<std::size_t>(i) % kBulbs.size()], Layer::Far});
  }
  // LEDs on the wall at 3 m: sharp when focused at 3 m. One sits 14 px right of the post.
  out.push_back({220.0, 230.0, 1.0, Rgb{90, 90, 85}, Layer::Wall});
  out.push_back({300.0, 160.0, 1.3, Rgb{200, 150, 60}, Layer::Wall});
  out.push_back({395.0, 300.0, 1.0, Rgb{30, 60, 140}, Layer::Wall});
  out.push_back({330.0, 245.0, 0.8, Rgb{160, 30, 25}, Layer::Wall});
  out.push_back({440.0, 150.0, 1.1, Rgb{60, 140, 60}, Layer::Wall});
  // Glints on the foreground at 1.2 m: two chrome bolts and an indicator on the post, dew on a leaf.
  out.push_back({178.0, 120.0, 1.4, Rgb{140, 135, 120}, Layer::Foreground});
  out.push_back({178.0, 250.0, 1.4, Rgb{140, 135, 120}, Layer::Foreground});
  out.push_back({170.0, 190.0, 1.0, Rgb{20, 120, 130}, Layer::Foreground});
  out.push_back({560.0, 318.0, 1.1, Rgb{70, 80, 60}, Layer::Foreground});
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTPUT.exr   (normally examples/bokeh-scene.exr)\n", argv[0]);
    return 2;
  }
  std::vector<float> pixels(static_cast<std::size_t>(kWidthPx) * kHeightPx * 4);
  std::vector<Hit> hits(static_cast<std::size_t>(kWidthPx) * kHeightPx);
  for (int y = 0; y < kHeightPx; ++y) {
    for (int x = 0; x < kWidthPx; ++x) {
      // Hard edges: the layer is the one at the pixel centre; its texture is averaged over the pixel.
      const Hit hit = layer_at(x + 0.5, y + 0.5);
      Rgb sum;
      for (int j = 0; j < kSupersample; ++j)
        for (int i = 0; i < kSupersample; ++i)
          sum = sum + texture_of(hit, x + (i + 0.5) / kSupersample, y + (j + 0.5) / kSupersample);
      const Rgb c = sum * (1.0 / (kSupersample * kSupersample));
      const std::size_t p = static_cast<std::size_t>(y) * kWidthPx + static_cast<std::size_t>(x);
      hits[p] = hit;
      pixels[p * 4 + 0] = static_cast<float>(c.r);
      pixels[p * 4 + 1] = static_cast<float>(c.g);
      pixels[p * 4 + 2] = static_cast<float>(c.b);
      pixels[p * 4 + 3] = static_cast<float>(depth_of(hit.layer));
    }
  }
  // Highlights blend in by their supersampled coverage, only over pixels of their own layer, so a
  // light never changes the depth it is seen at.
  int lights_per_layer[4] = {0, 0, 0, 0};
  for (const Highlight& h : highlights()) {
    ++lights_per_layer[static_cast<int>(h.layer)];
    const Hit centre = layer_at(h.x_px, h.y_px);
    if (centre.layer != h.layer) {
      std::fprintf(stderr, "make_bokeh_example: highlight at (%g, %g) is not on its layer\n", h.x_px, h.y_px);
      return 1;
    }
    const int r = static_cast<int>(std::ceil(h.radius_px)) + 1;
    for (int y = static_cast<int>(h.y_px) - r; y <= static_cast<int>(h.y_px) + r; ++y) {
      for (int x = static_cast<int>(h.x_px) - r; x <= static_cast<int>(h.x_px) + r; ++x) {
        if (x < 0 || y < 0 || x >= kWidthPx || y >= kHeightPx) continue;
        const std::size_t p = static_cast<std::size_t>(y) * kWidthPx + static_cast<std::size_t>(x);
        if (hits[p].layer != h.layer) continue;
        int inside = 0;
        for (int j = 0; j < kSupersample; ++j) {
          for (int i = 0; i < kSupersample; ++i) {
            const double dx = x + (i + 0.5) / kSupersample - h.x_px, dy = y + (j + 0.5) / kSupersample - h.y_px;
            if (dx * dx + dy * dy <= h.radius_px * h.radius_px) ++inside;
          }
        }
        const double cover = static_cast<double>(inside) / (kSupersample * kSupersample);
        const Rgb old{pixels[p * 4], pixels[p * 4 + 1], pixels[p * 4 + 2]};
        const Rgb c = mix(old, h.rgb, cover);
        pixels[p * 4 + 0] = static_cast<float>(c.r);
        pixels[p * 4 + 1] = static_cast<float>(c.g);
        pixels[p * 4 + 2] = static_cast<float>(c.b);
      }
    }
  }

  // RGB as half (OpenEXR converts the floats, rounding to nearest), Z as float; ZIP compression.
  Imf::Header header(kWidthPx, kHeightPx);
  header.compression() = Imf::ZIP_COMPRESSION;
  header.insert("comments", Imf::StringAttribute(
                                "lensmith bokeh example: all-in-focus pinhole view, 36 mm sensor width, 50 mm focal length; "
                                "linear Rec.709 RGB; Z = planar depth in metres (inf = sky). See examples/README.md."));
  header.insert("Software", Imf::StringAttribute("lensmith tools/make_bokeh_example.cpp"));
  // A fixed capture date, as the file has always carried one: the output stays byte-identical.
  header.insert("capDate", Imf::StringAttribute("2025:01:01 00:00:00"));
  header.insert("lensmith:sensor_width_mm", Imf::FloatAttribute(static_cast<float>(kSensorWidthMm)));
  header.insert("lensmith:focal_length_mm", Imf::FloatAttribute(static_cast<float>(kFocalLengthMm)));
  std::vector<Imath::half> rgb(static_cast<std::size_t>(kWidthPx) * kHeightPx * 3);
  std::vector<float> z(static_cast<std::size_t>(kWidthPx) * kHeightPx);
  for (std::size_t p = 0; p < z.size(); ++p) {
    for (std::size_t c = 0; c < 3; ++c) rgb[p * 3 + c] = Imath::half(pixels[p * 4 + c]);
    z[p] = pixels[p * 4 + 3];
  }
  Imf::FrameBuffer frame;
  const char* names[3] = {"R", "G", "B"};
  for (std::size_t c = 0; c < 3; ++c) {
    header.channels().insert(names[c], Imf::Channel(Imf::HALF));
    frame.insert(names[c], Imf::Slice::Make(Imf::HALF, rgb.data() + c, header.dataWindow(), 3 * sizeof(Imath::half),
                                            kWidthPx * 3 * sizeof(Imath::half)));
  }
  header.channels().insert("Z", Imf::Channel(Imf::FLOAT));
  frame.insert("Z", Imf::Slice::Make(Imf::FLOAT, z.data(), header.dataWindow(), sizeof(float), kWidthPx * sizeof(float)));
  try {
    Imf::OutputFile out(argv[1], header);
    out.setFrameBuffer(frame);
    out.writePixels(kHeightPx);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_bokeh_example: cannot write %s: %s\n", argv[1], e.what());
    return 1;
  }
  std::printf("wrote %s (%d x %d, R G B half + Z float); point lights: %d at 20 m, %d at 3 m, %d at 1.2 m\n", argv[1],
              kWidthPx, kHeightPx, lights_per_layer[static_cast<int>(Layer::Far)],
              lights_per_layer[static_cast<int>(Layer::Wall)], lights_per_layer[static_cast<int>(Layer::Foreground)]);
  return 0;
}
