// Throughput of the V1 and V3 time steps and of the V1 set-up (neighbour search + operator assembly),
// with the memory it holds per node and a STREAM-like triad for the machine's bandwidth.
//   scripts/bench.sh            (table + bench/results/<date>-<revision>.json)
//   build/bench/rktsph_bench --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "case/case_builder.hpp"
#include "linear_solvers/pore_pressure.hpp"
#include "materials/hardening.hpp"
#include "materials/lode_form.hpp"
#include "materials/perzyna.hpp"
#include "materials/perzyna_models.hpp"
#include "materials/tensor.hpp"
#include "materials/yield_cam_clay.hpp"
#include "materials/yield_drucker_prager.hpp"
#include "materials/yield_mohr_coulomb.hpp"
#include "operators/corrected_operator.hpp"
#include "particles/reseed.hpp"
#include "schemes/pressure_stage.hpp"
#include "schemes/simulation.hpp"
#include "schemes/staggered_stages.hpp"
#include "schemes/v2_stages.hpp"

namespace {

using namespace rktsph;

// Triad bandwidth of this run, GB/s (BM_Triad is registered first, so it runs first).
double g_triad_gbs = 0.0;

// STREAM-like triad a = b + s c on arrays far larger than the caches: the bandwidth ceiling.
void BM_Triad(benchmark::State& state) {
  const std::size_t n = 1 << 25;  // 3 x 256 MiB
  std::vector<double> a(n, 0.0), b(n, 1.0), c(n, 2.0);
  const auto t0 = std::chrono::steady_clock::now();
  for (auto _ : state) {
    for (std::size_t i = 0; i < n; ++i) a[i] = b[i] + 3.0 * c[i];
    benchmark::DoNotOptimize(a.data());
    benchmark::ClobberMemory();
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double bytes = 3.0 * 8.0 * static_cast<double>(n) * static_cast<double>(state.iterations());
  g_triad_gbs = std::max(g_triad_gbs, bytes / seconds / 1e9);
  state.counters["GB/s"] = benchmark::Counter(bytes / 1e9, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Triad)->Unit(benchmark::kMillisecond)->UseRealTime();

// A square 2D elastic block with about `nodes` nodes, fixed base, loaded top (a case built in
// code, case/case_builder.hpp). `v3`: saturated, drained top, K_f = 0.1 GPa, with the odd-even
// filter strength `filter` (solver.pressure_odd_even_filter; 0 = no pressure damping).
CaseSetup<2> block_case(long nodes, bool v3 = false, double filter = 1.0, double cfl = 0.9,
                        bool implicit_faces = false) {
  const long side = static_cast<long>(std::lround(std::sqrt(static_cast<double>(nodes)))) - 1;
  const double dx = 0.1, length = static_cast<double>(side) * dx;
  CaseBuilder<2> b(fmt::format("benchmark block, {} nodes{}", nodes, v3 ? ", V3" : ""));
  b.spacing(dx)
      .block(Vec<2>(0.0, 0.0), Vec<2>(length, length))
      .elastic(2.0e7, 0.3, 2000.0)
      .fix_velocity(Region<2>::plane(1, 0.0), {0, 1})
      .prescribe_stress(Region<2>::plane(1, length), StressComponent::yy, -1.0e4)
      .time(1.0, cfl);
  if (v3) {
    FluidSpec fluid;
    fluid.porosity = 0.3;
    fluid.density = 1000.0;
    fluid.bulk_modulus = 1.0e8;
    fluid.conductivity = 1.0e-6;
    // The default pressure damping (the odd-even filter, method-notes eq. (2.4.19)) at `filter`
    // > 0; none at 0.
    fluid.filter = 0.0;
    fluid.odd_even_filter = filter;
    // The impermeable free sides in the pressure step: "auto" keeps them explicit here (C c_u/c_d
    // = 1.8); implicit_faces measures the BiCGSTAB solve of method-notes eq. (2.4.17) instead.
    if (implicit_faces) fluid.face_condition = FluidSpec::FaceCondition::implicit;
    b.scheme("v3").fluid(fluid).drained(Region<2>::plane(1, length), 0.0);
  }
  return b.build();
}

// A model of the compulsory memory traffic of one V1 step with the default velocity filter:
// per pass, the arrays it reads plus those it writes (reads and writes counted apart), each
// particle's data once (the gathers are assumed to hit the cache after a particle's first use,
// which lattice order gives). The benchmark divides it by the step time for the effective
// bandwidth.
std::size_t step_traffic_bytes(const Simulation<2>& s) {
  const auto& m = s.model();
  const auto nn = static_cast<std::size_t>(m.nodes.size());
  const auto ne = static_cast<std::size_t>(m.stress_points.size());
  constexpr std::size_t vec = 2 * sizeof(double), str = kStressComponents<2> * sizeof(double), phi = vec + str;
  const std::size_t props = sizeof(double) + sizeof(int);  // density, material
  const std::size_t hist = static_cast<std::size_t>(m.materials.history.stride()) * sizeof(double);
  const std::size_t src = m.materials.any_source ? 2 * str : 0;  // sigma_start, rate
  auto rows = [](const CorrectedOperator<2>& op) {
    return op.bytes() - op.interp.size() * sizeof(double) - op.grad.size() * sizeof(op.grad[0]);
  };
  const std::size_t row_en = rows(m.to_stress_points), row_ne = rows(m.to_nodes);
  std::size_t bytes = 0;
  // step 1: node v, sigma, history -> stress-point v, sigma, history (+ source inputs)
  bytes += nn * (phi + hist) + ne * (phi + hist + props + src) + row_en;
  // step 2: stress-point v, sigma; node v, sigma, u -> node v, sigma, u (+ source inputs)
  bytes += ne * phi + nn * (2 * phi + 2 * vec + props + sizeof(Index) + src) + row_ne;
  if (m.setup.filter) {
    bytes += nn * vec + ne * vec + row_en;              // P_EN v
    bytes += ne * vec + nn * (vec + vec) + row_ne;      // v - P_NE P_EN v
    bytes += nn * vec + ne * vec + row_en;              // P_EN of that
    bytes += ne * vec + nn * (vec + 2 * vec) + row_ne;  // v -= eps (...)
  }
  // balance: volume, density, v
  bytes += nn * (2 * sizeof(double) + vec);
  return bytes;
}

void BM_V1Step(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(1)));
  Simulation<2> solver(block_case(state.range(0)));
  const auto t0 = std::chrono::steady_clock::now();
  for (auto _ : state) {
    solver.step();
    benchmark::ClobberMemory();
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double nodes = static_cast<double>(solver.nodes().size());
  const double steps = static_cast<double>(state.iterations());
  const double traffic = static_cast<double>(step_traffic_bytes(solver));
  state.counters["nodes"] = nodes;
  state.counters["node_steps/s"] = benchmark::Counter(nodes * steps, benchmark::Counter::kIsRate);
  state.counters["pairs/node"] = static_cast<double>(solver.pairs()) / nodes;
  state.counters["state_B/node"] = static_cast<double>(solver.state_bytes()) / nodes;
  state.counters["operator_B/node"] = static_cast<double>(solver.operator_bytes()) / nodes;
  state.counters["patterns"] = static_cast<double>(solver.operator_patterns());
  state.counters["threads"] = static_cast<double>(state.range(1));
  // Effective bandwidth: the step's compulsory traffic (step_traffic_bytes above)
  // over its time, and its fraction of the triad of this run.
  state.counters["traffic_B/node"] = traffic / nodes;
  state.counters["GB/s"] = benchmark::Counter(traffic * steps / 1e9, benchmark::Counter::kIsRate);
  state.counters["of_triad"] = g_triad_gbs > 0.0 ? traffic * steps / seconds / 1e9 / g_triad_gbs : 0.0;
}
BENCHMARK(BM_V1Step)
    ->Args({10000, 1})
    ->Args({100000, 1})
    ->Args({100000, 2})
    ->Args({1000000, 1})
    ->Args({1000000, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The measured loop of a step benchmark: one step an iteration, then the node count and the
// rate of node-steps. Returns the node count.
template <int Dim>
double time_steps(benchmark::State& state, Simulation<Dim>& solver) {
  for (auto _ : state) {
    solver.step();
    benchmark::ClobberMemory();
  }
  const double nodes = static_cast<double>(solver.nodes().size());
  state.counters["nodes"] = nodes;
  state.counters["node_steps/s"] =
      benchmark::Counter(nodes * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  return nodes;
}

// The V1 step in 3D: a cube of about `nodes` nodes, fixed base, loaded top (the 2D block of
// BM_V1Step one dimension up). A 3D node has about 3.4 times the pairs of a 2D one.
void BM_V1Step3D(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(1)));
  const long side = static_cast<long>(std::lround(std::cbrt(static_cast<double>(state.range(0))))) - 1;
  const double dx = 0.1, length = static_cast<double>(side) * dx;
  CaseBuilder<3> b(fmt::format("benchmark cube, {} nodes", state.range(0)));
  b.spacing(dx)
      .block(Vec<3>::Zero(), Vec<3>::Constant(length))
      .elastic(2.0e7, 0.3, 2000.0)
      .fix_velocity(Region<3>::plane(2, 0.0), {0, 1, 2})
      .prescribe_stress(Region<3>::plane(2, length), StressComponent::zz, -1.0e4)
      .time(1.0, 0.9);
  Simulation<3> solver(b.build());
  const double nodes = time_steps(state, solver);
  state.counters["pairs/node"] = static_cast<double>(solver.pairs()) / nodes;
  state.counters["state_B/node"] = static_cast<double>(solver.state_bytes()) / nodes;
  state.counters["operator_B/node"] = static_cast<double>(solver.operator_bytes()) / nodes;
  state.counters["threads"] = static_cast<double>(state.range(1));
}
BENCHMARK(BM_V1Step3D)->Args({100000, 1})->Args({100000, 2})->Unit(benchmark::kMillisecond)->UseRealTime();

// The V3 (saturated) step on the same block with a drained top: the explicit V1 part plus the
// pore-pressure step (right-hand side, PCG solve with the Jacobi preconditioner, velocity
// correction), with the default incremental projection and odd-even filter. `filter` = 0 runs
// without the filter, to show its cost. K_f = 0.1 GPa keeps C c_u/c_d below the limit of the
// impermeable free sides (docs/VALIDATION.md, Case 16).
void BM_V3Step(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(1)));
  const auto c0 = std::chrono::steady_clock::now();
  Simulation<2> solver(block_case(state.range(0), true, state.range(2) != 0 ? 1.0 : 0.0, 0.5, state.range(3) != 0));
  const double setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - c0).count();
  for (int k = 0; k < 20; ++k) solver.step();  // past the first steps' PCG transient
  const auto* pressure = solver.scheme().find<PorePressureStage<2>>();
  const PressureSolveStats* stats = pressure != nullptr ? &pressure->stats() : nullptr;
  if (stats == nullptr) {
    state.SkipWithError("not a V3 run");
    return;
  }
  const PressureSolveStats before = *stats;
  const auto t0 = std::chrono::steady_clock::now();
  for (auto _ : state) {
    solver.step();
    benchmark::ClobberMemory();
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const PressureSolveStats& after = *stats;
  const double nodes = static_cast<double>(solver.nodes().size());
  const double steps = static_cast<double>(state.iterations());
  state.counters["nodes"] = nodes;
  state.counters["node_steps/s"] = benchmark::Counter(nodes * steps, benchmark::Counter::kIsRate);
  state.counters["pcg_iter/step"] = static_cast<double>(after.total_iterations - before.total_iterations) / steps;
  state.counters["pressure_share"] = (after.seconds - before.seconds) / seconds;
  state.counters["threads"] = static_cast<double>(state.range(1));
  state.counters["filter"] = static_cast<double>(state.range(2));
  state.counters["implicit_faces"] = static_cast<double>(state.range(3));
  // Memory held per node: state_B/node counts the particle state and every stage's scratch, the
  // pressure stage's included, of which pressure_B/node is the pressure solve (matrices,
  // preconditioner, Krylov vectors) and pstage_B/node the whole pressure stage; operator_B/node
  // the V1 operators. The process's peak is measured outside (/usr/bin/time, docs/VALIDATION.md).
  state.counters["state_B/node"] = static_cast<double>(solver.state_bytes()) / nodes;
  state.counters["operator_B/node"] = static_cast<double>(solver.operator_bytes()) / nodes;
  state.counters["pressure_B/node"] = static_cast<double>(pressure->solver().bytes()) / nodes;
  state.counters["pstage_B/node"] = static_cast<double>(pressure->scratch_bytes()) / nodes;
  state.counters["setup_s"] = setup;
  state.counters["K_patterns"] = static_cast<double>(pressure->solver().matrix_patterns());
  state.counters["rhs_patterns"] = static_cast<double>(pressure->solver().rhs_patterns());
}
// Args: nodes, threads, filter on, implicit faces.
BENCHMARK(BM_V3Step)
    ->Args({10000, 1, 1, 0})
    ->Args({10000, 1, 1, 1})
    ->Args({10000, 1, 0, 0})
    ->Args({100000, 1, 1, 0})
    ->Args({100000, 2, 1, 0})
    ->Args({10000, 2, 1, 0})
    ->Args({1000000, 1, 1, 0})
    ->Args({1000000, 2, 1, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// A figure of V2's free-surface detection report (its seconds, its full passes), 0 without
// detection.
template <int Dim>
double surface_figure(const Simulation<Dim>& solver, std::string_view name) {
  const auto* surface = solver.scheme().template find<DetectFreeSurface<Dim>>();
  if (surface == nullptr) return 0.0;
  for (const auto& [key, value] : surface->report()) {
    if (key == name) return value;
  }
  return 0.0;
}

// The V2 (large-deformation) step on the same block set spinning about its centre (at 0.1 rad/s
// 2.2 m/s at the corners, half a skin's motion every ~19 steps): the particles move, the
// Verlet lists are searched again as they leave their skin and the operators are recomputed
// every step; node_steps/s includes all of it. Counters: the share of the operator
// recomputation and of the neighbour searches, and the searches per step.
void BM_V2Step(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(1)));
  const long side = static_cast<long>(std::lround(std::sqrt(static_cast<double>(state.range(0))))) - 1;
  const double dx = 0.1, length = static_cast<double>(side) * dx;
  CaseBuilder<2> b(fmt::format("benchmark block, {} nodes, V2, spinning", state.range(0)));
  b.spacing(dx)
      .block(Vec<2>(0.0, 0.0), Vec<2>(length, length))
      .elastic(2.0e7, 0.3, 2000.0)
      .initial_velocity(Vec<2>::Zero(), 1e-3 * static_cast<double>(state.range(2)), Vec<2>(0.5 * length, 0.5 * length))
      .scheme("v2")
      .time(1.0, 0.5);
  // The fifth argument: the gradient floor on (V2's default) or off, for its cost.
  if (state.range(4) == 0) b.gradient_floor(0.0);
  CaseSetup<2> setup = b.build();
  // Storage (the fourth argument): the order the lattice was made in (rows) or shuffled, and
  // solver.sort off, "auto" (the default) or "always".
  const long storage = state.range(3);
  const bool shuffled = storage >= 2;
  setup.sort = storage == 0 || storage == 2 ? SortSetting::off
               : storage == 4               ? SortSetting::always
                                            : SortSetting::automatic;
  // The sixth: the operators on the fly (0, the default) or stored (1); with the nodal stress
  // filter of method-notes eq. (2.3.4) at 0.5 on the mean stress, stored (2) or on the fly (4),
  // or on every component, stored (3) or on the fly (5): what solver.stress_filter costs.
  // 0-5 run the thesis's simple scheme (method-notes §2.3), which those variants were made for;
  // 6 V2's default step, the hourglass control (§2.6), side by side with 0.
  const long operators = state.range(5);
  setup.operators_on_the_fly = operators == 0 || operators >= 4;
  setup.simple_velocity = operators != 6;
  setup.hourglass = operators == 6;
  if (operators >= 2 && operators <= 5) {
    setup.stress_filter = 0.5;
    setup.stress_filter_part = operators == 3 || operators == 5 ? StressFilterPart::full : StressFilterPart::mean;
  }
  Simulation<2> solver(setup);
  if (shuffled) {
    // The storage order of a long flow: particles far apart in memory. Unsorted, the set stays
    // so; sorted, the first search puts it back in Morton order.
    solver.reorder(shuffled_orders(solver.nodes().size(), solver.stress_points().size(), 12345));
  }
  for (int k = 0; k < 3; ++k) solver.step();  // the first search and the work space's growth
  const auto* rebuild = solver.scheme().find<RebuildOperators<2>>();
  if (rebuild == nullptr) {
    state.SkipWithError("not a V2 run");
    return;
  }
  const long searches0 = rebuild->relation_builds();
  const double search0 = rebuild->relation_seconds(), build0 = rebuild->operator_seconds();
  const double sort0 = rebuild->sort_seconds();
  const long sorts0 = rebuild->sorts();
  auto surface_report = [&](std::string_view name) { return surface_figure(solver, name); };
  const double surface0 = surface_report("detection_seconds");
  const double full_passes0 = surface_report("detection_full_passes");
  const auto t0 = std::chrono::steady_clock::now();
  for (auto _ : state) {
    solver.step();
    benchmark::ClobberMemory();
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double nodes = static_cast<double>(solver.nodes().size());
  const double steps = static_cast<double>(state.iterations());
  state.counters["nodes"] = nodes;
  state.counters["node_steps/s"] = benchmark::Counter(nodes * steps, benchmark::Counter::kIsRate);
  state.counters["searches/step"] = static_cast<double>(rebuild->relation_builds() - searches0) / steps;
  state.counters["search_share"] = (rebuild->relation_seconds() - search0) / seconds;
  state.counters["operator_share"] = (rebuild->operator_seconds() - build0) / seconds;
  state.counters["surface_share"] = (surface_report("detection_seconds") - surface0) / seconds;
  state.counters["full_surface_passes/step"] = (surface_report("detection_full_passes") - full_passes0) / steps;
  state.counters["sort_share"] = (rebuild->sort_seconds() - sort0) / seconds;
  state.counters["sorts/step"] = static_cast<double>(rebuild->sorts() - sorts0) / steps;
  state.counters["state_B/node"] = static_cast<double>(solver.state_bytes()) / nodes;
  state.counters["operator_B/node"] = static_cast<double>(solver.operator_bytes()) / nodes;
  state.counters["threads"] = static_cast<double>(state.range(1));
  const auto* filter = solver.scheme().find<StressFilter<2>>();
  state.counters["stress_filter_share"] = filter == nullptr ? 0.0 : filter->seconds() / seconds;
}
// Arguments: nodes, threads, the block's spin in mrad/s, the storage order. At 100 mrad/s the
// lists are searched again every ~19 steps, so most timed steps search nothing; at 1000 mrad/s
// (the corners at 22 m/s, a fifth of the P-wave speed) every ~2 steps, a fast flow: the
// search's cost is then in the figure (the counter searches/step says how often). Storage, in
// the order the lattice made the particles (rows) with solver.sort 0 "off", 1 "auto" (the
// default: kept, rows do better than Morton order); shuffled first (what a long mixing flow
// leaves) with 2 "off", 3 "auto" (sorted at the first search), 4 "always" (every search).
// The fifth: the gradient floor on (1, V2's default) or off (0). The sixth: the operators on
// the fly (0, V2's default) or stored (1); with the mean stress filter stored (2) or on the fly
// (4); with the full stress filter stored (3) or on the fly (5), all of these with the simple
// scheme (velocity_update = "simple"); 6: on the fly with V2's default step, the hourglass
// control (velocity_update = "hourglass").
BENCHMARK(BM_V2Step)
    ->Args({10000, 1, 100, 1, 1, 0})
    ->Args({100000, 1, 100, 1, 1, 0})
    ->Args({100000, 1, 100, 1, 1, 6})
    ->Args({100000, 2, 100, 1, 1, 6})
    ->Args({100000, 1, 100, 1, 0, 0})
    ->Args({100000, 1, 100, 0, 1, 0})
    ->Args({100000, 1, 100, 2, 1, 0})
    ->Args({100000, 1, 100, 3, 1, 0})
    ->Args({100000, 1, 100, 4, 1, 0})
    ->Args({100000, 2, 100, 1, 1, 0})
    ->Args({100000, 2, 100, 1, 0, 0})
    ->Args({100000, 1, 1000, 1, 1, 0})
    ->Args({100000, 1, 1000, 3, 1, 0})
    ->Args({100000, 1, 1000, 4, 1, 0})
    ->Args({100000, 2, 1000, 1, 1, 0})
    ->Args({100000, 1, 100, 1, 1, 1})
    ->Args({100000, 1, 100, 1, 1, 2})
    ->Args({100000, 1, 100, 1, 1, 3})
    ->Args({100000, 1, 100, 1, 1, 4})
    ->Args({100000, 1, 100, 1, 1, 5})
    ->Args({100000, 2, 100, 1, 1, 4})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The V2 step in 3D on a cube translating at 1 m/s (V2 moves its particles, the operators are
// recomputed every step; the lists are rarely searched again), one thread, by storage order:
// 0 the lattice's rows (x fastest, then y, then z) with solver.sort "off", 1 the rows with
// "auto" (the default: kept if Morton order would not halve the storage gap), 2 shuffled and
// "off", 3 shuffled and "auto" (sorted into Morton order at the first search). In 3D a node's
// neighbours in row order lie up to two planes (2 n^(2/3) indices) away.
void BM_V2Step3D(benchmark::State& state) {
  omp_set_num_threads(1);
  const long side = static_cast<long>(std::lround(std::cbrt(static_cast<double>(state.range(0))))) - 1;
  const double dx = 0.1, length = static_cast<double>(side) * dx;
  CaseBuilder<3> b(fmt::format("benchmark cube, {} nodes, V2, translating", state.range(0)));
  b.spacing(dx)
      .block(Vec<3>::Zero(), Vec<3>::Constant(length))
      .elastic(2.0e7, 0.3, 2000.0)
      .initial_velocity(Vec<3>(1.0, 0.0, 0.0))
      .scheme("v2")
      .time(1.0, 0.5);
  CaseSetup<3> setup = b.build();
  const long storage = state.range(1);
  setup.sort = storage == 1 || storage == 3 ? SortSetting::automatic : SortSetting::off;
  Simulation<3> solver(setup);
  if (storage >= 2) solver.reorder(shuffled_orders(solver.nodes().size(), solver.stress_points().size(), 12345));
  for (int k = 0; k < 3; ++k) solver.step();
  const double surface0 = surface_figure(solver, "detection_seconds");
  const auto t0 = std::chrono::steady_clock::now();
  time_steps(state, solver);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  state.counters["sorts"] = static_cast<double>(solver.reorders());
  state.counters["surface_share"] = (surface_figure(solver, "detection_seconds") - surface0) / seconds;
}
BENCHMARK(BM_V2Step3D)
    ->Args({100000, 0})
    ->Args({100000, 1})
    ->Args({100000, 2})
    ->Args({100000, 3})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Neighbour search (cell list) and corrected-operator assembly of both directions, one thread:
// the set-up the large-deformation version would repeat every step.
void BM_OperatorSetup(benchmark::State& state) {
  omp_set_num_threads(1);
  const CaseSetup<2> setup = block_case(state.range(0));
  const LatticeParticles<2> disc = generate_lattice<2>(setup.blocks, setup.dx, setup.origin, {2000.0});
  const CubicSplineKernel<2> kernel(setup.h_over_dx * setup.dx);
  for (auto _ : state) {
    const auto en = build_corrected_operator<2>(disc.stress_points.position, disc.nodes, kernel);
    const auto ne = build_corrected_operator<2>(disc.nodes.position, disc.stress_points, kernel);
    benchmark::DoNotOptimize(en.base.data());
    benchmark::DoNotOptimize(ne.base.data());
  }
  const double nodes = static_cast<double>(disc.nodes.size());
  state.counters["nodes"] = nodes;
  state.counters["us/node"] = benchmark::Counter(nodes * static_cast<double>(state.iterations()),
                                                 benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_OperatorSetup)->Arg(100000)->Unit(benchmark::kMillisecond)->UseRealTime();

// One re-seeding of the stress points from a sheared node cloud (particles/reseed.hpp), one
// thread: what solver.reseed costs each time it fires, against a V2 step (BM_V2Step).
void BM_Reseed(benchmark::State& state) {
  omp_set_num_threads(1);
  const CaseSetup<2> setup = block_case(state.range(0));
  LatticeParticles<2> disc = generate_lattice<2>(setup.blocks, setup.dx, setup.origin, {2000.0});
  for (auto& x : disc.nodes.position) x[0] += 0.3 * x[1];  // a simple shear of 0.3
  ReseedOptions options;
  options.dx = setup.dx;
  options.cover = 0.45;
  std::int64_t next = 0;
  ParticleSet<2> sp;
  for (auto _ : state) {
    state.PauseTiming();
    sp = disc.stress_points;  // the set to replace, not timed
    state.ResumeTiming();
    benchmark::DoNotOptimize(reseed_stress_points<2>(disc.nodes, disc.lattice.origin, options, sp, next).after);
  }
  const double nodes = static_cast<double>(disc.nodes.size());
  state.counters["nodes"] = nodes;
  state.counters["us/node"] = benchmark::Counter(nodes * static_cast<double>(state.iterations()),
                                                 benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_Reseed)->Arg(100000)->Unit(benchmark::kMillisecond)->UseRealTime();

// The whole set-up of a run: lattice generation, operators, constraints, state.
void BM_V1Setup(benchmark::State& state) {
  omp_set_num_threads(1);
  double nodes = 0;
  for (auto _ : state) {
    Simulation<2> solver(block_case(state.range(0)));
    nodes = static_cast<double>(solver.nodes().size());
    benchmark::DoNotOptimize(solver.nodes().position.data());
  }
  state.counters["nodes"] = nodes;
  state.counters["us/node"] = benchmark::Counter(nodes * static_cast<double>(state.iterations()),
                                                 benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_V1Setup)->Arg(100000)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace


// ---- plasticity at any stiffness (method-notes §2.5)

// The elastic step of the plastic block below, node-steps/s by scheme (0: V1, 1: V2), for the
// ratio counter: BM_PlasticBlock with model 0 (elastic) runs first for each scheme.
double g_elastic_rate[2] = {0.0, 0.0};

// A square 2D block of about `nodes` nodes in homogeneous plastic flow: pure shear
// v = eps_dot (x, -y) about the centre (eps_dot = 1 1/s), from a uniform stress already beyond
// the surface (p' = 100 kPa, q = 400 kPa), no boundary conditions: until the free faces' waves
// arrive (about 300 steps at the centre) every stress point and node flows at every step.
// Models: 0 elastic, 1 Drucker–Prager (phi = 30 deg, psi = 0, cohesion c), 2 modified Cam-Clay
// (M = 1.2, p_c0 = 200 kPa; c unused). The fluidity from the table below, the last "inf".
CaseSetup<2> plastic_block_case(long nodes, int model, int fluidity_index, double cohesion, int scheme) {
  static constexpr double kFluidities[5] = {1.0, 1e2, 1e4, 1e6, std::numeric_limits<double>::infinity()};
  const double gamma = kFluidities[fluidity_index];
  const long side = static_cast<long>(std::lround(std::sqrt(static_cast<double>(nodes)))) - 1;
  const double dx = 0.1, length = static_cast<double>(side) * dx;
  const ElasticConstants el = ElasticConstants::from_E_nu(2.0e7, 0.3, 2000.0);
  CaseBuilder<2> b(fmt::format("plastic block, {} nodes, model {}, gamma {}, c {}", nodes, model, gamma, cohesion));
  b.spacing(dx).block(Vec<2>(0.0, 0.0), Vec<2>(length, length));
  if (model == 0) {
    b.elastic(el.E, el.nu, el.density);
  } else if (model == 1) {
    DruckerPragerParameters p;
    p.elastic = el;
    p.cohesion = cohesion;
    p.friction_angle = 30.0 * std::acos(-1.0) / 180.0;
    p.fluidity = gamma;
    b.material(make_perzyna_drucker_prager(p));
  } else {
    CamClayParameters p;
    p.elastic = el;
    p.M = 1.2;
    p.lambda = 0.2;
    p.kappa = 0.02;
    p.e0 = 1.0;
    p.p_c0 = 2.0e5;
    p.fluidity = gamma;
    b.material(make_perzyna_cam_clay(p));
  }
  // p' = 100 kPa, q = 400 kPa in plane strain: sxx - syy = 2 tau with q = sqrt(3) tau.
  const double tau = 4.0e5 / std::sqrt(3.0);
  b.initial_stress({-1.0e5 + tau, -1.0e5 - tau, -1.0e5, 0.0, 0.0, 0.0});
  if (scheme == 1) b.scheme("v2").free_surface(false);
  b.time(1.0, 0.5);
  return b.build();
}

void BM_PlasticBlock(benchmark::State& state) {
  omp_set_num_threads(1);
  const int model = static_cast<int>(state.range(1)), scheme = static_cast<int>(state.range(4));
  const double cohesion = static_cast<double>(state.range(3));
  Simulation<2> solver(plastic_block_case(state.range(0), model, static_cast<int>(state.range(2)), cohesion, scheme));
  // The pure-shear velocity field about the block's centre.
  {
    auto v = solver.mutable_node_velocity();
    const auto& x = solver.nodes().position;
    double cx = 0.0, cy = 0.0;
    for (const auto& p : x) {
      cx += p[0];
      cy += p[1];
    }
    cx /= static_cast<double>(x.size());
    cy /= static_cast<double>(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      v(static_cast<Index>(i), 0) = x[i][0] - cx;
      v(static_cast<Index>(i), 1) = -(x[i][1] - cy);
    }
  }
  for (int k = 0; k < 2; ++k) solver.step();  // past the first returns from the start beyond the surface
  const SourceStats s0 = solver.source_stats();
  const auto t0 = std::chrono::steady_clock::now();
  for (auto _ : state) {
    solver.step();
    benchmark::ClobberMemory();
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const SourceStats s1 = solver.source_stats();
  const double nodes = static_cast<double>(solver.nodes().size());
  const double steps = static_cast<double>(state.iterations());
  const double rate = nodes * steps / seconds;
  if (model == 0) g_elastic_rate[scheme] = rate;
  const double points = static_cast<double>((s1.elastic_points - s0.elastic_points) + (s1.rk4_points - s0.rk4_points) +
                                            (s1.implicit_points - s0.implicit_points));
  state.counters["nodes"] = nodes;
  state.counters["node_steps/s"] = benchmark::Counter(nodes * steps, benchmark::Counter::kIsRate);
  state.counters["of_elastic"] = g_elastic_rate[scheme] > 0.0 ? rate / g_elastic_rate[scheme] : 0.0;
  state.counters["plastic_share"] =
      points > 0.0 ? 1.0 - static_cast<double>(s1.elastic_points - s0.elastic_points) / points : 0.0;
  state.counters["implicit_share"] =
      points > 0.0 ? static_cast<double>(s1.implicit_points - s0.implicit_points) / points : 0.0;
  state.counters["newton/return"] =
      s1.implicit_points > s0.implicit_points
          ? static_cast<double>(s1.newton_iterations - s0.newton_iterations) /
                static_cast<double>(s1.implicit_points - s0.implicit_points)
          : 0.0;
  state.counters["rk4_substeps/point"] =
      points > 0.0 ? static_cast<double>(s1.total_substeps - s0.total_substeps) / points : 0.0;
}
// Arguments: nodes, model (0 elastic, 1 Drucker–Prager, 2 Cam-Clay), fluidity index (1, 1e2,
// 1e4, 1e6 1/s, inf), cohesion in Pa (Drucker–Prager), scheme (0 V1, 1 V2). The elastic block of
// each scheme runs first: of_elastic is the plastic rate over it.
void plastic_block_arguments(benchmark::internal::Benchmark* b) {
  for (int scheme : {0, 1}) {
    b->Args({100000, 0, 0, 0, scheme});
    for (int g = 0; g < 5; ++g) {
      for (long c : {1L, 1000L, 100000L}) b->Args({100000, 1, g, c, scheme});
      b->Args({100000, 2, g, 0, scheme});
    }
  }
}
BENCHMARK(BM_PlasticBlock)->Apply(plastic_block_arguments)->Unit(benchmark::kMillisecond)->UseRealTime();

// ---- one backward-Euler return (method-notes §2.5)

// Trial stresses just beyond the surface, as a stiff step brings them: a frictional soil
// (E = 50 MPa, c = 200 Pa, phi = 30 deg, psi = 0, gamma = 100 1/s, tau = 2.5e-4 s: a column
// 4 m high at its time step, method-notes §2.5) at p' = 1-80 kPa, or Cam-Clay (p_c = 200 kPa) at
// p' = 0.2-0.95 p_c; Lode angles over the whole range, principal axes turned, the overstress
// 0.1 %-30 % (of Mohr–Coulomb, and at least as much of the plane-strain Drucker–Prager cone,
// which is Mohr–Coulomb with K = 1).
struct ReturnTrials {
  std::vector<Sym6> stress;
  double tau = 2.5e-4;
};

ReturnTrials return_trials(bool cam_clay, std::size_t count) {
  ReturnTrials t;
  std::uint64_t seed = 12345;
  auto uniform = [&seed] {  // a 64-bit LCG: the same trials on every machine
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(seed >> 11) * 0x1.0p-53;
  };
  const double deg = std::numbers::pi / 180.0;
  const MohrCoulombSurface mc = MohrCoulombSurface::make(30.0 * deg, 0.0, 0.1);
  const double Y = std::sqrt(3.0) * std::cos(30.0 * deg) * 200.0, pc = 2.0e5, M = 1.2;
  for (std::size_t i = 0; i < count; ++i) {
    const double theta = (uniform() - 0.5) * 60.0 * deg, turn = 3.0 * uniform();
    const double over = 1.0 + 0.001 * std::pow(300.0, uniform());
    double p = 0.0, q = 0.0;
    if (cam_clay) {
      p = (0.2 + 0.75 * uniform()) * pc;
      const double sphi = 3.0 * M / (6.0 + M);  // M(theta) of method-notes eq. (1.8.4)
      q = over * 6.0 * sphi / (3.0 - sphi * std::sin(3.0 * theta)) * std::sqrt(p * (pc - p));
    } else {
      p = 1e3 + 7.9e4 * uniform();
      const double K = std::min(mc.lode_F.along(LodeAngle::of(theta)).K, 1.0), dF = mc.round_F * Y;
      const double R = Y + std::sqrt(3.0) * 0.5 * p;
      q = over * std::sqrt(R * R - dF * dF) / K;
    }
    t.stress.push_back(tensor::from_invariants(p, q, theta, turn));
  }
  return t;
}

template <class Model>
void time_returns(benchmark::State& state, const Model& model, typename detail::PerzynaBackwardEuler<Model>::Path path,
                  const ReturnTrials& trials, const std::vector<double>& k0) {
  const detail::PerzynaBackwardEuler<Model> solver(model, path);
  Sym6 sigma;
  double k[4];
  long returns = 0, iterations = 0, failed = 0;
  // This thread's CPU time: on a shared machine the wall clock counts the neighbours' work too.
  auto cpu_seconds = [] {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
  };
  const double t0 = cpu_seconds();
  for (auto _ : state) {
    for (const Sym6& trial : trials.stress) {
      const ImplicitOutcome o = solver.solve(trial, k0.data(), trials.tau, sigma, k);
      benchmark::DoNotOptimize(sigma);
      iterations += o.iterations;
      failed += o.converged ? 0 : 1;
      ++returns;
    }
  }
  const double seconds = cpu_seconds() - t0;
  state.counters["ns/return"] = seconds / static_cast<double>(returns) * 1e9;
  state.counters["newton/return"] = static_cast<double>(iterations) / static_cast<double>(returns);
  state.counters["failed"] = static_cast<double>(failed);
}

// Models: 0 Drucker–Prager ((p', q) return), 1 Mohr–Coulomb with the generic (mean, a, b)
// return and forward differences, 2 Mohr–Coulomb with the (p', q, theta) return, 3 and 4 the
// same two for Cam-Clay with M(theta).
void BM_ImplicitReturn(benchmark::State& state) {
  const int model = static_cast<int>(state.range(0));
  const double deg = std::numbers::pi / 180.0;
  const ElasticConstants el = ElasticConstants::from_E_nu(5.0e7, 0.3, 2000.0);
  const ReturnTrials trials = return_trials(model >= 3, 4096);
  if (model == 0) {
    DruckerPragerParameters p;
    p.elastic = el;
    p.cohesion = 200.0;
    p.friction_angle = 30.0 * deg;
    p.fluidity = 100.0;
    const auto m = make_perzyna_drucker_prager(p);
    using Model = PerzynaMaterial<DruckerPragerSurface, LinearHardening>;
    time_returns(state, dynamic_cast<const Model&>(*m), detail::PerzynaBackwardEuler<Model>::Path::fastest, trials,
                 {0.0});
  } else if (model <= 2) {
    MohrCoulombParameters p;
    p.elastic = el;
    p.cohesion = 200.0;
    p.friction_angle = 30.0 * deg;
    p.fluidity = 100.0;
    const auto m = make_perzyna_mohr_coulomb(p);
    using Model = PerzynaMaterial<MohrCoulombSurface, LinearHardening>;
    using Path = detail::PerzynaBackwardEuler<Model>::Path;
    time_returns(state, dynamic_cast<const Model&>(*m), model == 1 ? Path::generic : Path::fastest, trials, {0.0});
  } else {
    CamClayParameters p;
    p.elastic = el;
    p.M = 1.2;
    p.lode_dependent_M = true;
    p.lambda = 0.2;
    p.kappa = 0.02;
    p.e0 = 1.0;
    p.p_c0 = 2.0e5;
    p.fluidity = 100.0;
    const auto m = make_perzyna_cam_clay(p);
    using Model = PerzynaMaterial<CamClaySurface, CamClayHardening>;
    using Path = detail::PerzynaBackwardEuler<Model>::Path;
    time_returns(state, dynamic_cast<const Model&>(*m), model == 3 ? Path::generic : Path::fastest, trials,
                 {0.0, 0.0, 2.0e5});
  }
}
BENCHMARK(BM_ImplicitReturn)->DenseRange(0, 4)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
