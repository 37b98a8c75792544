#include "lensmith/core/ascii_text.h"
#include "lensmith/prescription/lens_library.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <span>

#include "lensmith/core/embedded_file.h"
#include "lensmith/core/located_json.h"
#include "lensmith/prescription/lens_json.h"

namespace lensmith {

std::span<const EmbeddedFile> embedded_lenses();  // generated from lenses/*.json

namespace {

std::string id_of(std::string_view path) {
  std::string id(path);
  if (id.size() > 5 && id.ends_with(".json")) id.resize(id.size() - 5);
  return id;
}

const EmbeddedFile* find_embedded(const std::string& id) {
  for (const EmbeddedFile& f : embedded_lenses()) {
    if (id_of(f.path) == id) return &f;
  }
  return nullptr;
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

}  // namespace

std::vector<ShippedLens> LensLibrary::list() {
  std::vector<ShippedLens> lenses;
  for (const EmbeddedFile& f : embedded_lenses()) {
    // Only the metadata is needed: read it without resolving glasses.
    const LocatedJson doc = LocatedJson::parse(f.text, "lenses/" + std::string(f.path));
    const auto& root = doc.root();
    ShippedLens lens;
    lens.id = id_of(f.path);
    lens.name = root.value("name", "");
    lens.source = root.value("source", "");
    lenses.push_back(std::move(lens));
  }
  std::sort(lenses.begin(), lenses.end(), [](const ShippedLens& a, const ShippedLens& b) { return a.id < b.id; });
  return lenses;
}

bool LensLibrary::contains(const std::string& id) { return find_embedded(id) != nullptr; }

LensReadResult LensLibrary::load(const std::string& id, const GlassCatalog& catalogue) {
  if (const EmbeddedFile* f = find_embedded(id)) {
    return read_lens_json(f->text, "lenses/" + std::string(f->path), catalogue);
  }
  std::vector<std::pair<std::size_t, std::string>> ranked;
  for (const EmbeddedFile& f : embedded_lenses()) {
    const std::string candidate = id_of(f.path);
    ranked.emplace_back(edit_distance(id, candidate), candidate);
  }
  std::sort(ranked.begin(), ranked.end());
  std::string closest;
  for (std::size_t i = 0; i < ranked.size() && i < 3; ++i) closest += (i ? ", " : "") + ranked[i].second;
  throw FileError({id, 0, 0}, "no such file, and no shipped lens of that name; closest shipped lenses: " + closest +
                                      " (`lensmith lenses` lists them all)");
}

LensReadResult LensLibrary::load_path_or_name(const std::string& path_or_id, const GlassCatalog& catalogue) {
  std::error_code ec;
  const std::string file_part = path_or_id.substr(0, path_or_id.rfind('#'));
  if (std::filesystem::exists(path_or_id, ec) || std::filesystem::exists(file_part, ec)) {
    return read_lens_file(path_or_id, catalogue);
  }
  // What names a file (a folder in it, or a lens file's extension) and is not there is a missing
  // file; anything else may be a shipped lens's name.
  const std::filesystem::path file(file_part);
  const std::string extension = to_lower_ascii(file.extension().string());
  if (!find_embedded(path_or_id) &&
      (file_part.find('/') != std::string::npos || extension == ".json" || extension == ".zmx" || extension == ".dat" || extension == ".seq")) {
    throw IoError(file_part + ": no such file");
  }
  return load(path_or_id, catalogue);
}

}  // namespace lensmith
