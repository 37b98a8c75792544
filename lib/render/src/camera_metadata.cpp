// Camera metadata of picture files (camera_metadata.h).
#include "lensmith/render/camera_metadata.h"

#include <cmath>

#include "lensmith/core/number_parsing.h"

namespace lensmith {

namespace {

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::optional<double> positive(const std::string& text) {
  const std::optional<double> v = parse_finite_number(text);
  return v && *v > 0.0 ? v : std::nullopt;
}

}  // namespace

CameraMetadata camera_metadata_from(const std::vector<std::pair<std::string, std::string>>& attributes) {
  CameraMetadata m;
  // OpenEXR's standard attributes first; Unreal's keys, read after, replace them.
  for (const auto& [name, value] : attributes) {
    if (name == "focus") {
      if (auto v = positive(value)) m.focus_from_image_plane_m = v;
    } else if (name == "aperture" || name == "FNumber") {  // read_image_metadata names OpenEXR's aperture FNumber
      if (auto v = positive(value)) m.f_number = v;
    } else if (name == "focalLength" || name == "pinholeFocalLength") {
      // pinholeFocalLength is the exact one for framing; focalLength is what most files carry.
      if (auto v = positive(value); v && (name == "pinholeFocalLength" || !m.focal_length_mm)) m.focal_length_mm = v;
    } else if (name == "entrancePupilOffset") {
      if (auto v = parse_finite_number(value)) m.entrance_pupil_offset_mm = v;
    } else if (name == "sensorOverallDimensions") {
      // V2f as text: "36, 24".
      if (auto v = positive(value.substr(0, value.find(',')))) m.sensor_width_mm = v;
    }
  }
  for (const auto& [name, value] : attributes) {
    if (name.rfind("unreal/", 0) != 0) continue;
    if (ends_with(name, "/fstop")) {
      if (auto v = positive(value)) m.f_number = v;
    } else if (ends_with(name, "/focalDistance")) {
      if (auto v = positive(value)) {
        m.focus_from_pupil_m = *v / 100.0;  // Unreal units are centimetres
        m.focus_from_image_plane_m.reset();
      }
    } else if (ends_with(name, "/focalLength")) {
      if (auto v = positive(value)) m.focal_length_mm = v;
    } else if (ends_with(name, "/sensorWidth")) {
      if (auto v = positive(value)) m.sensor_width_mm = v;
    } else if (ends_with(name, "/dofDiaphragmBladeCount")) {
      if (auto v = parse_finite_number(value); v && *v >= 3 && *v <= 64 && *v == std::floor(*v)) m.blades = static_cast<int>(*v);
    }
  }
  const auto add = [&](const char* what, const std::optional<double>& v, const char* unit) {
    if (v) m.found.push_back(std::string(what) + " " + format_number(*v) + unit);
  };
  add("focus", m.focus_from_pupil_m, " m from the camera");
  add("focus", m.focus_from_image_plane_m, " m from the image plane");
  add("f-number", m.f_number, "");
  add("focal length", m.focal_length_mm, " mm");
  add("sensor width", m.sensor_width_mm, " mm");
  add("entrance pupil offset", m.entrance_pupil_offset_mm, " mm");
  if (m.blades) m.found.push_back(std::to_string(*m.blades) + " blades");
  return m;
}

}  // namespace lensmith
