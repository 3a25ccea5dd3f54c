#pragma once
// Shared helpers of the unit tests: temporary folders, case files written from strings, and
// running the rktsph binary.
#include <gtest/gtest.h>
#include <omp.h>
#include <unistd.h>

#include <sys/wait.h>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "case/case_reader.hpp"

namespace rktsph::test {

/// A fresh folder per test (removed at the end unless RKTSPH_KEEP_TEST_FILES is set).
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = info != nullptr ? std::string(info->test_suite_name()) + "." + info->name() : "rktsph";
    for (char& c : name) {
      if (c == '/') c = '_';
    }
    path_ = std::filesystem::temp_directory_path() / ("rktsph_test_" + std::to_string(::getpid()) + "_" + name);
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    if (std::getenv("RKTSPH_KEEP_TEST_FILES") == nullptr) {
      std::error_code ec;
      std::filesystem::remove_all(path_, ec);
    }
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

  /// Write `text` to `name` in this folder; returns the full path.
  std::string write(const std::string& name, const std::string& text) const {
    const std::string p = file(name);
    std::ofstream(p) << text;
    return p;
  }

 private:
  std::filesystem::path path_;
};

/// Read a case from a TOML string, through the public path (file -> document -> setup).
template <int Dim>
CaseSetup<Dim> case_from_string(const TempDir& dir, const std::string& toml,
                                const std::vector<std::string>& overrides = {}, const std::string& name = "case.toml") {
  const std::string path = dir.write(name, toml);
  return read_case<Dim>(load_case_document(path, overrides));
}

/// Set the OpenMP thread count for the lifetime of the guard. Solver tests run on one thread
/// unless they test threading: ctest -j runs several test processes at once, and spinning
/// OpenMP barriers on an oversubscribed machine make a 50 ms test take seconds.
class ThreadCount {
 public:
  explicit ThreadCount(int n) : previous_(omp_get_max_threads()) { omp_set_num_threads(n); }
  ~ThreadCount() { omp_set_num_threads(previous_); }
  ThreadCount(const ThreadCount&) = delete;
  ThreadCount& operator=(const ThreadCount&) = delete;

 private:
  int previous_;
};

struct CommandResult {
  int status = -1;  // exit status, or 128 + signal
  std::string out;  // stdout and stderr as requested by the command line
};

/// Run a shell command, capturing its stdout (redirect stderr with 2>&1 to get both).
inline CommandResult run_command(const std::string& command) {
  CommandResult r;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return r;
  std::array<char, 4096> buf{};
  std::size_t n = 0;
  while ((n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0) r.out.append(buf.data(), n);
  const int raw = ::pclose(pipe);
  if (WIFEXITED(raw))
    r.status = WEXITSTATUS(raw);
  else if (WIFSIGNALED(raw))
    r.status = 128 + WTERMSIG(raw);
  return r;
}

inline std::string read_text(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace rktsph::test
