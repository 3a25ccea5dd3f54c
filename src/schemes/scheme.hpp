#pragma once
// A scheme: an ordered list of stages that together advance one time step, with the hooks a
// stage may add to the step's bookkeeping (energy, instability hints). Schemes are made by name
// and dimension through schemes/registry.hpp.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "schemes/stage.hpp"

namespace rktsph {

class Scheme {
 public:
  explicit Scheme(std::string name) : name_(std::move(name)) {}

  const std::string& name() const { return name_; }

  /// Append a stage; returns it (typed) so the factory can keep a handle.
  template <class S>
  S& add(std::unique_ptr<S> stage) {
    S& ref = *stage;
    stages_.push_back(std::move(stage));
    return ref;
  }
  const std::vector<std::unique_ptr<Stage>>& stages() const { return stages_; }

  /// The first stage of type S, or nullptr.
  template <class S>
  S* find() const {
    for (const auto& s : stages_) {
      if (auto* p = dynamic_cast<S*>(s.get())) return p;
    }
    return nullptr;
  }

  /// One step: every stage in order.
  void run(const StepContext& context) {
    for (auto& s : stages_) s->run(context);
  }

  /// Tell every stage that the particle sets were reordered (Stage::reordered).
  void reordered(const Reordering& reordering) {
    for (auto& s : stages_) s->reordered(reordering);
  }

  std::size_t scratch_bytes() const {
    std::size_t b = 0;
    for (const auto& s : stages_) b += s->scratch_bytes();
    return b;
  }

  /// Energy stored per node besides the elastic strain energy (J/m^Dim; V3: the fluid's
  /// p^2/(2 Q*)), added to the strain-energy density of node i. Empty: none.
  std::function<double(Index)> stored_energy_density;
  /// Power of loads outside the particle sets on the body, W (V2: the rigid bodies' contact
  /// tractions), added to the boundary power of the energy account. Empty: none.
  std::function<double()> extra_power;
  /// Kinetic energy of velocity components prescribed outside the lattice constraints, J (V2:
  /// the contact nodes' components the bodies set), for the growth guard. Empty: none.
  std::function<double()> extra_imposed_kinetic;
  /// A hint appended to the growth guard's message (V3: the undrained Courant limit). Empty: none.
  std::function<std::string()> instability_hint;

 private:
  std::string name_;
  std::vector<std::unique_ptr<Stage>> stages_;
};

}  // namespace rktsph
