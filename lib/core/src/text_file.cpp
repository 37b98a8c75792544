#include "lensmith/core/text_file.h"

#include <fcntl.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
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
    throw FileError({file_name, 0, 0}, "UTF-16 text has an odd number of bytes (truncated file?)");
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
      if (i + 3 >= bytes.size()) throw FileError({file_name, line, 0}, "UTF-16 surrogate pair cut off at end of file");
      char16_t lo = unit_at(i + 2);
      if (lo < 0xDC00 || lo > 0xDFFF) throw FileError({file_name, line, 0}, "malformed UTF-16 surrogate pair");
      cp = 0x10000 + ((static_cast<char32_t>(u) - 0xD800) << 10) + (lo - 0xDC00);
      i += 2;
    } else if (u >= 0xDC00 && u <= 0xDFFF) {
      throw FileError({file_name, line, 0}, "malformed UTF-16: lone low surrogate");
    }
    if (cp == U'\n') ++line;
    append_utf8(out, cp);
  }
  return out;
}

// Unicode of the bytes 0x80-0x9F in Windows-1252 (the WHATWG Encoding Standard's index); the five
// bytes it leaves undefined keep their ISO-8859-1 meaning (C1 controls), as browsers decode them.
// Bytes 0xA0-0xFF are U+00A0-U+00FF in both.
constexpr char32_t kWindows1252High[32] = {
    0x20AC, 0x0081, 0x201A, 0x0192, 0x201E, 0x2026, 0x2020, 0x2021, 0x02C6, 0x2030, 0x0160, 0x2039, 0x0152, 0x008D, 0x017D, 0x008F,
    0x0090, 0x2018, 0x2019, 0x201C, 0x201D, 0x2022, 0x2013, 0x2014, 0x02DC, 0x2122, 0x0161, 0x203A, 0x0153, 0x009D, 0x017E, 0x0178};

std::string decode_windows_1252(std::string_view bytes) {
  std::string out;
  out.reserve(bytes.size() + bytes.size() / 8);
  for (const char c : bytes) {
    const auto b = static_cast<unsigned char>(c);
    append_utf8(out, b >= 0x80 && b < 0xA0 ? kWindows1252High[b - 0x80] : static_cast<char32_t>(b));
  }
  return out;
}

// UTF-16 without a byte-order mark: text that is mostly ASCII has a zero byte in every pair, on the
// high byte's side, and never on the other (a sample of the first 512 bytes).
std::optional<bool> utf16_without_bom(std::string_view bytes) {
  if (bytes.size() < 4 || bytes.size() % 2 != 0) return std::nullopt;
  const std::size_t n = std::min<std::size_t>(bytes.size(), 512);
  std::size_t zero_even = 0, zero_odd = 0;
  for (std::size_t i = 0; i + 1 < n; i += 2) {
    zero_even += bytes[i] == '\0';
    zero_odd += bytes[i + 1] == '\0';
  }
  const std::size_t pairs = n / 2;
  if (zero_even == 0 && zero_odd * 2 > pairs) return true;   // little-endian: "A\0"
  if (zero_odd == 0 && zero_even * 2 > pairs) return false;  // big-endian: "\0A"
  return std::nullopt;
}

}  // namespace


std::string shown_text(std::string_view text, std::size_t max_length) {
  if (text.size() <= max_length) return std::string(text);
  return std::string(text.substr(0, max_length)) + "...";
}

