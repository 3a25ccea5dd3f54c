#pragma once
// The initial velocity field of the entries of CaseSetup::initial_velocities
// (docs/case-format.md "[initial_velocity]").
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "case/case_setup.hpp"
#include "core/types.hpp"

namespace rktsph {

/// Evaluates the entries at node positions. Compiles each expression once.
template <int Dim>
class InitialVelocityField {
 public:
  explicit InitialVelocityField(const std::vector<InitialVelocitySpec<Dim>>& specs);
  ~InitialVelocityField();
  InitialVelocityField(const InitialVelocityField&) = delete;
  InitialVelocityField& operator=(const InitialVelocityField&) = delete;

  /// The velocity of a node at x of material `material`: that of the last entry selecting it,
  /// zero when none does.
  Vec<Dim> at(const Vec<Dim>& x, int material) const;

 private:
  struct Compiled;
  std::vector<InitialVelocitySpec<Dim>> specs_;
  std::vector<std::unique_ptr<Compiled>> compiled_;
};

/// Checks an expression of position (variables x and, in 2D, y): throws InputError with
/// `where` and muparser's message when it does not parse or does not give a finite value at x.
void check_position_expression(const std::string& expression, int dim, const std::string& where);

}  // namespace rktsph
