// Glass catalogues by vendor (Schott, Ohara, Hoya, CDGM, Hikari, Sumita from the refractiveindex.info
// database, CC0; lenses/glass/README.md) and name lookup that never guesses: an unknown name is an
// error naming the closest catalogue names.
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "lensmith/glass/glass.h"

namespace lensmith {

class GlassCatalog {
 public:
  // The catalogues compiled into the library (lenses/glass/*.json), vendors in the default search
  // order: SCHOTT, OHARA, HOYA, CDGM, HIKARI, SUMITA. Built once, thread-safe.
  static const GlassCatalog& builtin();

  // Parses one catalogue in lensmith's compact JSON form (docs/glass.md). `source_name` is used in
  // error messages. Throws GlassError (or FileError with a position) on malformed input.
  static GlassCatalog from_json(std::string_view json_text, const std::string& source_name);

  // Parses a Zemax glass catalogue (.agf: NM, CD and LD records; every AGF dispersion formula,
  // 1-13, docs/glass.md), its glasses under `vendor` (OpticStudio names a catalogue by its file
  // name). `text` is decoded text (text_file.h's decode_text: AGF files are UTF-16, UTF-8 or ANSI).
  // Throws FileError at the line of a malformed record.
  static GlassCatalog from_agf(std::string_view text, const std::string& file_name, const std::string& vendor);
  // A catalogue file by its extension: .agf (vendor: the file name without extension, upper case)
  // or lensmith's .json. Throws IoError, FileError or GlassError.
  static GlassCatalog read_file(const std::string& path);
  // Adds a user's catalogue files to builtin(), searched after the shipped vendors (a lens file's
  // GCAT line names them first). LENSMITH_GLASS_CATALOGS (files or folders of .agf, separated by
  // ':') is read the same way when builtin() is first used. Call before lenses are read: not safe
  // against concurrent lookups. Throws as read_file, and GlassError for a vendor name that is
  // already present (a user's SCHOTT.agf beside the built-in SCHOTT: rename it, e.g. SCHOTT_2024).
  static void add_user_catalogs(const std::vector<std::string>& paths);

  // Appends every glass of `other`; its vendors come after the ones already present in search order.
  // Throws GlassError when a glass of `other` has the vendor and name (ignoring case) of one
  // already present, rather than letting one silently shadow the other.
  void merge(const GlassCatalog& other);

  // Looks up a glass by name, case-insensitively. With a vendor, only that vendor's catalogue is
  // searched. Without one, vendors are searched in `vendor_order` (names of vendors, e.g. from a
  // Zemax GCAT line) and then in the catalogue's default order; the first match wins.
  // Returns nullptr when nothing matches.
  const Glass* find(std::string_view name, std::string_view vendor = {},
                    std::span<const std::string> vendor_order = {}) const;

  // As find(), but throws GlassError when nothing matches, e.g.
  //   unknown glass "NBK7"; closest catalogue names: N-BK7 (SCHOTT), N-BK7HT (SCHOTT), ...
  const Glass& get(std::string_view name, std::string_view vendor = {},
                   std::span<const std::string> vendor_order = {}) const;

  // The successor of an obsolete glass name that is in no catalogue: SCHOTT renamed its glasses when
  // it made them lead- and arsenic-free (BK7 -> N-BK7, BAK1 -> N-BAK1, LAK21 -> N-LAK21); the new glass
  // has the same glass type but not exactly the old index (N-BK7 and BK7 differ by about 1e-4 in nd).
  // Returns SCHOTT's "N-" + name (or "N-" + name + "A"), or nullptr when `name` is itself in a
  // catalogue or has no such successor. Callers warn, naming both.
  const Glass* successor(std::string_view obsolete_name) const;

  // Up to `count` catalogue names closest to `name` (ignoring case, '-', ' ' and '_', then by
  // edit distance), formatted "NAME (VENDOR)"; an obsolete name's successor comes first.
  std::vector<std::string> closest_names(std::string_view name, std::size_t count = 5) const;

  // Vendors in default search order (upper case, e.g. "SCHOTT").
  const std::vector<std::string>& vendors() const { return vendors_; }
  const std::vector<Glass>& glasses() const { return glasses_; }
  std::size_t size() const { return glasses_.size(); }

 private:
  // Appends one glass, keeping the lookup tables in step. Throws GlassError on a duplicate.
  void add(Glass glass);
  // Position of `vendor_upper` in vendors_, or vendors_.size() when absent.
  std::size_t vendor_rank(std::string_view vendor_upper) const;
  // closest_names() restricted to one vendor (all vendors when `vendor_upper` is empty).
  std::vector<std::string> closest_names_at(std::string_view name, std::string_view vendor_upper,
                                            std::size_t count) const;

  std::vector<Glass> glasses_;
  std::vector<std::string> vendors_;
  // Upper-case name -> indices into glasses_, in insertion order: find() costs one hash lookup.
  std::unordered_map<std::string, std::vector<std::size_t>> by_name_;
  // Each name upper-cased without '-', ' ' and '_' (parallel to glasses_), for closest_names().
  std::vector<std::string> normalised_names_;
};

}  // namespace lensmith
