// rktsph: Runge–Kutta Taylor SPH for the dynamics of dry and saturated soils.
#include <omp.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "app/check_case.hpp"
#include "app/fos.hpp"
#include "app/lem_command.hpp"
#include "app/material_point.hpp"
#include "app/run_case.hpp"
#include "case/material_reader.hpp"
#include "core/error.hpp"
#include "core/execution.hpp"
#include "rktsph/version.hpp"
#include "validation/validation.hpp"

namespace {

// Threads (docs/architecture.md, "Execution").
//
// Wait policy. libgomp's waiting threads spin (GOMP_SPINCOUNT = 300000 by default) at every
// barrier and between parallel regions. When another process keeps a core busy, a thread of
// ours that shares its core is preempted while the others spin for it, holding the cores it
// could run on: the default two threads measured 5.7x slower than one thread on the V1
// benchmark and 19x on a V3 run. With OMP_WAIT_POLICY=passive a waiting thread sleeps at once,
// its core goes idle and the scheduler moves the preempted thread there. libgomp reads the
// variable when it is loaded, before main, so it cannot be set from here: the program runs
// itself again (/proc/self/exe, same pid, arguments and environment) with the variable set,
// unless the user has set OMP_WAIT_POLICY or GOMP_SPINCOUNT, whose choice is then kept. If the
// exec fails the run goes on with the runtime's own policy.
void ensure_passive_wait_policy(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr || std::getenv("GOMP_SPINCOUNT") != nullptr) return;
  if (::setenv("OMP_WAIT_POLICY", "passive", 0) != 0) return;
  ::execv("/proc/self/exe", argv);
  ::unsetenv("OMP_WAIT_POLICY");  // exec failed: nothing changed, the runtime keeps its default
}

// The CPUs this process may run on (its affinity mask: taskset, cgroup cpusets, a batch
// scheduler's allocation), else what OpenMP counts.
int available_cpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (::sched_getaffinity(0, sizeof(set), &set) == 0) {
    const int n = CPU_COUNT(&set);
    if (n > 0) return n;
  }
  return std::max(1, omp_get_num_procs());
}

