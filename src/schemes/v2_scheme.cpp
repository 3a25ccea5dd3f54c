// V2: the staggered RKT-SPH step for dry soil in large deformation (method-notes §5.2):
//   0. neighbours and operators rebuilt from the current positions (never frozen), the
//      particles sorted into Morton order of their cells before each search; in 2D and
//      3D the free surface detected and the nodal stress made traction-free on it;
//   1. stress points: half step from the nodes, with the Jaumann rotation, the continuity
//      equation and the new positions;
//   2. nodes: the stress by step 2 with the Jaumann rotation, the velocity by the simple
//      scheme (solver.velocity_update = "simple", default) or V1's step 2
//      ("taylor_galerkin"), continuity, positions and displacements;
//   3. the nodal stress filter when solver.stress_filter > 0 (method-notes eq. (2.3.4));
//      prescribed components at t^{n+1} (and V1's velocity filter with the Taylor-Galerkin
//      update only: the simple scheme has no nodal velocity mode to filter); the free
//      surface made traction-free again on the stress at t^{n+1}.
// With rigid bodies (2D, method-notes §4.5): the contact set at t^n after step 0 (its nodes are
// never flagged as free surface), the contact constraints, projections and reactions after 3.
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <utility>

#include "schemes/deactivate_stage.hpp"
#include "schemes/hourglass_control.hpp"
#include "schemes/registry.hpp"
#include "schemes/reseed_stage.hpp"
#include "schemes/shift_stage.hpp"
#include "schemes/staggered_stages.hpp"
#include "schemes/v2_stages.hpp"

