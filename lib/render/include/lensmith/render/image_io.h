// Reading the renderer's inputs (an all-in-focus picture and its depth map) and writing its output,
// through lensmith::imageio (OpenEXR, libtiff, libpng, stb_image). The sRGB transfer curve is the
// piecewise one of IEC 61966-2-1:1999, 5.2/5.3.
// Pixel layout and units are those of image.h: linear float, row-major, top row first; depth in metres.
#pragma once

#include <filesystem>
#include <optional>
#include <ostream>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "lensmith/camera/pinhole_frame.h"
#include "lensmith/core/errors.h"
#include "lensmith/core/text_file.h"
#include "lensmith/imageio/image_file.h"
#include "lensmith/imageio/raster.h"
#include "lensmith/render/image.h"

namespace lensmith {

// ImageFileError (a file read but not usable: a NaN pixel, a missing channel, integer depth, a size
// that does not match, a deep or cropped image) is declared in lensmith/imageio/raster.h.

// sRGB-encoded value in [0, 1] from linear light (IEC 61966-2-1: 12.92 l below l = 0.0031308, else
// 1.055 l^(1/2.4) - 0.055). Not clamped: values outside [0, 1] follow the same formulas (negative
// values the linear segment).
float srgb_encode(float linear);
// Linear light from an sRGB-encoded value (e / 12.92 at or below e = 0.04045, else
// ((e + 0.055) / 1.055)^2.4); the inverse of srgb_encode.
float srgb_decode(float encoded);

// How read_radiance_image treats 8/16-bit (display-referred) pictures.
struct RadianceReadOptions {
  // Encoded value in (0, 1] at or above which a channel of an 8/16-bit file counts as clipped.
  double highlight_threshold = 0.98;
  // >= 1 (finite). The linear values of a pixel whose largest encoded channel e reaches the
  // threshold t are multiplied by 1 + (gain - 1) s((e - t) / (1 - t)), s the smoothstep
  // 3u^2 - 2u^3: 1 at the threshold, `gain` at full scale. A clipped highlight in an LDR photo
  // stands for light of unknown strength; a gain > 1 lets it carry more energy into the bokeh.
  // 1 = off. Float files (true radiance) are never changed.
  double highlight_gain = 1.0;

  void validate() const;  // throws OptionsError naming the field and the constraint
  std::string to_string() const;  // "RadianceReadOptions(highlight_threshold 0.98, highlight_gain 1)"
  friend std::ostream& operator<<(std::ostream& os, const RadianceReadOptions& o) { return os << o.to_string(); }
};

// Reads a picture as linear Rec.709 RGB, 3 channels: OpenEXR (scanline or tiled, the first part),
// TIFF (the first page), PNG, JPEG, Radiance HDR, PFM, BMP, TGA or binary PNM, recognised by the
// file's first bytes (kReadableImageFormats in lensmith/imageio/image_file.h).
// - Float/half channels (EXR, HDR, float TIFF, PFM) are linear radiance as stored; a NaN, infinite
//   or negative value is an ImageFileError naming the first such pixel, channel and value.
// - 8/16-bit integer channels are sRGB-encoded and decoded by srgb_decode, unless the file says it
//   is linear, then taken as stored in [0, 1]: an OpenEXR's integer channels (OpenEXR pixels are
//   linear), or a PNG with a gAMA chunk of 1.0 and no sRGB chunk. Nothing else is consulted: TIFF,
//   JPEG and the other formats are taken as sRGB, and no ICC profile is applied.
// - Channels R, G, B by name when all three exist, else those of the first layer that has all
//   three (a Blender multilayer EXR's ViewLayer.Combined.R, .G, .B), else the first three; a 1- or 2-channel
//   (gray, gray + alpha) picture is replicated to R = G = B. Alpha is ignored: premultiplied
//   colours are taken as they are.
// - The data window must be the display window (no crop or overscan); a deep OpenEXR is refused.
// Throws IoError (with the decoder's message) when the file cannot be opened or read or is of
// another format (the message lists the formats read), ImageFileError for the refusals above,
// OptionsError for invalid options.
Image read_radiance_image(const std::filesystem::path& path, const RadianceReadOptions& options = {});

// The picture's alpha channel ("A", as OpenEXR, PNG, TIFF name it), width x height floats in [0, 1]
// (integers normalised), or nothing when it has none. Throws ImageFileError naming the first pixel
// whose alpha is NaN, negative or above 1 by more than rounding, IoError when the file cannot be read.
std::optional<std::vector<float>> read_alpha(const std::filesystem::path& path);

// The channels of an OpenEXR picture other than its colour, alpha and depth (as read_radiance_image,
// read_alpha and read_depth choose them): render passes (AOVs) such as diffuse.R or N.x, in the
// file's order; nothing for other
// formats. `samples[(y * width + x) * names.size() + c]`, as stored (not validated: a pass may hold
// any value).
struct OtherChannels {
  std::vector<std::string> names;
  std::vector<float> samples;
};
OtherChannels read_other_channels(const std::filesystem::path& path);

// A depth input named on a command line as FILE[:CHANNEL].
struct DepthSource {
  std::filesystem::path file;
  std::string channel;  // empty = the default choice of read_depth

