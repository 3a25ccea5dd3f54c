// V1: the staggered RKT-SPH step for dry soil in small deformation (method-notes §5.1):
//   1. stress points: half step from the nodes (flux + sources), t^n -> t^{n+1/2}
//   2. nodes: full step from the stress points (flux + sources), and the displacement
//   3. prescribed components at t^{n+1}
//   4. the velocity filter (solver.filter), and the prescribed components again.
// With rigid bodies (2D, method-notes §4.6): their velocities at t^{n+1} before 3, their
// offsets and reactions after 4.
#include <memory>

#include "schemes/plate_stages.hpp"
#include "schemes/registry.hpp"
#include "schemes/staggered_stages.hpp"

namespace rktsph {

template <int Dim>
std::unique_ptr<Scheme> make_v1_scheme(StaggeredModel<Dim>& model) {
  auto scheme = std::make_unique<Scheme>("v1");
  auto sources = std::make_shared<ViscoplasticSources<Dim>>(model);
  scheme->add(std::make_unique<StressPointHalfStep<Dim>>(model, sources));
  scheme->add(std::make_unique<NodeFullStep<Dim>>(model, sources));
  if constexpr (Dim == 2) {
    if (model.plates) scheme->add(std::make_unique<DriveRigidPlates>(model));
  }
  scheme->add(std::make_unique<ApplyConstraints<Dim>>(model));
  if (model.setup.filter) {
    scheme->add(std::make_unique<VelocityFilter<Dim>>(model, model.setup.filter_strength));
    scheme->add(std::make_unique<ApplyConstraints<Dim>>(model));
  }
  if constexpr (Dim == 2) {
    if (model.plates) scheme->add(std::make_unique<FinishRigidPlates>(model));
  }
  return scheme;
}

template std::unique_ptr<Scheme> make_v1_scheme<1>(StaggeredModel<1>&);
template std::unique_ptr<Scheme> make_v1_scheme<2>(StaggeredModel<2>&);
template std::unique_ptr<Scheme> make_v1_scheme<3>(StaggeredModel<3>&);

}  // namespace rktsph
