#pragma once
// V2's first regularisation (method-notes §5.2, "Regularisation"): the stress points re-seeded
// from the node cloud (particles/reseed.hpp) at the start of a step, before the operators are
// rebuilt, when the two sets have drifted apart or every solver.reseed_interval steps.
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "particles/reseed.hpp"
#include "schemes/moving_operators.hpp"
#include "schemes/stage.hpp"
#include "schemes/staggered_model.hpp"

namespace rktsph {

template <int Dim>
class ReseedStressPoints final : public Stage {
 public:
  /// `excluded`: cell centres that get no stress point (inside a rigid body); may be empty.
  ReseedStressPoints(StaggeredModel<Dim>& model, std::function<bool(const double*)> excluded);
  std::string_view name() const override { return "reseed_stress_points"; }
  void run(const StepContext& context) override;
  void save(io::StateArchive& archive, const std::string& prefix) const override;
  void load(const io::StateArchive& archive, const std::string& prefix) override;
  std::vector<std::pair<std::string, double>> report() const override {
    return {{"reseeds", static_cast<double>(reseeds_)},
            {"reseed_first_time", first_time_},
            {"reseed_last_time", last_time_},
            {"stress_points_now", static_cast<double>(m_.stress_points.size())},
            {"uncovered_particles_last_check", static_cast<double>(uncovered_)}};
  }

  /// Eq. (5.2.4): the particles of either set whose nearest particle of the other set (within
  /// the operators' supports) is farther than solver.reseed_distance * dx; a particle with
  /// none in its support counts too.
  Index uncovered() const;
  /// With V2's operators on the fly the rows are not stored: uncovered() reads the steps'
  /// candidate lists cut back to the support instead.
  void set_moving_operators(const MovingOperators<Dim>* moving) { moving_ = moving; }
  /// At the end of a step (stage ReseedCheck), on the operators of the step and the positions
  /// at its end, as the next step starts: whether that step re-seeds ("auto"). The decision is
  /// kept in checkpoints, so that a resumed run decides as the uninterrupted one.
  void check();
  long reseeds() const { return reseeds_; }
  /// When the first re-seeding happened, s (-1: none yet).
  double first_time() const { return first_time_; }

 private:
  void reseed(double t);

  StaggeredModel<Dim>& m_;
  const MovingOperators<Dim>* moving_ = nullptr;
  ReseedOptions options_;
  std::int64_t next_global_id_ = 0;
  long reseeds_ = 0;
  long steps_since_ = 0;
  // The uncovered count of the case's own arrangement (after the first step) or just after the
  // last re-seeding (particles the lattice cannot cover: detached nodes): only more than these
  // triggers another (-1: to be measured).
  Index baseline_ = -1;
  Index uncovered_ = 0;
  bool pending_ = false;  // the next step re-seeds
  double first_time_ = -1.0, last_time_ = -1.0;
};

/// The end-of-step half of ReseedStressPoints ("auto"): see ReseedStressPoints::check().
template <int Dim>
class ReseedCheck final : public Stage {
 public:
  explicit ReseedCheck(ReseedStressPoints<Dim>& reseed) : reseed_(reseed) {}
  std::string_view name() const override { return "reseed_check"; }
  void run(const StepContext&) override { reseed_.check(); }

 private:
  ReseedStressPoints<Dim>& reseed_;
};

}  // namespace rktsph