namespace rktsph {

template <int Dim>
std::unique_ptr<Scheme> make_v2_scheme(StaggeredModel<Dim>& model) {
  auto scheme = std::make_unique<Scheme>("v2");
  auto sources = std::make_shared<ViscoplasticSources<Dim>>(model);
  // Sorting moves the model's tables (StaggeredModel::reorder), then every stage's.
  typename RebuildOperators<Dim>::ReorderAction reorder;
  if (model.setup.sort != SortSetting::off) {
    reorder = [&model, s = scheme.get()](const Reordering& r) {
      model.reorder(r);
      s->reordered(r);
    };
  }
  auto rebuild = std::make_unique<RebuildOperators<Dim>>(model, std::move(reorder));
  DetectFreeSurface<Dim>* surface = nullptr;
  std::shared_ptr<RigidContact> contact;
  if constexpr (Dim == 2) {
    if (!model.setup.bodies.empty()) {
      contact = std::make_shared<RigidContact>(model.setup.bodies, model.nodes.position.size(),
                                               model.stress_points.position.size(), model.dx(),
                                               [&model](int f, double t) { return model.function_value(f, t); });
    }
  }
  ReseedStressPoints<Dim>* reseed = nullptr;
  if (model.setup.reseed != ReseedSetting::off) {
    // Before the operators are rebuilt, so that they are built on the new stress points.
    std::function<bool(const double*)> excluded;
    if constexpr (Dim == 2) {
      if (contact) excluded = [contact](const double* x) { return contact->inside(Vec<2>(x[0], x[1])); };
    }
    reseed = &scheme->add(std::make_unique<ReseedStressPoints<Dim>>(model, std::move(excluded)));
  }
  auto& rebuilt = scheme->add(std::move(rebuild));
  if (reseed != nullptr) reseed->set_moving_operators(&rebuilt.moving_operators());
  if constexpr (Dim == 2) {
    if (contact) scheme->add(std::make_unique<ContactSelect>(model, rebuilt, contact));
  }
  if (model.setup.detect_free_surface) {
    auto detect = std::make_unique<DetectFreeSurface<Dim>>(model, rebuilt);
    if constexpr (Dim >= 2) {
      if (model.setup.shift != ShiftSetting::off) {
        // After the contact set (its nodes stay), before the detection on the shifted nodes.
        scheme->add(std::make_unique<ShiftNodes<Dim>>(model, rebuilt, contact.get(), &detect->corners()));
      }
    }
    surface = &scheme->add(std::move(detect));
    if constexpr (Dim == 2) surface->set_contact(contact.get());
  }
  // The operators applied on the fly or stored (solver.operators): the steps read the
  // candidates and the degenerate-row record from the rebuild stage either way.
  MovingOperators<Dim>* moving = &rebuilt.moving_operators();
  scheme->add(std::make_unique<StressPointHalfStep<Dim, NoPressureGradient, MovingParticles>>(model, sources))
      .set_moving_operators(moving);
  // The nodal stress filter (eq. (2.3.4)) on step 2's stress, source included, before the
  // prescribed components and the traction-free rotation put theirs back.
  // On the fly, steps 1 and 2 keep their rows' interpolation weights for it.
  auto add_stress_filter = [&] {
    scheme->add(std::make_unique<StressFilter<Dim>>(model, model.setup.stress_filter, model.setup.stress_filter_part))
        .set_moving_operators(moving);
  };
  if (model.setup.simple_velocity) {
    scheme->add(std::make_unique<NodeFullStep<Dim, MovingParticles, SimpleVelocity>>(model, sources))
        .set_moving_operators(moving);
    if (model.setup.stress_filter > 0.0) add_stress_filter();
    scheme->add(std::make_unique<ApplyConstraints<Dim>>(model));
  } else {
    auto& step2 = scheme->add(std::make_unique<NodeFullStep<Dim, MovingParticles, TaylorGalerkinVelocity>>(model, sources));
    step2.set_moving_operators(moving);
    if (model.setup.hourglass) {
      step2.set_hourglass(std::make_shared<HourglassControl<Dim>>(model), &rebuilt.node_neighbours());
    }
    if (model.setup.stress_filter > 0.0) add_stress_filter();
    scheme->add(std::make_unique<ApplyConstraints<Dim>>(model));
    if (model.setup.filter && !model.setup.hourglass) {
      scheme->add(std::make_unique<VelocityFilter<Dim>>(model, model.setup.filter_strength))
          .set_moving_operators(moving);
      scheme->add(std::make_unique<ApplyConstraints<Dim>>(model));
    }
  }
  if constexpr (Dim == 2) {
    if (contact) {
      scheme->add(std::make_unique<ContactEnforce>(model, contact));
      // The energy account (method-notes §4.5): the power of the contact tractions on the soil.
      scheme->extra_power = [contact, &model] {
        if (!contact->selected()) {
          contact->select_now(0.0, model.nodes.position, std::as_const(model.nodes).view(model.fields.velocity),
                              std::as_const(model.nodes).view(model.fields.stress));
        }
        return contact->power();
      };
      // The growth guard's budget: the contact nodes' components the bodies prescribe, the
      // normal one always and the tangential one where the contact sticks.
      scheme->extra_imposed_kinetic = [contact, &model] {
        return contact->imposed_kinetic(std::as_const(model.nodes).view(model.fields.velocity),
                                        [&model](Index i) { return model.nodes.mass(i); });
      };
    }
  }
  if (surface != nullptr) scheme->add(std::make_unique<SurfaceTractionFree<Dim>>(*surface));
  if (model.setup.simple_velocity && model.setup.stress_filter == 0.0) {
    // What a run of the simple scheme that goes unstable in a flow most often is
    // (docs/VALIDATION.md, Case 9); the default step damps that mode (method-notes eq. (2.6.3)).
    scheme->instability_hint = [] {
      return std::string(
          ". In a V2 flow a nodal stress mode that the stress points do not see can grow and throw nodes out "
          "under the simple scheme: solver.velocity_update = \"hourglass\" (the default) damps it "
          "(method-notes §2.6)");
    };
  }
  // Last but the re-seeding check: the particles outside the domain box frozen (and the ones
  // frozen before put back) on the step's final positions.
  if (model.setup.domain_box) scheme->add(std::make_unique<DeactivateOutside<Dim>>(model));
  if (reseed != nullptr) scheme->add(std::make_unique<ReseedCheck<Dim>>(*reseed));
  return scheme;
}

template std::unique_ptr<Scheme> make_v2_scheme<1>(StaggeredModel<1>&);
template std::unique_ptr<Scheme> make_v2_scheme<2>(StaggeredModel<2>&);
template std::unique_ptr<Scheme> make_v2_scheme<3>(StaggeredModel<3>&);

}  // namespace rktsph
