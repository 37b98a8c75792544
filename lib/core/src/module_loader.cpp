#include "lensmith/core/module_loader.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <string>
#include <system_error>
#include <vector>

#include "lensmith/core/errors.h"

namespace lensmith {

namespace {

namespace fs = std::filesystem;

std::vector<fs::path> module_folders() {
  if (const char* dir = std::getenv("LENSMITH_MODULE_DIR"); dir != nullptr && *dir != '\0') return {fs::path(dir)};
  std::error_code ec;
  const fs::path program = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return {};
  const fs::path folder = program.parent_path();
  return {folder, (folder / LENSMITH_MODULE_RELATIVE_DIR).lexically_normal()};
}

// The table of one module, or why it could not be loaded.
struct Loaded {
  const void* table = nullptr;
  std::string failure;
};

Loaded load(const char* file, const char* entry, int abi, const char* purpose) {
  std::string tried;
  for (const fs::path& folder : module_folders()) {
    const fs::path path = folder / file;
    tried += "\n  " + path.string();
    std::error_code ec;
    if (!fs::exists(path, ec)) continue;
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
      const char* why = dlerror();
      tried += std::string(": ") + (why != nullptr ? why : "dlopen failed");
      continue;
    }
    using Entry = const void* (*)();
    const auto function = reinterpret_cast<Entry>(dlsym(handle, entry));
    const void* table = function != nullptr ? function() : nullptr;
    const int found = table != nullptr ? *static_cast<const int*>(table) : -1;
    if (found != abi) {
      tried += ": not a lensmith module of this build (ABI " + std::to_string(found) + ", expected " + std::to_string(abi) + ")";
      dlclose(handle);
      continue;
    }
    return {table, {}};  // kept loaded for the process's life
  }
  return {nullptr, std::string("lensmith's module ") + file + ", which this command needs for " + purpose +
                       ", was not found or not usable; looked for:" + tried +
                       "\nReinstall lensmith, or set LENSMITH_MODULE_DIR to the folder that holds it"};
}

}  // namespace

const void* load_module(const char* file, const char* entry, int abi, const char* purpose) {
  static std::mutex mutex;
  static std::map<std::string, Loaded> loaded;  // by file: each is tried once
  const std::lock_guard lock(mutex);
  auto it = loaded.find(file);
  if (it == loaded.end()) it = loaded.emplace(file, load(file, entry, abi, purpose)).first;
  if (it->second.table == nullptr) throw IoError(it->second.failure);
  return it->second.table;
}

}  // namespace lensmith
