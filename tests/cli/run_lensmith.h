// Runs the lensmith binary as a user would, for the CLI tests: stdout, stderr and the exit code.
#pragma once

#include <catch2/catch.hpp>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace lensmith::testing {

// A folder for a test's files under the system's temporary folder, named after the test process,
// emptied when made and removed with what is in it when the test ends (ctest runs every test case
// as a process of its own: folders left behind piled up by the hundred).
class ScratchFolder {
 public:
  explicit ScratchFolder(const std::string& prefix)
      : dir(std::filesystem::temp_directory_path() / (prefix + std::to_string(::getpid()))) {
    std::error_code ignored;
    std::filesystem::remove_all(dir, ignored);
    std::filesystem::create_directories(dir);
  }
  ~ScratchFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(dir, ignored);
  }
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;
  // A file in the folder, written with `text` unless that is empty.
  std::string file(const std::string& name, const std::string& text = "") const {
    const std::filesystem::path p = dir / name;
    if (!text.empty()) std::ofstream(p) << text;
    return p.string();
  }
  const std::filesystem::path dir;
};

struct CommandResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

// Runs the lensmith binary with `args` (shell-quoted by the caller), capturing stdout and stderr.
inline CommandResult run_lensmith(const std::string& args) {
  namespace fs = std::filesystem;
  const fs::path err_file = fs::temp_directory_path() / ("lensmith_cli_test_" + std::to_string(::getpid()) + ".err");
  const std::string command = std::string(LENSMITH_CLI_PATH) + " " + args + " 2>" + err_file.string();
  CommandResult result;
  FILE* pipe = ::popen(command.c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::array<char, 4096> buffer{};
  std::size_t n = 0;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) result.out.append(buffer.data(), n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream err(err_file);
  result.err.assign(std::istreambuf_iterator<char>(err), std::istreambuf_iterator<char>());
  fs::remove(err_file);
  return result;
}

}  // namespace lensmith::testing