  // If the whole spec names an existing file it is the file (so "C:\depth.exr" or a name with a
  // ':' works); otherwise the spec splits at its last ':' into FILE and a non-empty CHANNEL; with
  // no ':' it is a file name. Throws OptionsError for an empty spec, file or channel.
  static DepthSource parse(const std::string& spec);
  std::string to_string() const;  // "depth.exr:depth.Z", or "depth.exr" with no channel
  friend std::ostream& operator<<(std::ostream& os, const DepthSource& s) { return os << s.to_string(); }
};

// What the numbers in a depth channel measure.
enum class DepthKind {
  Z,         // planar distance along the optical axis (Blender/Cycles "Z", pbrt, most renderers)
  Distance,  // Euclidean distance from the pinhole; planar z = d / sqrt(1 + tx^2 + ty^2)
  Inverse,   // 1 / z in 1 / unit (disparity-like maps from depth estimators); 0 = infinitely far
};
// The length unit of a depth channel (of z, d, or of 1 / value for Inverse).
enum class DepthUnit { M, Cm, Mm };
// What to do with a depth that names no point in front of the camera: NaN, negative, zero
// (a point at the pinhole) or, for Inverse, NaN, negative or infinite values.
enum class InvalidDepth {
  Error,  // refuse the map, naming the first bad pixel
  Far,    // treat as infinitely far (+inf)
  Near,   // treat as the nearest valid depth of the map
};

// "z" | "distance" | "inverse", "m" | "cm" | "mm", "error" | "far" | "near"; anything else is an
// OptionsError listing the allowed values. to_string gives back the same words.
DepthKind parse_depth_kind(const std::string& text);
DepthUnit parse_depth_unit(const std::string& text);
InvalidDepth parse_invalid_depth(const std::string& text);
std::string to_string(DepthKind kind);
std::string to_string(DepthUnit unit);
std::string to_string(InvalidDepth invalid);

struct DepthReadOptions {
  DepthKind kind = DepthKind::Z;
  DepthUnit unit = DepthUnit::M;
  InvalidDepth invalid = InvalidDepth::Error;
  std::string to_string() const;  // "DepthReadOptions(kind z, unit m, invalid error)"
  friend std::ostream& operator<<(std::ostream& os, const DepthReadOptions& o) { return os << o.to_string(); }
};

// One depth value of pixel (x, y) of `frame` as planar depth z in metres (+inf = infinitely far):
// what read_depth does per pixel. NaN where the value names no point in front of the camera (z <= 0
// comes back as it is; the caller decides).
double planar_depth_m(double value, const DepthReadOptions& options, const PinholeFrame& frame, int x, int y);

// Depth values of `frame`'s pixels (row-major, top row first, as read_depth reads them from a file)
// as planar depth z in metres (+inf = infinitely far), with invalid values handled as `options` says.
// `where` names the values in errors ("depth.exr channel Z"). Throws ImageFileError.
DepthMap depth_map_from_values(std::span<const float> values, const DepthReadOptions& options, const PinholeFrame& frame,
                               const std::string& where);

// Reads one channel of a depth file as planar depth z in metres (+inf = infinitely far), pixel
// (x, y) of the map belonging to pixel (x, y) of `frame`; Distance is converted with the frame's
// tangents at pixel centres (x + 0.5, y + 0.5).
// The channel is source.channel, or by default "Z", then "depth.Z", then a layer's "Depth.Z" (any
// case: Blender's "ViewLayer.Depth.Z"), then channel 0 of a one-channel file; otherwise
// ImageFileError listing the channels.
// Reads the formats read_radiance_image reads (float channels: OpenEXR, float TIFF, PFM, HDR).
// Throws IoError when the file cannot be read, and ImageFileError when the channel is missing
// (listing the file's channels), stored as integers (normalised integers carry no metric depth:
// store float EXR, float TIFF or PFM), of another size than the frame, or holds an invalid depth
// under InvalidDepth::Error (naming the first bad pixel and how to override).
DepthMap read_depth(const DepthSource& source, const DepthReadOptions& options, const PinholeFrame& frame);

// What the renderer records in its output files.
struct OutputMetadata {
  std::string lens;              // lens name or file; empty = not recorded
  std::string model;             // renderer model name; empty = not recorded
  std::string lensmith_version;  // empty = not recorded
  double f_number = 0.0;         // working f-number; 0 = not recorded
  double focus_m = 0.0;          // focus distance, m (inf allowed); 0 = not recorded
  std::vector<std::pair<std::string, std::string>> extra;  // written as "lensmith:<key>"
  // The input's OpenEXR windows when it had overscan: an OpenEXR output keeps them (the image is
  // the data window), other formats get the display window only. Empty (width 0): the image.
  PixelBox data_window;
  PixelBox display_window;
  // OpenEXR's standard camera attributes (float, as the standard has them), written when set:
  // focus (m), aperture (f-number), focalLength (mm), entrancePupilOffset (m).
  std::vector<std::pair<std::string, double>> camera;
  // OpenEXR's standard chromaticities of the output's RGB, "rx, ry, gx, gy, bx, by, wx, wy" as
  // read_image_metadata gives them (an input's, passed through); empty: not written (readers then
  // take Rec.709).
  std::string chromaticities;

