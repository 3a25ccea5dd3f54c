// V3: the saturated v-p_w scheme in small deformation (method-notes §5.3): V1's stages with the
// pore-pressure gradient in the stress points' half step, and the pressure stage after step 2:
//   0. (consistent storage rate, before the first step only) the initial nodal divergence D v^0
//   1. stress points: half step with -grad p^n / rho
//   2. nodes: v*, sigma' (effective stress), displacement (and tr d, for the storage equation)
//   3. prescribed components (total stresses: sigma' = sigma + p_w)
//   4. pressure: the storage equation by PCG, v^{n+1} = v* - (dt/rho) grad p^{n+1}
//   5. prescribed components (then, consistent storage rate, D v^{n+1}); the velocity filter and
//      the prescribed components again.
// With rigid bodies (2D, method-notes §4.6): their velocities at t^{n+1} before 3 without the
// pore pressure, whose part the pressure stage adds (implicit); offsets and reactions last.
#include <memory>

#include "schemes/pressure_stage.hpp"
#include "schemes/plate_stages.hpp"
#include "schemes/registry.hpp"
#include "schemes/staggered_stages.hpp"

namespace rktsph {

template <int Dim>
std::unique_ptr<Scheme> make_v3_scheme(StaggeredModel<Dim>& model) {
  auto scheme = std::make_unique<Scheme>("v3");
  auto pressure = std::make_unique<PorePressureStage<Dim>>(model);
  PorePressureGradient<Dim> gradient;
  gradient.pressure = model.nodes.view(pressure->pore_pressure()).data();
  gradient.skeleton = pressure->skeleton_velocity();
  auto sources = std::make_shared<ViscoplasticSources<Dim>>(model);
  const bool consistent = pressure->volumetric_rate() != nullptr;
  if (consistent) scheme->add(std::make_unique<RecordNodeDivergence<Dim>>(*pressure, true));
  scheme->add(std::make_unique<StressPointHalfStep<Dim, PorePressureGradient<Dim>>>(model, sources, gradient));
  auto node_step = std::make_unique<NodeFullStep<Dim>>(model, sources);
  node_step->record_volumetric_rate(pressure->volumetric_rate());
  scheme->add(std::move(node_step));
  if constexpr (Dim == 2) {
    if (model.plates) scheme->add(std::make_unique<DriveRigidPlates>(model));
  }
  scheme->add(std::make_unique<ApplyConstraints<Dim>>(model));
  PorePressureStage<Dim>& stage = scheme->add(std::move(pressure));
  scheme->add(std::make_unique<ApplyConstraints<Dim>>(model));
  if (consistent) scheme->add(std::make_unique<RecordNodeDivergence<Dim>>(stage, false));
  if (model.setup.filter) {
    scheme->add(std::make_unique<VelocityFilter<Dim>>(model, model.setup.filter_strength));
    scheme->add(std::make_unique<ApplyConstraints<Dim>>(model));
  }
  if constexpr (Dim == 2) {
    if (model.plates) scheme->add(std::make_unique<FinishRigidPlates>(model));
  }
  // The fluid's stored energy p^2/(2 Q*) per unit volume joins the energy account, and the
  // growth guard names the undrained Courant limit when it applies.
  const double inv_storage = stage.inverse_storage();
  const double* pw = model.nodes.view(stage.pore_pressure()).data();
  scheme->stored_energy_density = [inv_storage, pw](Index i) {
    return inv_storage * pw[static_cast<std::size_t>(i)] * pw[static_cast<std::size_t>(i)];
  };
  scheme->instability_hint = [&stage] { return stage.instability_hint(); };
  return scheme;
}

template std::unique_ptr<Scheme> make_v3_scheme<1>(StaggeredModel<1>&);
template std::unique_ptr<Scheme> make_v3_scheme<2>(StaggeredModel<2>&);
template std::unique_ptr<Scheme> make_v3_scheme<3>(StaggeredModel<3>&);

}  // namespace rktsph
