// Initial velocity fields (case/initial_velocity.hpp). Expressions are parsed by muparser,
// once per entry, so a field over 10^6 nodes costs one bytecode evaluation per node.
#include "case/initial_velocity.hpp"

#include <cmath>

#include <fmt/format.h>
#include <muParser.h>
#include <Eigen/Geometry>

#include "core/error.hpp"

namespace rktsph {

namespace {

/// One parser bound to the variables x, y, z of `position` (as many as the dimension).
std::unique_ptr<mu::Parser> make_parser(const std::string& expression, int dim, std::array<double, 3>& position) {
  auto p = std::make_unique<mu::Parser>();
  p->DefineVar("x", &position[0]);
  if (dim >= 2) p->DefineVar("y", &position[1]);
  if (dim >= 3) p->DefineVar("z", &position[2]);
  p->SetExpr(expression);
  return p;
}

}  // namespace

void check_position_expression(const std::string& expression, int dim, const std::string& where) {
  std::array<double, 3> position{0.0, 0.0, 0.0};
  double value = 0.0;
  try {
    auto p = make_parser(expression, dim, position);
    value = p->Eval();
  } catch (const mu::Parser::exception_type& e) {
    throw InputError(fmt::format("{}: cannot evaluate '{}': {} (variables: {}; constants _pi, _e)", where, expression,
                                 e.GetMsg(),
                                 dim == 1   ? "x"
                                 : dim == 2 ? "x, y"
                                            : "x, y, z"));
  }
  if (!std::isfinite(value)) {
    throw InputError(fmt::format("{}: '{}' is not finite at x = 0", where, expression));
  }
}

template <int Dim>
struct InitialVelocityField<Dim>::Compiled {
  mutable std::array<double, 3> position{0.0, 0.0, 0.0};
  std::array<std::unique_ptr<mu::Parser>, Dim> parsers;
};

template <int Dim>
InitialVelocityField<Dim>::InitialVelocityField(const std::vector<InitialVelocitySpec<Dim>>& specs) : specs_(specs) {
  for (const auto& s : specs_) {
    auto c = std::make_unique<Compiled>();
    for (int d = 0; d < Dim; ++d) {
      const auto& e = s.expression[static_cast<std::size_t>(d)];
      if (!e.empty()) c->parsers[static_cast<std::size_t>(d)] = make_parser(e, Dim, c->position);
    }
    compiled_.push_back(std::move(c));
  }
}

template <int Dim>
InitialVelocityField<Dim>::~InitialVelocityField() = default;

template <int Dim>
Vec<Dim> InitialVelocityField<Dim>::at(const Vec<Dim>& x, int material) const {
  for (std::size_t k = specs_.size(); k-- > 0;) {
    const auto& s = specs_[k];
    if (s.material >= 0 && s.material != material) continue;
    if (!s.region.contains(x, 0.0)) continue;
    Vec<Dim> v = s.velocity;
    if constexpr (Dim == 2) {
      if (s.angular_velocity != 0.0) {
        const Vec<Dim> r = x - s.centre;
        v[0] -= s.angular_velocity * r[1];
        v[1] += s.angular_velocity * r[0];
      }
    } else if constexpr (Dim == 3) {
      v += s.angular_velocity_vector.cross(x - s.centre);
    }
    const auto& c = *compiled_[k];
    for (int d = 0; d < Dim; ++d) c.position[static_cast<std::size_t>(d)] = x[d];
    for (int d = 0; d < Dim; ++d) {
      const auto& p = c.parsers[static_cast<std::size_t>(d)];
      if (!p) continue;
      const double value = p->Eval();
      if (!std::isfinite(value)) {
        throw InputError(fmt::format("{}: component {} of the initial velocity is {} at ({}) m", s.where,
                                     kAxisNames[static_cast<std::size_t>(d)], value,
                                     fmt::join(std::vector<double>(x.data(), x.data() + Dim), ", ")));
      }
      v[d] += value;
    }
    return v;
  }
  return Vec<Dim>::Zero();
}

template class InitialVelocityField<1>;
template class InitialVelocityField<2>;
template class InitialVelocityField<3>;

}  // namespace rktsph
