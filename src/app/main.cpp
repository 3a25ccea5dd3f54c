// rktsph: Runge–Kutta Taylor SPH for the dynamics of dry and saturated soils.
#include <omp.h>

#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "app/material_point.hpp"
#include "app/run_case.hpp"
#include "case/material_reader.hpp"
#include "core/error.hpp"
#include "rktsph/version.hpp"
#include "validation/validation.hpp"

int main(int argc, char** argv) {
  using namespace rktsph;
  CLI::App app{
      "rktsph - dynamics of dry and saturated soils by the Runge-Kutta Taylor SPH method.\n"
      "Cases are TOML files (format: docs/case-format.md); results go to an output folder\n"
      "with ParaView files (nodes.pvd, elements.pvd), probes.csv, energy.csv and summary.json.\n\n"
      "Examples:\n"
      "  rktsph run cases/thesis/01_elastic_bar_1d.toml\n"
      "  rktsph run case.toml --out runs/stiff --set material.E=2.5e7 --threads 2\n"
      "  rktsph material-point cases/material_point/cam_clay_drained_nc.toml\n"};
  app.set_version_flag("--version", fmt::format("rktsph {} ({})", kVersion, kGitRevision));
  app.require_subcommand(1);

  RunOptions run;
  auto* run_cmd = app.add_subcommand("run", "Run a case file and write its output folder");
  run_cmd->add_option("case", run.case_file, "Case file (TOML)")->required()->check(CLI::ExistingFile);
  run_cmd->add_option("--out,-o", run.out_dir, "Output folder (default: out/<case name>)");
  run_cmd->add_option("--set,-s", run.overrides,
                      "Override a case key, e.g. --set material.E=2.5e7 (repeatable; checked "
                      "like the file)");
  run_cmd->add_option("--threads,-j", run.threads, "Number of threads (default: all cores)")
      ->check(CLI::NonNegativeNumber);
  run_cmd->add_flag("--quiet,-q", run.quiet, "No progress output");

  RunOptions resume;
  auto* resume_cmd = app.add_subcommand(
      "resume", "Continue an interrupted run from its checkpoint (output folder of `rktsph run`)");
  resume_cmd->add_option("folder", resume.out_dir, "Output folder of the interrupted run")->required();
  resume_cmd->add_option("--set,-s", resume.overrides, "Override time.end or an output.* key, e.g. --set time.end=20");
  resume_cmd->add_option("--threads,-j", resume.threads, "Number of threads (default: all cores)")
      ->check(CLI::NonNegativeNumber);
  resume_cmd->add_flag("--quiet,-q", resume.quiet, "No progress output");

  std::string mp_file, mp_out;
  std::vector<std::string> mp_overrides;
  auto* mp_cmd =
      app.add_subcommand("material-point", "Drive one material point along a stress/strain path (path.csv + plot)");
  mp_cmd->add_option("case", mp_file, "Material-point file (TOML)")->required()->check(CLI::ExistingFile);
  mp_cmd->add_option("--out,-o", mp_out, "Output folder (default: out/<file name>)");
  mp_cmd->add_option("--set,-s", mp_overrides, "Override a key, e.g. --set material.fluidity=10");

  auto* mat_cmd = app.add_subcommand("materials", "List the constitutive models");

  validation::Options val;
  val.cases_dir = std::string(RKTSPH_SOURCE_DIR) + "/cases/thesis";
  bool val_quick = false;
  auto* val_cmd =
      app.add_subcommand("validate", "Run the thesis cases against their references; write validation/report.md");
  val_cmd->add_option("cases", val.only, "Case numbers to run, e.g. 01 (default: all)");
  auto* full_flag = val_cmd->add_flag("--full", val.full, "docs/cases.md acceptance resolutions");
  val_cmd->add_flag("--quick", val_quick, "Coarse resolutions that fit in CI (default)")->excludes(full_flag);
  val_cmd->add_option("--out,-o", val.out_dir, "Report folder (default: validation)");
  val_cmd->add_option("--cases-dir", val.cases_dir, "Folder of the thesis case files");
  val_cmd->add_flag("!--no-plots", val.plots, "Skip the matplotlib plots");
  val_cmd->add_option("--threads,-j", run.threads, "Number of threads")->check(CLI::NonNegativeNumber);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }

  try {
    if (run_cmd->parsed()) return run_case(run);
    if (resume_cmd->parsed()) return resume_case(resume);
    if (mp_cmd->parsed()) return run_material_point(mp_file, mp_out, mp_overrides);
    if (val_cmd->parsed()) {
      if (run.threads > 0) omp_set_num_threads(run.threads);
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
