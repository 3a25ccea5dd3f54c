#include "validation/footing_common.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "case/case_reader.hpp"
#include "core/error.hpp"
#include "schemes/simulation.hpp"
#include "schemes/v2_stages.hpp"
#include "validation/band_common.hpp"

namespace rktsph::validation {

FootingRun run_footing(const std::string& case_file, const std::vector<std::string>& overrides, double t_end,
                       double record_every, double loaded_width, double yield_stress,
                       const std::vector<double>& map_settlements, double cut_y) {
  std::vector<std::string> o = overrides;
  o.push_back(fmt::format("time.end={}", t_end));
  o.push_back("output.interval=0");
  const CaseDocument doc = load_case_document(case_file, o);
  Simulation<2> s(read_case<2>(doc));
  FootingRun out;
  out.t_end = t_end;
  out.dx = s.setup().dx;
  const auto* enforce = s.scheme().find<ContactEnforce>();
  if (enforce == nullptr || enforce->contact().state().empty())
    throw SolverError("footing validation: the case has no [[body]] (the footing)");
  const auto t0 = std::chrono::steady_clock::now();
  const auto& nodes = s.nodes();
  const auto& sps = s.stress_points();
  const auto nn = static_cast<std::size_t>(nodes.size());
  const std::vector<Vec<2>> X = nodes.position;
  // The slab: the row of stress points (by reference height) nearest cut_y; after a re-seeding
  // (solver.reseed) the row nearest it where the new stress points are.
  std::vector<std::size_t> slab;
  std::vector<std::int64_t> slab_ids;  // the slab by global id: V2 sorts its particles as they move
  std::int64_t slab_made = -1;
  long slab_sorted = s.reorders();
  auto follow_slab = [&] {
    if (slab_sorted == s.reorders()) return;
    slab.clear();
    for (std::size_t e = 0; e < sps.global_id.size(); ++e) {
      if (std::binary_search(slab_ids.begin(), slab_ids.end(), sps.global_id[e])) slab.push_back(e);
    }
    slab_sorted = s.reorders();
  };
  auto select_slab = [&] {
    const std::size_t n = sps.position.size();
    double row_y = sps.position[0][1];
    for (std::size_t e = 0; e < n; ++e) {
      if (std::abs(sps.position[e][1] - cut_y) < std::abs(row_y - cut_y)) row_y = sps.position[e][1];
    }
    slab.clear();
    for (std::size_t e = 0; e < n; ++e) {
      if (std::abs(sps.position[e][1] - row_y) < 0.25 * out.dx) slab.push_back(e);
    }
    slab_ids.clear();
    for (const std::size_t e : slab) slab_ids.push_back(sps.global_id[e]);
    std::sort(slab_ids.begin(), slab_ids.end());
    slab_made = sps.replacements();
    slab_sorted = s.reorders();
  };
  const HistoryView eps = node_history(s, "eps_vp_eq", "footing validation");
  auto record = [&] {
    const BodyState& b = enforce->contact().state()[0];
    FootingRecord r;
    r.t = s.time();
    r.settlement = -b.offset[1];
    r.force = b.force[1];
    r.shear = b.force[0];
    r.width = b.width;
    r.pressure = b.force[1] / loaded_width;
    if (slab_made != sps.replacements()) select_slab();
    follow_slab();
    const auto sig = s.stress_point_stress();
    double sum = 0.0;
    for (const std::size_t e : slab) sum += sig(e, StressComponent::yy) * sps.volume[e];
    r.cut = -sum / out.dx / loaded_width;
    r.contact_nodes = b.contact_nodes;
    r.projections = b.node_projections + b.stress_point_projections;
    out.min_gap = std::min(out.min_gap, b.min_gap);
    out.records.push_back(r);
    return r.settlement;
  };
  auto snapshot = [&] {
    FootingMap m;
    m.t = s.time();
    m.settlement = -enforce->contact().state()[0].offset[1];
    const auto u = s.node_displacement();
    const auto v = s.node_velocity();
    // In the order the case made the nodes (by global id), so that maps compare node by node.
    const std::vector<Index> node_at = s.nodes_by_id();
    for (std::size_t k = 0; k < nn; ++k) {
      const Index i = node_at[k];
      const auto iu = static_cast<std::size_t>(i);
      m.X.push_back(X[k][0]);
      m.Y.push_back(X[k][1]);
      m.x.push_back(nodes.position[iu][0]);
      m.y.push_back(nodes.position[iu][1]);
      m.ux.push_back(u(i, 0));
      m.uy.push_back(u(i, 1));
      m.vx.push_back(v(i, 0));
      m.vy.push_back(v(i, 1));
      m.eps.push_back(eps(i));
    }
    const auto sig = s.stress_point_stress();
    for (std::size_t e = 0; e < sps.position.size(); ++e) {
      m.sx.push_back(sps.position[e][0]);
      m.sy.push_back(sps.position[e][1]);
      m.flowing.push_back(sig.invariants(e).q > yield_stress ? 1 : 0);
    }
    out.maps.push_back(std::move(m));
  };
  std::size_t next_map = 0;
  const long every = std::max(1L, std::lround(record_every / s.dt()));
  record();
  try {
    while (s.time() < t_end - 1e-9) {
      s.step();
      if (s.step_count() % every != 0 && s.time() < t_end - 1e-9) continue;
      const double settlement = record();
      while (next_map < map_settlements.size() && settlement >= map_settlements[next_map] - 1e-9) {
        snapshot();
        ++next_map;
      }
    }
  } catch (const SolverError& e) {
    out.stopped = e.what();
  }
  out.t_reached = s.time();
  out.steps = s.step_count();
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

double mean_pressure(const FootingRun& r, double s0, double s1) {
  double sum = 0.0;
  int n = 0;
  for (const FootingRecord& x : r.records) {
    if (x.settlement >= s0 && x.settlement <= s1) sum += x.pressure, ++n;
  }
  return n > 0 ? sum / n : NAN;
}

double mean_cut_pressure(const FootingRun& r, double s0, double s1) {
  double sum = 0.0;
  int n = 0;
  for (const FootingRecord& x : r.records) {
    if (x.settlement >= s0 && x.settlement <= s1) sum += x.cut, ++n;
  }
  return n > 0 ? sum / n : NAN;
}

void write_footing_records(const std::string& file, const FootingRun& r) {
  std::ofstream f(file);
  f << "t,settlement,force,shear,width,pressure,cut,contact_nodes,projections\n";
  for (const FootingRecord& x : r.records) {
    f << fmt::format("{:.6g},{:.8g},{:.8g},{:.6g},{:.6g},{:.8g},{:.8g},{},{}\n", x.t, x.settlement, x.force, x.shear,
                     x.width, x.pressure, x.cut, x.contact_nodes, x.projections);
  }
}

void write_footing_maps(const std::string& file, const FootingRun& r) {
  std::ofstream f(file);
  f << "map,settlement,X,Y,x,y,ux,uy,vx,vy,eps_vp_eq\n";
  for (std::size_t k = 0; k < r.maps.size(); ++k) {
    const FootingMap& m = r.maps[k];
    for (std::size_t i = 0; i < m.x.size(); ++i) {
      f << fmt::format("{},{:.6g},{:.8g},{:.8g},{:.8g},{:.8g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g}\n", k, m.settlement,
                       m.X[i], m.Y[i], m.x[i], m.y[i], m.ux[i], m.uy[i], m.vx[i], m.vy[i], m.eps[i]);
    }
  }
}

}  // namespace rktsph::validation
