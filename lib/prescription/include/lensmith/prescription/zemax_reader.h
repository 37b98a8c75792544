// Reader for Zemax OpticStudio sequential lens files (.zmx), UTF-8 or UTF-16LE with BOM.
// Supported keywords and what is ignored or refused: docs/lens-formats-foreign.md, section "Zemax".
#pragma once

#include <string>
#include <string_view>

#include "lensmith/glass/glass_catalog.h"
#include "lensmith/prescription/lens_file.h"

namespace lensmith {

// Parses the bytes of a .zmx file (any BOM handled). Surface 0 (object) gives the object distance
// and medium, the last surface is the image plane; surfaces 1..N-1 become the prescription.
// Throws FileError naming file:line and the keyword for anything malformed or unsupported
// that changes the optics (e.g. TYPE COORDBRK, GLAS MIRROR); a glass found in no catalogue falls
// back to the nd/Vd on its GLAS line with a warning, or is an error when the line has none.
LensReadResult read_zemax(std::string_view bytes, const std::string& file_name,
                          const GlassCatalog& catalogue = GlassCatalog::builtin());

}  // namespace lensmith
