#pragma once
// A stage: one named part of a time step, acting on the particle sets and operators of a model
// (docs/architecture.md, "Schemes and stages"). A scheme is an ordered list of stages
// (schemes/scheme.hpp); the stages of V1 are reused by V3 and by any scheme registered later.
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "particles/permutation.hpp"

namespace rktsph {
namespace io {
class StateArchive;
}

/// What every stage of a step t^n -> t^{n+1} is told.
struct StepContext {
  double t = 0.0;        // t^n, s
  double dt = 0.0;       // s
  double damping = 0.0;  // velocity damping coefficient in force over the step, 1/s
};

class Stage {
 public:
  virtual ~Stage() = default;
  Stage() = default;
  Stage(const Stage&) = delete;
  Stage& operator=(const Stage&) = delete;

  /// A short name for logs and profiles, e.g. "stress_points_half_step".
  virtual std::string_view name() const = 0;
  virtual void run(const StepContext& context) = 0;
  /// Bytes of work space the stage holds (counted with the state).
  virtual std::size_t scratch_bytes() const { return 0; }
  /// State the stage carries from one step to the next beyond the particle fields (a solver's
  /// warm start, statistics), saved in checkpoints under `prefix` and restored on resume so
  /// that the run continues bit for bit. Most stages have none.
  virtual void save(io::StateArchive& /*archive*/, const std::string& /*prefix*/) const {}
  virtual void load(const io::StateArchive& /*archive*/, const std::string& /*prefix*/) {}
  /// Follow a reordering of the particle sets (V2 sorts them by cell at its neighbour searches;
  /// a resume restores the checkpoint's order), after the model has moved the particles and
  /// their fields: whatever the stage keeps per particle, or by particle index, from one step
  /// to the next moves with it. Most stages keep nothing of the kind.
  virtual void reordered(const Reordering& /*reordering*/) {}
  /// Figures for the log and summary.json (counts, seconds), by name; most stages have none.
  virtual std::vector<std::pair<std::string, double>> report() const { return {}; }
};

}  // namespace rktsph