  std::string to_string() const;  // "lens X, f/2.8, focus 2 m, model Y" (the ImageDescription)
  friend std::ostream& operator<<(std::ostream& os, const OutputMetadata& m) { return os << m.to_string(); }
};

// The file attributes write_output_image records from `meta`: Software, ImageDescription and the
// lensmith:* keys.
std::vector<ImageAttribute> output_attributes(const OutputMetadata& meta);

// Writes a linear RGB image (3 channels, or 4 (RGBA, premultiplied) to OpenEXR only, else
// OptionsError; a NaN is a ComputationError naming the pixel, since whatever made the image
// failed), the format chosen by the extension (any case):
//   .exr             32-bit float RGB or RGBA, ZIP compression, linear as given;
//   .hdr             Radiance RGBE float (run-length encoded), linear as given;
//   .png .jpg .jpeg  8-bit sRGB (srgb_encode, clamped to [0, 1], rounded; PNG with an sRGB chunk,
//                    JPEG quality 95 without chroma subsampling);
//   .tif .tiff       16-bit sRGB, the same way (deflate compression).
// Every format gets "Software" = "lensmith <version>" and an ImageDescription from meta (EXR:
// string attributes, the description as the standard "comments"; PNG: text chunks; TIFF: its tags;
// JPEG: Exif tags and the description as the JPEG comment; HDR: header lines, Software as SOFTWARE).
// The formats that keep free attributes (EXR, PNG, HDR) also get "lensmith:lens",
// "lensmith:f_number", "lensmith:focus_m" (EXR: doubles), "lensmith:model", "lensmith:version" and
// "lensmith:<key>" for meta.extra.
// The file is written to a temporary file beside `path` and renamed onto it, so a failure never
// leaves a half-written picture. Throws OptionsError for another extension (listing the supported
// ones) and IoError when writing fails.
// `channel_names` (OpenEXR only) names the image's channels when it carries more than RGB(A), e.g.
// {"R", "G", "B", "A", "Z"}: the first three must be R, G, B.
void write_output_image(const std::filesystem::path& path, const Image& linear_rgb, const OutputMetadata& meta,
                        const std::vector<std::string>& channel_names = {});
// Whether write_output_image keeps an alpha channel for this path (OpenEXR); throws as it does for
// an unsupported extension.
bool output_keeps_alpha(const std::filesystem::path& path);

// Writes every channel of `image` to a 32-bit float EXR (ZIP) with the given channel names (one
// per channel): depth or other passes for tools that read them by name. Written atomically like
// write_output_image. Throws OptionsError when the path does not end in .exr or the names do not
// match the channels, IoError when writing fails.
void write_float_exr(const std::filesystem::path& path, const Image& image, const std::vector<std::string>& channel_names);

// The metadata of an image file as (name, value) text pairs, under OpenImageIO's names, in the
// file's order (read_image_metadata_pairs in lensmith/imageio/image_file.h lists what each format
// gives): string attributes as stored, numbers in the shortest text that reads back exactly.
// Throws IoError.
std::vector<std::pair<std::string, std::string>> read_image_metadata(const std::filesystem::path& path);

// ensure_not_an_input and ensure_writable_location: lensmith/core/text_file.h, beside the atomic writer.

}  // namespace lensmith
