#pragma once
// The search of `rktsph fos` for the factor of safety by strength reduction (docs/fos.md,
// docs/method-notes.md §10): which trial factors F to run, from the outcomes of the trials run so
// far. Pure logic, no solver: a trial is only "stable" or "not stable" here (app/fos.cpp runs and
// classifies it).
//
// The sequential search: F = 1 first (it must be stable), then F = growth^k upward until a trial
// is not stable, then bisection of the bracket [lo, hi] (lo the largest stable F below hi, hi the
// smallest F that is not stable) until hi - lo <= tolerance * lo; the answer is (lo + hi) / 2.
// Parallel trials do not change it: `speculative_batch` picks the factors the sequential search
// may ask for next (the first levels of its decision tree), so that with any number of trials at
// once the search takes the same path and gives the same F bit for bit; the trials off that path
// are reported as speculative and do not count towards max_trials.
#include <functional>
#include <map>
#include <optional>
#include <vector>

namespace rktsph::fos {

struct SearchSettings {
  double start = 1.0;       // the unreduced strength, F = 1
  double growth = 1.25;     // expansion factor while every trial stands (> 1)
  double tolerance = 0.01;  // relative width of the final bracket: (hi - lo) / lo
  int max_trials = 12;      // trials the search may use (the speculative ones not counted)
};

struct Step {
  double factor = 0.0;
  bool stable = false;
};

enum class SearchState {
  running,          // `next` is the factor to run
  converged,        // bracket [lo, hi] within the tolerance
  unreduced_fails,  // the first trial (F = start) is not stable
  bracket_open,     // max_trials used and the bracket is not closed to the tolerance
};
const char* state_name(SearchState s);

struct SearchStatus {
  SearchState state = SearchState::running;
  double next = 0.0;  // when running
  // The bracket so far: lo the largest stable factor below hi (0 if none), hi the smallest factor
  // that is not stable (infinity if none).
  double lo = 0.0;
  double hi = 0.0;
  /// (lo + hi) / 2 once converged, else NaN.
  double factor() const;
};

/// The sequential search's status after the trials `path` (in the order it asked for them).
SearchStatus status_after(const SearchSettings& settings, const std::vector<Step>& path);

/// Up to `width` distinct factors, not in `known`, that the sequential search asks for from
/// `path` on, breadth first over the outcomes of the trials it has not seen yet (for each
/// unknown trial the branch "not stable" is explored before "stable"). Empty when the search
/// has ended. `known` maps a factor already run to its outcome (stable = true).
std::vector<double> speculative_batch(const SearchSettings& settings, const std::vector<Step>& path,
                                      const std::map<double, bool>& known, int width);

/// Extend `path` along the known outcomes as far as the sequential search goes; returns its
/// status there (running: `next` is not known yet).
SearchStatus follow(const SearchSettings& settings, std::vector<Step>& path, const std::map<double, bool>& known);

/// Runs the outcomes of a batch of factors (stable = true), in the order given.
using BatchEvaluator = std::function<std::vector<bool>(const std::vector<double>&)>;

/// The whole search: batches of up to `width` factors (speculative_batch) evaluated by
/// `evaluate`, until the sequential search ends. `path` receives the trials on the search's path,
/// `known` every trial run. An exception of `evaluate` propagates (what was run stays in `known`).
SearchStatus run_search(const SearchSettings& settings, int width, const BatchEvaluator& evaluate,
                        std::vector<Step>& path, std::map<double, bool>& known);

}  // namespace rktsph::fos
