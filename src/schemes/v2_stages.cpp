#include "schemes/v2_stages.hpp"

#include <chrono>

#include "operators/corrected_operator.hpp"

namespace rktsph {

template <int Dim>
RebuildOperators<Dim>::RebuildOperators(StaggeredModel<Dim>& model)
    : m_(model), constrained_positions_(model.constraints.constrained().size()) {}

template <int Dim>
void RebuildOperators<Dim>::run(const StepContext&) {
  const auto t0 = std::chrono::steady_clock::now();
  OperatorOptions options;
  options.share_patterns = false;
  const RelationOptions rel = operator_relation_options(m_.kernel);
  to_stress_points_.build(m_.stress_points.position, m_.nodes.position, rel, m_.policy);
  m_.to_stress_points = build_corrected_operator<Dim>(to_stress_points_, m_.stress_points.position, m_.nodes,
                                                      m_.kernel, options);
  to_nodes_.build(m_.nodes.position, m_.stress_points.position, rel, m_.policy);
  m_.to_nodes = build_corrected_operator<Dim>(to_nodes_, m_.nodes.position, m_.stress_points, m_.kernel, options);
  const auto& which = m_.constraints.constrained();
  for (std::size_t k = 0; k < which.size(); ++k) {
    constrained_positions_[k] = m_.nodes.position[static_cast<std::size_t>(which[k])];
  }
  constrained_.build(constrained_positions_, m_.stress_points.position, difference_gradient_relation_options(m_.kernel),
                     m_.policy);
  m_.constrained_gradient =
      build_difference_gradient<Dim>(constrained_, constrained_positions_, m_.stress_points, m_.kernel);
  ++rebuilds_;
  seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

template class RebuildOperators<1>;
template class RebuildOperators<2>;
template class RebuildOperators<3>;

}  // namespace rktsph
