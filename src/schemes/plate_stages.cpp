#include "schemes/plate_stages.hpp"

namespace rktsph {

namespace {
ConstFieldView<double, RigidPlates::NS> nodal_stress(const StaggeredModel<2>& m) {
  const auto s = m.nodes.view(m.fields.stress);
  return {s.data(), s.size(), RigidPlates::NS};
}
}  // namespace

void DriveRigidPlates::run(const StepContext& c) {
  m_.plates->drive(c.t, c.dt, c.damping, nodal_stress(m_));
}

void FinishRigidPlates::run(const StepContext& c) {
  const double* pw = m_.fields.pore_pressure.valid() ? m_.nodes.view(m_.fields.pore_pressure).data() : nullptr;
  m_.plates->finish(c.dt, nodal_stress(m_), pw);
}

std::vector<std::pair<std::string, double>> FinishRigidPlates::report() const {
  std::vector<std::pair<std::string, double>> out;
  for (const RigidPlates::Plate& p : m_.plates->plates()) add_body_report(p.spec.name, p.state, out);
  return out;
}

std::string FinishRigidPlates::csv_rows(double t) const {
  std::string rows;
  for (const RigidPlates::Plate& p : m_.plates->plates()) rows += body_csv_row(t, p.spec.name, p.state);
  return rows;
}

}  // namespace rktsph
