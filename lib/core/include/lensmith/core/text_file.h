// Reading user text files and writing outputs safely.
#pragma once

#include <functional>
#include <string>
#include <string_view>

namespace lensmith {

// Reads a whole file as bytes. Throws IoError naming the path when it cannot be opened.
std::string read_file_bytes(const std::string& path);

// Decodes text as Zemax and Windows tools write it: UTF-8 (with or without BOM) or UTF-16LE/BE
// with a BOM, returned as UTF-8. Throws LensFileError(file) on a malformed UTF-16 sequence.
std::string decode_text(std::string_view bytes, const std::string& file_name);

// Writes `contents` to `path` through a temporary file in the same folder and a rename, so a
// crash never leaves a half-written output. Throws IoError.
void write_file_atomically(const std::string& path, std::string_view contents);

// The same mechanism for writers that need a file name (an image library, say): `write` is called
// with a temporary path in the folder of `path`, ending in `extension` (e.g. ".png") so a writer that
// picks the format by name picks the right one, and the finished file is renamed onto `path`. When
// `write` throws, the temporary file is removed and the exception passes on. Throws IoError when
// the rename fails.
void write_atomically(const std::string& path, const std::string& extension,
                      const std::function<void(const std::string& temporary_path)>& write);

}  // namespace lensmith