// The thread count of a run: --threads N, else OMP_NUM_THREADS, else every available CPU;
// bounded by the available CPUs. More threads than CPUs only slows a run down (results are
// bit for bit the same on any thread count), and a huge count crashes the OpenMP runtime, so
// the count is clamped with a warning rather than refused: a job script written for a larger
// machine still runs. With neither --threads nor OMP_NUM_THREADS, each parallel loop chooses
// between all of them and one thread by measuring both (exec::adaptive_teams): the default must
// not be slower than one thread when other processes keep the cores busy. A count the user
// fixed is used as given.
int resolve_threads(int requested) {
  const int cpus = available_cpus();
  const bool from_option = requested > 0;
  const int wanted = from_option ? requested : omp_get_max_threads();
  if (wanted > cpus) {
    std::cerr << fmt::format(
        "warning: {} {} thread{} but this process may run on {} CPU{}; using {} (more threads than "
        "CPUs only slow the run down)\n",
        from_option ? "--threads asks for" : "OMP_NUM_THREADS asks for", wanted, wanted > 1 ? "s" : "", cpus,
        cpus > 1 ? "s" : "", cpus);
  }
  const int threads = std::min(wanted, cpus);
  omp_set_num_threads(threads);
  rktsph::exec::adaptive_teams() = !from_option && std::getenv("OMP_NUM_THREADS") == nullptr && threads > 1;
  return threads;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace rktsph;
  ensure_passive_wait_policy(argv);
  CLI::App app{
      "rktsph - dynamics of dry and saturated soils by the Runge-Kutta Taylor SPH method.\n"
      "Cases are TOML files (format: docs/case-format.md); results go to an output folder\n"
      "with ParaView files (nodes.pvd, elements.pvd), probes.csv, energy.csv and summary.json.\n\n"
      "Examples:\n"
      "  rktsph run cases/thesis/01_elastic_bar_1d.toml\n"
      "  rktsph run case.toml --out runs/stiff --set material.E=2.5e7 --threads 2\n"
      "  rktsph check cases/examples/*.toml\n"
      "  rktsph material-point cases/material_point/cam_clay_drained_nc.toml\n"
      "  rktsph lem cases/examples/slope_2to1_c10_phi20.toml\n"
      "  rktsph fos cases/thesis/05_viscoplastic_cut_2d.toml --tol 0.02\n"};
  app.set_version_flag("--version", fmt::format("rktsph {} ({})", kVersion, kGitRevision));
  app.require_subcommand(1);

  RunOptions run;
  auto* run_cmd = app.add_subcommand("run", "Run a case file and write its output folder");
  run_cmd->add_option("case", run.case_file, "Case file (TOML)")->required()->check(CLI::ExistingFile);
  run_cmd->add_option("--out,-o", run.out_dir, "Output folder (default: out/<case name>)");
  run_cmd->add_option("--set,-s", run.overrides,
                      "Override a case key, e.g. --set material.E=2.5e7 (repeatable; checked "
                      "like the file)");
  run_cmd
      ->add_option("--threads,-j", run.threads,
                   "Number of threads (default: every CPU this process may use; more are clamped to that)")
      ->check(CLI::NonNegativeNumber);
  run_cmd->add_flag("--quiet,-q", run.quiet, "No progress output");

  RunOptions resume;
  auto* resume_cmd =
      app.add_subcommand("resume", "Continue an interrupted run from its checkpoint (output folder of `rktsph run`)");
  resume_cmd->add_option("folder", resume.out_dir, "Output folder of the interrupted run")->required();
  resume_cmd->add_option("--set,-s", resume.overrides, "Override time.end or an output.* key, e.g. --set time.end=20");
  resume_cmd->add_option("--threads,-j", resume.threads, "Number of threads (default and bound as for run)")
      ->check(CLI::NonNegativeNumber);
  resume_cmd->add_flag("--quiet,-q", resume.quiet, "No progress output");

  CheckOptions check;
  auto* check_cmd = app.add_subcommand(
      "check", "Check case files without running them: particles, solver, time step and steps to the end");
  check_cmd->add_option("cases", check.files, "Case files (TOML; material-point files too)")
      ->required()
      ->check(CLI::ExistingFile);
  check_cmd->add_option("--set,-s", check.overrides, "Override a case key in every file, as for run");
  check_cmd->add_option("--threads,-j", check.threads, "Threads for the run-time estimate (default as for run)")
      ->check(CLI::NonNegativeNumber);
  check_cmd->add_flag("!--no-estimate", check.estimate, "Skip the trial steps that estimate the run time");

  std::string mp_file, mp_out;
  std::vector<std::string> mp_overrides;
  auto* mp_cmd =
      app.add_subcommand("material-point", "Drive one material point along a stress/strain path (path.csv + plot)");
  mp_cmd->add_option("case", mp_file, "Material-point file (TOML)")->required()->check(CLI::ExistingFile);
  mp_cmd->add_option("--out,-o", mp_out, "Output folder (default: out/<file name>)");
  mp_cmd->add_option("--set,-s", mp_overrides, "Override a key, e.g. --set material.fluidity=10");

  auto* mat_cmd = app.add_subcommand("materials", "List the constitutive models");

  LemOptions lem_opt;
  auto* lem_cmd = app.add_subcommand(
      "lem", "Limit equilibrium: Bishop's simplified method, search for the critical circle (lem.json + plot)");
  lem_cmd->add_option("case", lem_opt.case_file, "Case file (TOML)")->required()->check(CLI::ExistingFile);
  lem_cmd->add_option("--out,-o", lem_opt.out_dir, "Output folder (default: out/<case name>-lem)");
  lem_cmd->add_option("--set,-s", lem_opt.overrides, "Override a case key, e.g. --set material.cohesion=12e3");
  lem_cmd->add_option("--slices", lem_opt.search.bishop.slices, "Slices per circle (default 50)")
      ->check(CLI::Range(4, 100000));
  lem_cmd->add_option("--grid", lem_opt.search.grid, "Centres per axis of each search level (default 21)")
      ->check(CLI::Range(3, 401));
  lem_cmd->add_option("--levels", lem_opt.search.levels, "Search levels: the first grid and its refinements (default 5)")
      ->check(CLI::Range(1, 20));
  lem_cmd->add_option("--radii", lem_opt.search.radii, "Radii scanned per centre before refining (default 30)")
      ->check(CLI::Range(3, 10000));
  lem_cmd
      ->add_option("--centres", lem_opt.centre_box,
                   "First search box of circle centres: X0 X1 Y0 Y1 in m (default: 3H beyond the soil on each "
                   "side, mid-height to 3H above its top)")
      ->expected(4);
  lem_cmd->add_flag("!--no-plot", lem_opt.plot, "Skip the matplotlib plot");
  lem_cmd->add_flag("--quiet,-q", lem_opt.quiet, "No summary output");

  validation::Options val;
  val.cases_dir = std::string(RKTSPH_SOURCE_DIR) + "/cases/thesis";
  bool val_quick = false;
  auto* val_cmd =
      app.add_subcommand("validate", "Run the thesis cases against their references; write validation/report.md");
  val_cmd->add_option("cases", val.only, "Case numbers to run, e.g. 01, or mandel (default: all)");
  auto* full_flag = val_cmd->add_flag("--full", val.full, "docs/cases.md acceptance resolutions");
  val_cmd->add_flag("--quick", val_quick, "Coarse resolutions that fit in CI (default)")->excludes(full_flag);
  val_cmd
      ->add_flag("--refine", val.refine,
                 "With --full: one more halving of the finest spacing where a criterion is a convergence under "
                 "refinement (Case 11's band width: 0.0625 m, about 25 min on two threads)")
      ->needs(full_flag);
  val_cmd->add_option("--out,-o", val.out_dir, "Report folder (default: validation)");
  val_cmd->add_option("--cases-dir", val.cases_dir, "Folder of the thesis case files");
  val_cmd->add_flag("!--no-plots", val.plots, "Skip the matplotlib plots");
  val_cmd->add_option("--threads,-j", run.threads, "Number of threads (default and bound as for run)")
      ->check(CLI::NonNegativeNumber);

  FosOptions fos;
  auto* fos_cmd = app.add_subcommand(
      "fos",
      "Factor of safety by strength reduction (trials at c/F, tan(phi)/F), or with fos.mode = \"load\" the load factor "
      "of the collapse load (trials at F times the loads); bisected on F (fos.json + plot)");
  fos_cmd->add_option("case", fos.case_file, "Case file (TOML; its [fos] table: docs/case-format.md)")
      ->required()
      ->check(CLI::ExistingFile);
  fos_cmd->add_option("--out,-o", fos.out_dir, "Output folder (default: out/<case name>_fos)");
  fos_cmd->add_option("--set,-s", fos.overrides, "Override a case key for every trial (repeatable)");
  fos_cmd->add_option("--solver", fos.solver, "Solver of the trials (default: the case's solver.version, v1 unless set)")
      ->check(CLI::IsMember({"v1", "v2", "v3"}));
  fos_cmd->add_option("--tol", fos.tolerance, "Relative tolerance on F (default: fos.tolerance, 0.01)")
      ->check(CLI::Range(1e-6, 0.999));
  fos_cmd->add_option("--max-trials", fos.max_trials, "Trials the search may use (default: fos.max_trials, 12)")
      ->check(CLI::Range(2, 200));
  fos_cmd->add_option("--jobs", fos.jobs, "Trials run at once (default: one per thread)")->check(CLI::Range(1, 64));
  fos_cmd->add_option("--threads,-j", fos.threads, "Threads in all, shared by the trials at once (default as for run)")
      ->check(CLI::NonNegativeNumber);
  fos_cmd->add_flag("--quiet,-q", fos.quiet, "No progress lines");
  fos_cmd->add_flag("!--no-plot", fos.plot, "Skip the u_c(t) plot");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }

  try {
    if (run_cmd->parsed()) {
      run.threads = resolve_threads(run.threads);
      return run_case(run);
    }
    if (resume_cmd->parsed()) {
      resume.threads = resolve_threads(resume.threads);
      return resume_case(resume);
    }
    if (fos_cmd->parsed()) {
      fos.threads = resolve_threads(fos.threads);
      // The trials run side by side, each on a fixed share of the threads: no adaptive teams.
      exec::adaptive_teams() = false;
      return run_fos(fos);
    }
    if (check_cmd->parsed()) return check_cases(check);
    if (mp_cmd->parsed()) return run_material_point(mp_file, mp_out, mp_overrides);
    if (lem_cmd->parsed()) return run_lem(lem_opt);
    if (val_cmd->parsed()) {
      resolve_threads(run.threads);
      return validation::run_validation(val);
    }
    if (mat_cmd->parsed()) {
      for (const auto& [name, description] : registered_materials()) {
        std::cout << fmt::format("{:<22} {}\n", name, description);
      }
      return 0;
    }
  } catch (const InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitInput;
  } catch (const SolverError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitUnstable;
  } catch (const IoError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitIo;
  } catch (const std::filesystem::filesystem_error& e) {
    // A folder that cannot be made or read: the output path given is the problem.
    std::cerr << "error: " << e.what() << "\n";
    return kExitInput;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
