// The JSON form of lensmith's results: first-order data, the 64-wavelength table, Seidel sums,
// spot diagrams, ray fans, distortion, field curves, chromatic focal shift, relative illumination,
// the unvignetted pupil and polynomial fits. One schema (docs/cli.md), written by the command's
// --json and read by the Python module, so that both always say the same thing.
//
// Units are in the key names (mm, um, nm, deg, sr). JSON has no infinity or NaN: a non-finite
// number (a distance at infinity, a ray that died) is written as null.
#pragma once

#include <vector>

#include <nlohmann/json.hpp>

namespace lensmith {

struct Prescription;
class ParaxialSystem;
class ParaxialSpectralTable;
class SeidelAnalysis;
struct SpotDiagram;
struct RayFan;
struct Wavefront;
struct Mtf;
struct Psf;
struct ThroughFocusMtf;
struct DistortionCurve;
struct FieldCurves;
struct ChromaticFocalShift;
struct RelativeIllumination;
struct PupilShape;
class LensFit;
struct OptimizeResult;
struct OptimizeProgress;

using ojson = nlohmann::ordered_json;

// `v`, or null when it is not finite.
ojson number_or_null(double v);

// `lensmith info --json`: the system at one wavelength and object distance.
ojson info_json(const Prescription& lens, const ParaxialSystem& system);
// `lensmith info --spectral --json`'s "spectral": one row per tabulated wavelength.
ojson spectral_json(const ParaxialSpectralTable& table);
// `lensmith seidel --json`: sums per surface and in total, and every form derived from them.
ojson seidel_json(const Prescription& lens, const SeidelAnalysis& seidel);
ojson spot_json(const SpotDiagram& diagram);
ojson fan_json(const RayFan& fan);
// lensmith wavefront --json: per field and wavelength the OPD statistics in waves, the reference
// sphere, the Zernike coefficients and the OPD fans; with `include_map`, the grid too (row-major from
// py = -1, null outside the pupil or where the ray died).
ojson wavefront_json(const Wavefront& wavefront, bool include_map);
// lensmith mtf --json: frequencies (cycles/mm), per field the tangential, sagittal and diffraction-limit
// curves and the Strehl ratio.
ojson mtf_json(const Mtf& mtf);
// lensmith mtf --through-focus --json: the frequency, focus shifts (mm) and per field the curves over them.
ojson through_focus_mtf_json(const ThroughFocusMtf& mtf);
// lensmith psf --json: the sampling, per field the Strehl ratio, the centroid and (with `include_grid`) the
// intensity grid (size x size, row-major from the top row, +y).
ojson psf_json(const Psf& psf, bool include_grid);
// `lensmith analyze --what ... --json`.
ojson distortion_json(const DistortionCurve& curve);
ojson field_curves_json(const FieldCurves& curves);
ojson focal_shift_json(const ChromaticFocalShift& shift);
ojson illumination_json(const RelativeIllumination& illumination);
ojson pupil_json(const PupilShape& shape);
// `lensmith fit --json` without the output file name: the fit, its held-out errors and its timing.
ojson fit_json(const LensFit& fit);
// `lensmith optimize --json`: the variables and operands before and after (each operand's value in its own
// unit, its goal and weight, its part of the merit), the merit, the iterations, glass substitutions, and the
// merit after each iteration (`history`).
ojson optimize_json(const OptimizeResult& result, const std::vector<OptimizeProgress>& history);

}  // namespace lensmith
