// A process stopped while writing an output leaves nothing behind (termination_cleanup.h).
#include <catch2/catch.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>

#include "lensmith/core/termination_cleanup.h"
#include "lensmith/core/text_file.h"

namespace fs = std::filesystem;

namespace {

// Runs `body` in a child process and returns its wait status.
template <typename Body>
int in_child(Body body) {
  const pid_t pid = fork();
  if (pid == 0) {
    body();
    _exit(0);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return status;
}

}  // namespace

TEST_CASE("SIGTERM while an output is half written removes its temporary file and ends the process by the signal",
          "[core][termination]") {
  const fs::path dir = fs::temp_directory_path() / ("lensmith_termination_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string target = (dir / "frame.1001.exr").string();
  // The child writes half a file, then is told to stop (as scancel does), inside the write.
  const int status = in_child([&] {
    lensmith::remove_temporaries_on_termination();
    lensmith::write_atomically(target, ".exr", [](const std::string& temporary) {
      std::ofstream(temporary) << "half a frame";
      std::raise(SIGTERM);
    });
  });
  REQUIRE(WIFSIGNALED(status));
  CHECK(WTERMSIG(status) == SIGTERM);  // the parent (a shell, Slurm) still sees which signal
  CHECK(fs::is_empty(dir));            // neither the frame nor its temporary file
  fs::remove_all(dir);
}

TEST_CASE("without the handlers a stopped write leaves only a hidden temporary file, never the output's name", "[core][termination]") {
  // The rename is what keeps a partial file off the output's name; the handlers only tidy up.
  const fs::path dir = fs::temp_directory_path() / ("lensmith_termination_plain_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string target = (dir / "frame.exr").string();
  const int status = in_child([&] {
    lensmith::write_atomically(target, ".exr", [](const std::string& temporary) {
      std::ofstream(temporary) << "half a frame";
      std::signal(SIGTERM, SIG_DFL);
      std::raise(SIGTERM);
    });
  });
  REQUIRE(WIFSIGNALED(status));
  CHECK_FALSE(fs::exists(target));
  int hidden = 0;
  for (const auto& entry : fs::directory_iterator(dir)) hidden += entry.path().filename().string().rfind(".frame.exr.tmp", 0) == 0;
  CHECK(hidden == 1);
  fs::remove_all(dir);
}
