// Reader for pbrt RealisticCamera lens files (.dat): rows of radius, thickness, index, aperture
// diameter (mm); radius 0 marks the aperture stop. Two column conventions exist (see
// docs/lens-formats-foreign.md, section "pbrt"); both are read.
#pragma once

#include <string>
#include <string_view>

#include "lensmith/prescription/lens_file.h"

namespace lensmith {

enum class PbrtConvention {
  Auto,                    // SeparationFromPrevious when the first row's second column is 0 and the
                           // last row's is not, ThicknessToNext otherwise
  ThicknessToNext,         // pbrt-v4 scaled files (*.NNmm.dat): column 2 = distance to the next vertex
  SeparationFromPrevious,  // unscaled files (dgauss.dat ...): column 2 = distance from the previous vertex
};

// Parses a pbrt lens file. Indices become dispersion-free model glasses (pbrt gives no Abbe number),
// the stop row a plane stop in air, the aperture floats by the stop, and the image plane is placed
// at the paraxial focus (pbrt solves focus itself). Throws FileError with file:line.
LensReadResult read_pbrt(std::string_view text, const std::string& file_name,
                         PbrtConvention convention = PbrtConvention::Auto);

}  // namespace lensmith
