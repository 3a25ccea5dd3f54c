#include "schemes/reseed_stage.hpp"

#include <algorithm>
#include <atomic>
#include <limits>

#include <fmt/format.h>

#include "io/state_archive.hpp"

namespace rktsph {

template <int Dim>
ReseedStressPoints<Dim>::ReseedStressPoints(StaggeredModel<Dim>& model, std::function<bool(const double*)> excluded)
    : m_(model) {
  options_.dx = model.lattice.dx > 0.0 ? model.lattice.dx : model.dx();
  options_.fill = model.setup.reseed_fill;
  options_.cover = model.setup.reseed_cover;
  options_.excluded = std::move(excluded);
  for (const std::int64_t id : model.stress_points.global_id) next_global_id_ = std::max(next_global_id_, id + 1);
  for (const std::int64_t id : model.nodes.global_id) next_global_id_ = std::max(next_global_id_, id + 1);
}

template <int Dim>
Index ReseedStressPoints<Dim>::uncovered() const {
  const double limit = m_.setup.reseed_distance * m_.dx();
  const double limit2 = limit * limit;
  // rows(a, f) calls f(b) for each source b of row a.
  auto count = [this, limit2](Index targets, const std::vector<Vec<Dim>>& x, const std::vector<Vec<Dim>>& y,
                              auto&& rows) {
    // An integer sum: the same whatever the threads' order.
    std::atomic<Index> n{0};
    exec::particle_for(m_.policy, targets, [&](Index a) {
      double nearest = std::numeric_limits<double>::infinity();
      rows(a, [&](Index b) {
        nearest = std::min(nearest, (x[static_cast<std::size_t>(a)] - y[static_cast<std::size_t>(b)]).squaredNorm());
      });
      if (nearest > limit2) n.fetch_add(1, std::memory_order_relaxed);
    });
    return n.load();
  };
  const auto& xn = m_.nodes.position;
  const auto& xs = m_.stress_points.position;
  if (moving_ != nullptr && moving_->on_the_fly) {
    // The candidates within the support at the positions now: the same nearest particle as the
    // rows of the step (reseed_distance <= 2 dx lies inside the support by more than a step's
    // motion).
    const double r2 = moving_->r2;
    auto within = [r2](const Relation<Dim>& rel, const std::vector<Vec<Dim>>& x, const std::vector<Vec<Dim>>& y) {
      return [&rel, &x, &y, r2](Index a, auto&& f) {
        for (const Index b : rel.row(a)) {
          if ((x[static_cast<std::size_t>(a)] - y[static_cast<std::size_t>(b)]).squaredNorm() < r2) f(b);
        }
      };
    };
    return count(m_.nodes.size(), xn, xs, within(*moving_->stress_points_near_nodes, xn, xs)) +
           count(m_.stress_points.size(), xs, xn, within(*moving_->nodes_near_stress_points, xs, xn));
  }
  auto stored = [](const CorrectedOperator<Dim>& op) {
    return [&op](Index a, auto&& f) {
      const auto row = op.row(a);
      for (Index k = row.begin; k < row.end; ++k) f(op.source(row, k));
    };
  };
  // The operators of the step just ended; the particles have moved since by a fraction of dx,
  // well inside the margin between the limit and the support.
  return count(m_.to_nodes.rows(), xn, xs, stored(m_.to_nodes)) +
         count(m_.to_stress_points.rows(), xs, xn, stored(m_.to_stress_points));
}

template <int Dim>
void ReseedStressPoints<Dim>::reseed(double t) {
  // Polygons and particle files carry no lattice of their own: the case's (geometry.origin),
  // through which polygons are discretised.
  const Vec<Dim> origin = m_.lattice.dx > 0.0 ? m_.lattice.origin : m_.setup.origin;
  reseed_stress_points<Dim>(m_.nodes, origin, options_, m_.stress_points, next_global_id_);
  m_.stress_points_changed();
  ++reseeds_;
  if (first_time_ < 0.0) first_time_ = t;
  last_time_ = t;
  steps_since_ = 0;
  baseline_ = -1;
}

template <int Dim>
void ReseedStressPoints<Dim>::run(const StepContext& c) {
  ++steps_since_;
  if (m_.setup.reseed == ReseedSetting::periodic) {
    if (steps_since_ >= m_.setup.reseed_interval) reseed(c.t);
    return;
  }
  if (pending_) {
    pending_ = false;
    reseed(c.t);
  }
}

template <int Dim>
void ReseedStressPoints<Dim>::check() {
  if (m_.setup.reseed != ReseedSetting::automatic) return;
  // Just after a re-seeding: the count the lattice cannot help (detached nodes).
  if (baseline_ < 0) {
    baseline_ = uncovered();
    uncovered_ = baseline_;
    return;
  }
  if (steps_since_ + 1 < m_.setup.reseed_interval) return;
  uncovered_ = uncovered();
  pending_ = uncovered_ > baseline_;
}

template <int Dim>
void ReseedStressPoints<Dim>::save(io::StateArchive& a, const std::string& prefix) const {
  a.put_integer(prefix + "next_global_id", next_global_id_);
  a.put_integer(prefix + "reseeds", reseeds_);
  a.put_integer(prefix + "steps_since", steps_since_);
  a.put_integer(prefix + "baseline", baseline_);
  a.put_integer(prefix + "uncovered", uncovered_);
  a.put_integer(prefix + "pending", pending_ ? 1 : 0);
  a.put(prefix + "first_time", first_time_);
  a.put(prefix + "last_time", last_time_);
}

template <int Dim>
void ReseedStressPoints<Dim>::load(const io::StateArchive& a, const std::string& prefix) {
  next_global_id_ = a.integer(prefix + "next_global_id");
  reseeds_ = static_cast<long>(a.integer(prefix + "reseeds"));
  steps_since_ = static_cast<long>(a.integer(prefix + "steps_since"));
  baseline_ = static_cast<Index>(a.integer(prefix + "baseline"));
  uncovered_ = static_cast<Index>(a.integer(prefix + "uncovered"));
  pending_ = a.integer(prefix + "pending") != 0;
  first_time_ = a.number(prefix + "first_time");
  last_time_ = a.number(prefix + "last_time");
  // The checkpoint's stress points replaced the case's (schemes/simulation_state.cpp).
  if (reseeds_ > 0) m_.stress_points_changed();
}

template class ReseedStressPoints<1>;
template class ReseedStressPoints<2>;
template class ReseedStressPoints<3>;

}  // namespace rktsph
