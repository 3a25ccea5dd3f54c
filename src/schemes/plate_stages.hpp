#pragma once
// Rigid bodies in the small-deformation schemes V1 and V3 (2D; bodies/plates.hpp, method-notes
// §4.6), as two stages around the prescribed components:
//   DriveRigidPlates after step 2: each body's velocity at t^{n+1} from its time function or its
//     force balance (in V3 without the pore pressure, which the pressure stage adds);
//   FinishRigidPlates at the end of the step: offsets, the reaction with the total stress at
//     t^{n+1} and its work; it keeps the bodies in checkpoints and writes bodies.csv.
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "schemes/body_output.hpp"
#include "schemes/stage.hpp"
#include "schemes/staggered_model.hpp"

namespace rktsph {

class DriveRigidPlates final : public Stage {
 public:
  explicit DriveRigidPlates(StaggeredModel<2>& model) : m_(model) {}
  std::string_view name() const override { return "rigid_bodies_drive"; }
  void run(const StepContext& context) override;

 private:
  StaggeredModel<2>& m_;
};

class FinishRigidPlates final : public Stage, public BodyOutput {
 public:
  explicit FinishRigidPlates(StaggeredModel<2>& model) : m_(model) {}
  std::string_view name() const override { return "rigid_bodies"; }
  void run(const StepContext& context) override;
  void save(io::StateArchive& archive, const std::string& prefix) const override { m_.plates->save(archive, prefix); }
  void load(const io::StateArchive& archive, const std::string& prefix) override { m_.plates->load(archive, prefix); }
  std::vector<std::pair<std::string, double>> report() const override;
  std::string csv_rows(double t) const override;
  const RigidPlates& plates() const { return *m_.plates; }

 private:
  StaggeredModel<2>& m_;
};

}  // namespace rktsph
