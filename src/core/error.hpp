#pragma once
// Errors that reach the user. An InputError names where the bad value came from (file, line,
// key) and makes the program exit with status 2; a SolverError (instability, failed solve)
// exits with status 3 after the last good output has been kept.
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

}  // namespace rktsph
