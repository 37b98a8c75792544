// The camera a picture file says it was made with: OpenEXR's standard attributes and Unreal Engine's
// Movie Render Queue keys (docs/sequences.md, "Camera metadata"). `lensmith bokeh` takes what the
// flags do not give from here, frame by frame.
//
// OpenEXR (openexr.com, StandardAttributes; float attributes): focus (m; OpenEXR does not say from
// where: lensmith reads it as from the image plane, as cameras, SMPTE camdkit and ARRI measure it),
// aperture (f-number), focalLength (mm), pinholeFocalLength (mm, OpenEXR 3.2), entrancePupilOffset
// (mm from the image plane to the entrance pupil, positive toward the object; 3.2),
// sensorOverallDimensions (mm, 3.2). Unreal (MoviePipelineUtils, string attributes
// "unreal/<camera>/<pass>/<key>"): fstop, focalDistance (cm, from the camera: the perspective
// centre), focalLength (mm), sensorWidth (mm), dofDiaphragmBladeCount.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace lensmith {

struct CameraMetadata {
  std::optional<double> focus_from_image_plane_m;  // OpenEXR focus
  std::optional<double> focus_from_pupil_m;        // Unreal focalDistance / 100
  std::optional<double> f_number;
  std::optional<double> focal_length_mm;           // the render camera's focal length (pinhole framing; a thin lens's)
  std::optional<double> sensor_width_mm;
  std::optional<double> entrance_pupil_offset_mm;  // image plane to entrance pupil, + toward the object
  std::optional<int> blades;
  // What was found, for a note: "focus 2.5 m (OpenEXR focus, from the image plane)", ...
  std::vector<std::string> found;
  bool empty() const { return found.empty(); }
};

// From a file's attributes as read_image_metadata gives them (name, value as text). Values that are
// not positive finite numbers (a blade count below 3) are ignored; when both conventions give a value,
// Unreal's wins (it says more exactly what the render did).
CameraMetadata camera_metadata_from(const std::vector<std::pair<std::string, std::string>>& attributes);

}  // namespace lensmith
