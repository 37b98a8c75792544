// Reading user text files and writing outputs safely.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace lensmith {

// Reads a whole file as bytes. Throws IoError naming the path when it cannot be opened.
std::string read_file_bytes(const std::string& path);

// Decodes text as Zemax and Windows tools write it, returned as valid UTF-8: UTF-16LE/BE with a BOM
// (or without one, recognised by the zero byte in every pair of mostly-ASCII text), UTF-8 with or
// without a BOM, and otherwise (bytes that are not UTF-8) "ANSI": Windows-1252, whose printable
// characters include ISO-8859-1's (OpticStudio writes all three). Throws FileError(file) on a
// malformed UTF-16 sequence.
std::string decode_text(std::string_view bytes, const std::string& file_name);


// A display form of user text for messages: at most `max_length` bytes, then "...", so that a
// megabyte "keyword" from a garbage file does not become a megabyte error message.
std::string shown_text(std::string_view text, std::size_t max_length = 32);

// Whether the bytes are well-formed UTF-8 (RFC 3629: no overlong forms, surrogates or code points
// above U+10FFFF).
bool is_valid_utf8(std::string_view bytes);

// The one rule for outputs: never an input. Throws UsageError (the command line's fault, exit 2) when
// `output` names the same file as one of `inputs` (the same file on disk when both exist, else the same
// normalised absolute path).
void ensure_not_an_input(const std::filesystem::path& output, const std::vector<std::filesystem::path>& inputs);
// Throws IoError when `output` cannot be written where it is: its folder does not exist, or it is a
// folder. Checked before a long computation, so that it does not end in a failed write.
void ensure_writable_location(const std::filesystem::path& output);

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
