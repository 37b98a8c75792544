// An output replaces what is at its name in one step, and only a file (text_file.h, write_atomically).
#include <catch2/catch.hpp>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "lensmith/core/errors.h"
#include "lensmith/core/text_file.h"

namespace fs = std::filesystem;

namespace {

std::string contents(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A fresh, empty folder for one test, removed when it ends.
struct Folder {
  fs::path path;
  explicit Folder(const std::string& name) : path(fs::temp_directory_path() / (name + "_" + std::to_string(getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~Folder() { fs::remove_all(path); }
  int entries() const { return static_cast<int>(std::distance(fs::directory_iterator(path), fs::directory_iterator())); }
};

}  // namespace

TEST_CASE("an output written over an existing file replaces it and leaves no other file behind", "[core][write]") {
  const Folder dir("lensmith_write_over");
  const fs::path target = dir.path / "frame.exr";
  std::ofstream(target) << "the previous render, longer than the new one";
  lensmith::write_file_atomically(target.string(), "new");
  CHECK(contents(target) == "new");
  CHECK(dir.entries() == 1);  // neither the old file under the temporary name nor the temporary file
  // Again, over the file just written (the case a render re-run to the same name meets).
  lensmith::write_file_atomically(target.string(), "newer");
  CHECK(contents(target) == "newer");
  CHECK(dir.entries() == 1);
}

TEST_CASE("an output written where nothing is makes the file", "[core][write]") {
  const Folder dir("lensmith_write_new");
  const fs::path target = dir.path / "frame.exr";
  lensmith::write_file_atomically(target.string(), "first");
  CHECK(contents(target) == "first");
  CHECK(dir.entries() == 1);
}

TEST_CASE("an output written over a symbolic link replaces the link and leaves the file it named alone", "[core][write]") {
  // As a rename onto the link does: the name now holds the output.
  const Folder dir("lensmith_write_link");
  const fs::path named = dir.path / "elsewhere.exr", target = dir.path / "frame.exr";
  std::ofstream(named) << "kept";
  fs::create_symlink(named, target);
  lensmith::write_file_atomically(target.string(), "new");
  CHECK_FALSE(fs::is_symlink(target));
  CHECK(contents(target) == "new");
  CHECK(contents(named) == "kept");
  CHECK(dir.entries() == 2);
}

TEST_CASE("an output whose name is a folder is refused and the folder and its contents stay", "[core][write]") {
  const Folder dir("lensmith_write_folder");
  const fs::path target = dir.path / "frame.exr";
  fs::create_directories(target);
  std::ofstream(target / "inside.txt") << "kept";
  CHECK_THROWS_AS(lensmith::write_file_atomically(target.string(), "new"), lensmith::IoError);
  CHECK(fs::is_directory(target));
  CHECK(contents(target / "inside.txt") == "kept");
  CHECK(dir.entries() == 1);  // no temporary file left
}