bool is_valid_utf8(std::string_view bytes) {
  std::size_t i = 0;
  while (i < bytes.size()) {
    const auto b = static_cast<unsigned char>(bytes[i]);
    if (b < 0x80) {
      ++i;
      continue;
    }
    // The lead byte gives the length and the smallest code point it may encode (no overlong forms,
    // no surrogates, nothing above U+10FFFF: RFC 3629).
    std::size_t length = 0;
    char32_t cp = 0, least = 0;
    if (b >= 0xC2 && b <= 0xDF) length = 2, cp = b & 0x1F, least = 0x80;
    else if (b >= 0xE0 && b <= 0xEF) length = 3, cp = b & 0x0F, least = 0x800;
    else if (b >= 0xF0 && b <= 0xF4) length = 4, cp = b & 0x07, least = 0x10000;
    else return false;
    if (i + length > bytes.size()) return false;
    for (std::size_t k = 1; k < length; ++k) {
      const auto c = static_cast<unsigned char>(bytes[i + k]);
      if ((c & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (c & 0x3F);
    }
    if (cp < least || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    i += length;
  }
  return true;
}

std::string decode_text(std::string_view bytes, const std::string& file_name) {
  if (bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0xFF && static_cast<unsigned char>(bytes[1]) == 0xFE) {
    return decode_utf16(bytes.substr(2), true, file_name);
  }
  if (bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0xFE && static_cast<unsigned char>(bytes[1]) == 0xFF) {
    return decode_utf16(bytes.substr(2), false, file_name);
  }
  if (const std::optional<bool> little_endian = utf16_without_bom(bytes)) return decode_utf16(bytes, *little_endian, file_name);
  if (bytes.size() >= 3 && static_cast<unsigned char>(bytes[0]) == 0xEF && static_cast<unsigned char>(bytes[1]) == 0xBB &&
      static_cast<unsigned char>(bytes[2]) == 0xBF) {
    bytes.remove_prefix(3);
  }
  // Not UTF-8: OpticStudio's "ANSI" files, Windows-1252 (a superset of ISO-8859-1's printable
  // characters) on the machines that write them.
  return is_valid_utf8(bytes) ? std::string(bytes) : decode_windows_1252(bytes);
}

namespace {

// Puts the finished temporary file in place of an existing regular file (or symbolic link) at
// `target` by swapping the two names in one step (renameat2's RENAME_EXCHANGE, Linux 3.15 on), then
// removes the old file under the temporary name. A reader of `target` sees the old file or the new
// one, never neither, as with a rename onto it; but ext4 (its auto_da_alloc default) makes a rename
// onto an existing file write the new file's data out first, which held `lensmith bokeh` on a
// 600 x 400 picture for 2.7 ms of its 50 (0.6 ms of it CPU; docs/performance.md): after an
// exchange the new file is written out as a file newly made would be. Like every lensmith output
// it is not synced to disk: a power cut soon after may lose it. False (nothing done) where there
// is nothing to replace, the target is something else (a folder: rename refuses it, exchange would
// not), or the file system cannot exchange; the caller then renames.
bool replace_by_exchange(const std::filesystem::path& temp, const std::filesystem::path& target) {
  struct stat existing{};
  if (lstat(target.c_str(), &existing) != 0 || !(S_ISREG(existing.st_mode) || S_ISLNK(existing.st_mode))) return false;
  if (renameat2(AT_FDCWD, temp.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) != 0) return false;
  // The old file's name is now the temporary one: hidden, and removed at once.
  unlink(temp.c_str());
  return true;
}

}  // namespace

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
  if (replace_by_exchange(temp, target)) return;
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

namespace fs = std::filesystem;

void ensure_writable_location(const fs::path& output) {
  std::error_code ec;
  const fs::path dir = output.has_parent_path() ? output.parent_path() : fs::path(".");
  if (!fs::is_directory(dir, ec)) {
    throw IoError("cannot write " + output.string() + ": the folder " + dir.string() + " does not exist");
  }
  if (fs::is_directory(output, ec)) throw IoError("cannot write " + output.string() + ": it is a folder");
}

void ensure_not_an_input(const fs::path& output, const std::vector<fs::path>& inputs) {
  for (const fs::path& input : inputs) {
    std::error_code ec;
    bool same = false;
    if (fs::exists(output, ec) && fs::exists(input, ec)) {
      same = fs::equivalent(output, input, ec) && !ec;
    } else {
      std::error_code ec_output, ec_input;
      const fs::path a = fs::weakly_canonical(fs::absolute(output), ec_output);
      const fs::path b = fs::weakly_canonical(fs::absolute(input), ec_input);
      same = !ec_output && !ec_input && a == b;
    }
    if (same) {
      throw UsageError("output " + output.string() + " is the input " + input.string() +
                       ": lensmith never overwrites its inputs; choose another output file");
    }
  }
}

}  // namespace lensmith
