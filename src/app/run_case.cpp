// `rktsph run` and `rktsph resume`: the output folder and the case, then the time loop
// (app/run_loop.cpp).
#include "app/run_case.hpp"

#include <omp.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/run_loop.hpp"
#include "core/error.hpp"
#include "io/checkpoint.hpp"
#include "io/output_files.hpp"
#include "rktsph/version.hpp"

namespace rktsph {

namespace fs = std::filesystem;

namespace {

// A temporary file of an atomic write (io/output_files.hpp: NAME.tmpPID), left by a killed run.
bool is_temporary(const std::string& name) {
  const auto at = name.rfind(".tmp");
  return at != std::string::npos && at + 4 < name.size() &&
         name.find_first_not_of("0123456789", at + 4) == std::string::npos;
}

// Files of an rktsph output folder that a new run replaces. A run killed while it wrote its
// first summary leaves only that summary's temporary file: still an rktsph folder.
bool is_run_output(const fs::path& dir) {
  if (fs::exists(dir / "summary.json") || fs::exists(dir / "case.resolved.toml")) return true;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("summary.json", 0) == 0 && is_temporary(name)) return true;
  }
  return false;
}

// Remove the temporary files of atomic writes that a killed run left in the output folder and
// its vtu/ and checkpoint/ folders.
void remove_temporaries(const fs::path& out) {
  std::error_code ec;
  for (const fs::path& dir : {out, out / "vtu", out / "checkpoint"}) {
    if (!fs::is_directory(dir, ec)) continue;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
      if (is_temporary(e.path().filename().string())) fs::remove(e.path(), ec);
    }
  }
}

// summary.json before anything else is done: a run killed during its set-up still leaves one
// (replaced by the loop's "running" one, then by the final one).
void write_starting_summary(const fs::path& out, const std::string& case_file) {
  io::write_file_atomically(
      (out / "summary.json").string(),
      fmt::format("{{\n  \"case\": {},\n  \"status\": \"starting\",\n  \"message\": \"\",\n  \"version\": \"{}\",\n  "
                  "\"git_revision\": \"{}\"\n}}\n",
                  nlohmann::json(case_file).dump(), kVersion, kGitRevision));
}

// Make `out` ready for a fresh run: create it, or clear the output of an earlier run in it.
// Refuses the filesystem root and a folder that holds something else (InputError).
void prepare_output_folder(const fs::path& out, const std::string& case_file, bool quiet) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(out, ec);
  if (out.empty() || (!ec && absolute == absolute.root_path())) {
    throw InputError(fmt::format("--out '{}': not a usable output folder (the filesystem root)", out.string()));
  }
  if (fs::exists(out, ec) && !fs::is_directory(out, ec)) {
    throw InputError(fmt::format("--out '{}': exists and is not a folder", out.string()));
  }
  if (fs::is_directory(out, ec) && !fs::is_empty(out, ec)) {
    if (!is_run_output(out)) {
      throw InputError(fmt::format("--out '{}': the folder holds files that are not the output of an rktsph run; "
                                   "choose an empty or new folder",
                                   out.string()));
    }
    // The output of an earlier run: its frames, tables and checkpoint go (stale frames would
    // otherwise sit beside the new ones in ParaView).
    write_starting_summary(out, case_file);  // replaces the old one, never leaves none
    for (const char* f : {"probes.csv", "energy.csv", "nodes.pvd", "elements.pvd", "case.resolved.toml"}) {
      fs::remove(out / f, ec);
    }
    fs::remove_all(out / "vtu", ec);
    fs::remove_all(out / "checkpoint", ec);
    remove_temporaries(out);
    if (!quiet) std::cerr << fmt::format("replacing the output of an earlier run in {}\n", out.string());
  }
  fs::create_directories(out / "vtu", ec);
  if (ec) throw InputError(io::system_error_text("create the output folder", out.string(), ec.value()));
  write_starting_summary(out, case_file);
}

std::string document_text(const CaseDocument& doc) {
  std::ostringstream text;
  text << doc.table;
  return text.str();
}

int dispatch(const LoopInput& input) {
  const int dim = case_dimension(input.document);
  if (dim == 1) return run_loop<1>(input);
  if (dim == 3) return run_loop<3>(input);
  return run_loop<2>(input);
}

}  // namespace

int run_case(const RunOptions& opt) {
  if (opt.threads > 0) omp_set_num_threads(opt.threads);
  LoopInput input;
  input.options = opt;
  input.document = load_case_document(opt.case_file, opt.overrides);
  (void)case_dimension(input.document);  // checked before the folder is touched
  const std::string case_name = fs::path(opt.case_file).stem().string();
  input.out = opt.out_dir.empty() ? fs::path("out") / case_name : fs::path(opt.out_dir);
  prepare_output_folder(input.out, opt.case_file, opt.quiet);
  io::write_file_atomically((input.out / "case.resolved.toml").string(),
                            fmt::format("# resolved input of {} (rktsph {}, {})\n{}\n", opt.case_file, kVersion,
                                        kGitRevision, document_text(input.document)),
                            false);
  return dispatch(input);
}

int resume_case(const RunOptions& opt) {
  if (opt.threads > 0) omp_set_num_threads(opt.threads);
  const fs::path out(opt.out_dir);
  const fs::path file = out / "checkpoint" / "checkpoint.h5";
  if (!fs::is_directory(out)) throw InputError(fmt::format("{}: no such output folder", out.string()));
  if (!fs::exists(file)) {
    throw InputError(fmt::format("{}: no checkpoint to resume from ({} does not exist)", out.string(), file.string()));
  }
  for (const std::string& o : opt.overrides) {
    const std::string key = o.substr(0, o.find('='));
    if (key != "time.end" && key.rfind("output.", 0) != 0) {
      throw InputError(fmt::format("--set '{}': a resumed run continues the same case; only time.end and output.* "
                                   "may change",
                                   o));
    }
  }
  const io::StateArchive checkpoint = io::read_checkpoint(file.string());
  remove_temporaries(out);
  LoopInput input;
  input.options = opt;
  input.options.case_file = checkpoint.text("case/file");
  input.document = parse_case_document(checkpoint.text("case/document"),
                                       fmt::format("{} (the case of the checkpoint)", file.string()), opt.overrides);
  // Particle files are read again from beside the original case file; the particles'
  // fingerprint in the checkpoint tells whether they are still the same.
  input.document.directory = std::filesystem::path(input.options.case_file).parent_path().string();
  if (case_dimension(input.document) != checkpoint.integer("case/dimension")) {
    throw InputError(fmt::format("{}: a damaged checkpoint (its case and its state disagree on the dimension)",
                                 file.string()));
  }
  input.out = out;
  input.checkpoint = &checkpoint;
  return dispatch(input);
}

}  // namespace rktsph
