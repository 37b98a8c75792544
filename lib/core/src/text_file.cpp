#include "lensmith/core/text_file.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <system_error>

#include "lensmith/core/errors.h"
#include "lensmith/core/termination_cleanup.h"

namespace lensmith {

std::string read_file_bytes(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw IoError(path + ": is a directory, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(path + ": cannot open for reading");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw IoError(path + ": read error");
  return buffer.str();
}

namespace {

void append_utf8(std::string& out, char32_t cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (cp >> 18));
    out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}

std::string decode_utf16(std::string_view bytes, bool little_endian, const std::string& file_name) {
  if (bytes.size() % 2 != 0) {
    throw LensFileError({file_name, 0, 0}, "UTF-16 text has an odd number of bytes (truncated file?)");
  }
  std::string out;
  out.reserve(bytes.size() / 2);
  int line = 1;
  auto unit_at = [&](std::size_t i) -> char16_t {
    const auto lo = static_cast<unsigned char>(bytes[little_endian ? i : i + 1]);
    const auto hi = static_cast<unsigned char>(bytes[little_endian ? i + 1 : i]);
    return static_cast<char16_t>(lo | (hi << 8));
  };
  for (std::size_t i = 0; i < bytes.size(); i += 2) {
    char16_t u = unit_at(i);
    char32_t cp = u;
    if (u >= 0xD800 && u <= 0xDBFF) {
      if (i + 3 >= bytes.size()) throw LensFileError({file_name, line, 0}, "UTF-16 surrogate pair cut off at end of file");
      char16_t lo = unit_at(i + 2);
      if (lo < 0xDC00 || lo > 0xDFFF) throw LensFileError({file_name, line, 0}, "malformed UTF-16 surrogate pair");
      cp = 0x10000 + ((static_cast<char32_t>(u) - 0xD800) << 10) + (lo - 0xDC00);
      i += 2;
    } else if (u >= 0xDC00 && u <= 0xDFFF) {
      throw LensFileError({file_name, line, 0}, "malformed UTF-16: lone low surrogate");
    }
    if (cp == U'\n') ++line;
    append_utf8(out, cp);
  }
  return out;
}

}  // namespace

std::string decode_text(std::string_view bytes, const std::string& file_name) {
  if (bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0xFF && static_cast<unsigned char>(bytes[1]) == 0xFE) {
    return decode_utf16(bytes.substr(2), true, file_name);
  }
  if (bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0xFE && static_cast<unsigned char>(bytes[1]) == 0xFF) {
    return decode_utf16(bytes.substr(2), false, file_name);
  }
  if (bytes.size() >= 3 && static_cast<unsigned char>(bytes[0]) == 0xEF && static_cast<unsigned char>(bytes[1]) == 0xBB &&
      static_cast<unsigned char>(bytes[2]) == 0xBF) {
    return std::string(bytes.substr(3));
  }
  return std::string(bytes);
}

void write_atomically(const std::string& path, const std::string& extension,
                      const std::function<void(const std::string& temporary_path)>& write) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  // Hidden and unique, so a crash leaves no half-written file under the final name.
  std::random_device rd;
  // Built with append: GCC 12 warns (-Wrestrict, a false positive) on "." + std::string.
  std::string name(".");
  name += target.filename().string();
  name += ".tmp";
  name += std::to_string(rd());
  name += extension;
  const fs::path temp = dir / name;
  const TemporaryFileGuard removed_if_stopped(temp.string());  // SIGTERM mid-write leaves nothing
  try {
    write(temp.string());
  } catch (...) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw;
  }
  std::error_code ec;
  fs::rename(temp, target, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw IoError(path + ": cannot rename temporary file into place: " + ec.message());
  }
}

void write_file_atomically(const std::string& path, std::string_view contents) {
  write_atomically(path, "", [&](const std::string& temp) {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) throw IoError(path + ": cannot create temporary file " + temp);
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.flush();
    if (!out) throw IoError(path + ": write failed (disk full?)");
  });
}

}  // namespace lensmith
