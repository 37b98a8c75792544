// Reader for CODE V sequential lens files (.seq): the command file CODE V writes with "save" (or a
// person writes by hand). Keywords read, ignored and refused: docs/lens-formats-foreign.md, "CODE V".
#pragma once

#include <string>
#include <string_view>

#include "lensmith/glass/glass_catalog.h"
#include "lensmith/prescription/lens_file.h"

namespace lensmith {

// Parses the bytes of a .seq file (UTF-8, UTF-16 or Windows-1252, as decode_text reads them). SO is
// the object surface (its thickness the object distance, >= 1e10 lens units meaning infinity), the S
// lines are the lens surfaces, SI the image surface (its thickness a defocus added to the last
// surface's). Rays are aimed at the real stop (RayAiming::RealStop), as CODE V does.
// Throws FileError naming file:line:col and the keyword for anything malformed or that would
// change the optics and cannot be represented (mirrors, decentres and tilts, zoom, diffractive or
// toroidal surfaces, object-space NA); a fictitious glass code or private glass becomes a model
// glass with a warning; an unknown glass is an error naming the closest catalogue names.
LensReadResult read_codev(std::string_view bytes, const std::string& file_name,
                          const GlassCatalog& catalogue = GlassCatalog::builtin());

}  // namespace lensmith
