// Throughput of the V1 time step and of its set-up (neighbour search + operator assembly),
// with the memory it holds per node and a STREAM-like triad for the machine's bandwidth.
//   build/bench/rktsph_bench --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

#include <fmt/format.h>

#include "case/case_setup.hpp"
#include "solvers/staggered_solver.hpp"

namespace {

using namespace rktsph;

// A square 2D elastic block with about `nodes` nodes, fixed base, loaded top.
std::string block_case(long nodes) {
  const long side = static_cast<long>(std::lround(std::sqrt(static_cast<double>(nodes)))) - 1;
  const double dx = 0.1, length = static_cast<double>(side) * dx;
  const std::string path = (std::filesystem::temp_directory_path() / fmt::format("rktsph_bench_{}.toml", nodes)).string();
  std::ofstream(path) << fmt::format(R"(
[geometry]
dimension = 2
spacing = {dx}
[[geometry.block]]
min = [0.0, 0.0]
max = [{L}, {L}]
[material]
model = "elastic"
E = 2.0e7
nu = 0.3
density = 2000.0
[[boundary]]
y = [0.0, 0.0]
velocity = {{ x = 0.0, y = 0.0 }}
[[boundary]]
y = [{L}, {L}]
stress = {{ yy = -1.0e4 }}
[time]
end = 1.0
cfl = 0.9
)", fmt::arg("dx", dx), fmt::arg("L", length));
  return path;
}

void BM_V1Step(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(1)));
  const CaseDocument doc = load_case_document(block_case(state.range(0)), {});
  CaseSetup<2> setup = read_case<2>(doc);
  StaggeredSolver<2> solver(setup);
  for (auto _ : state) {
    solver.step();
    benchmark::ClobberMemory();
  }
  const double nodes = static_cast<double>(solver.particles().nodes.size());
  state.counters["nodes"] = nodes;
  state.counters["node_steps/s"] = benchmark::Counter(nodes * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["pairs/node"] = static_cast<double>(solver.pairs()) / nodes;
  state.counters["state_B/node"] = static_cast<double>(solver.state_bytes()) / nodes;
  state.counters["operator_B/node"] = static_cast<double>(solver.operator_bytes()) / nodes;
  state.counters["threads"] = static_cast<double>(state.range(1));
}
BENCHMARK(BM_V1Step)->Args({10000, 1})->Args({100000, 1})->Args({100000, 2})->Args({1000000, 1})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

// Set-up: lattice generation, cell-list neighbour search and corrected-operator assembly.
void BM_V1Setup(benchmark::State& state) {
  omp_set_num_threads(1);
  const CaseDocument doc = load_case_document(block_case(state.range(0)), {});
  double nodes = 0;
  for (auto _ : state) {
    CaseSetup<2> setup = read_case<2>(doc);
    StaggeredSolver<2> solver(setup);
    nodes = static_cast<double>(solver.particles().nodes.size());
    benchmark::DoNotOptimize(solver.node_phi().data());
  }
  state.counters["nodes"] = nodes;
  state.counters["us/node"] = benchmark::Counter(nodes * static_cast<double>(state.iterations()),
                                                 benchmark::Counter::kIsRate | benchmark::Counter::kInvert) ;
}
BENCHMARK(BM_V1Setup)->Arg(100000)->Unit(benchmark::kMillisecond)->UseRealTime();

// STREAM-like triad a = b + s c on arrays far larger than the caches: the bandwidth ceiling.
void BM_Triad(benchmark::State& state) {
  const std::size_t n = 1 << 25;  // 3 x 256 MiB
  std::vector<double> a(n, 0.0), b(n, 1.0), c(n, 2.0);
  for (auto _ : state) {
    for (std::size_t i = 0; i < n; ++i) a[i] = b[i] + 3.0 * c[i];
    benchmark::DoNotOptimize(a.data());
    benchmark::ClobberMemory();
  }
  state.counters["GB/s"] = benchmark::Counter(3.0 * 8.0 * static_cast<double>(n) * static_cast<double>(state.iterations()) / 1e9,
                                              benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Triad)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
