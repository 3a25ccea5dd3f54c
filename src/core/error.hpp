#pragma once
// Errors that reach the user. An InputError names where the bad value came from (file, line,
// key) and makes the program exit with status 2; a SolverError (instability, failed solve)
// exits with status 3 after the last good output has been kept; an IoError (a file that cannot
// be written: a full disk, a missing permission) carries the system's error text and exits
// with status 4, the output written so far kept.
#include <stdexcept>
#include <string>

namespace rktsph {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class SolverError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Exit statuses of the command line.
inline constexpr int kExitInput = 2;
inline constexpr int kExitUnstable = 3;
inline constexpr int kExitIo = 4;

}  // namespace rktsph
