#include "app/fos_search.hpp"

#include <cmath>
#include <algorithm>
#include <deque>
#include <limits>
#include <stdexcept>

namespace rktsph::fos {

const char* state_name(SearchState s) {
  switch (s) {
    case SearchState::running:
      return "running";
    case SearchState::converged:
      return "converged";
    case SearchState::unreduced_fails:
      return "unreduced_fails";
    default:
      return "bracket_open";
  }
}

double SearchStatus::factor() const {
  return state == SearchState::converged ? 0.5 * (lo + hi) : std::numeric_limits<double>::quiet_NaN();
}

SearchStatus status_after(const SearchSettings& settings, const std::vector<Step>& path) {
  SearchStatus s;
  s.hi = std::numeric_limits<double>::infinity();
  if (path.empty()) {
    s.next = settings.start;
    return s;
  }
  if (!path.front().stable) {
    s.state = SearchState::unreduced_fails;
    s.hi = path.front().factor;
    return s;
  }
  for (const Step& t : path) {
    if (!t.stable) s.hi = std::min(s.hi, t.factor);
  }
  // lo below hi: a stable trial above a failed one (a non-monotone outcome) does not move it.
  for (const Step& t : path) {
    if (t.stable && t.factor < s.hi) s.lo = std::max(s.lo, t.factor);
  }
  const bool closed = std::isfinite(s.hi);
  // method-notes eq. (10.3): the bracket is closed to the tolerance.
  if (closed && s.hi - s.lo <= settings.tolerance * s.lo) {
    s.state = SearchState::converged;
    return s;
  }
  if (static_cast<int>(path.size()) >= settings.max_trials) {
    s.state = SearchState::bracket_open;
    return s;
  }
  // method-notes eq. (10.2): expand geometrically while every trial stands, then bisect.
  s.next = closed ? 0.5 * (s.lo + s.hi) : s.lo * settings.growth;
  return s;
}

SearchStatus follow(const SearchSettings& settings, std::vector<Step>& path, const std::map<double, bool>& known) {
  for (;;) {
    const SearchStatus s = status_after(settings, path);
    if (s.state != SearchState::running) return s;
    const auto hit = known.find(s.next);
    if (hit == known.end()) return s;
    path.push_back({s.next, hit->second});
  }
}

std::vector<double> speculative_batch(const SearchSettings& settings, const std::vector<Step>& path,
                                      const std::map<double, bool>& known, int width) {
  std::vector<double> batch;
  std::deque<std::vector<Step>> queue{path};
  // Each level at most doubles the queue; the paths end at max_trials, so this terminates.
  while (!queue.empty() && static_cast<int>(batch.size()) < width) {
    std::vector<Step> p = std::move(queue.front());
    queue.pop_front();
    const SearchStatus s = status_after(settings, p);
    if (s.state != SearchState::running) continue;
    const auto hit = known.find(s.next);
    if (hit != known.end()) {
      p.push_back({s.next, hit->second});
      queue.push_back(std::move(p));
      continue;
    }
    bool queued = false;
    for (double f : batch) queued = queued || f == s.next;
    if (!queued) batch.push_back(s.next);
    std::vector<Step> fails = p;
    fails.push_back({s.next, false});
    p.push_back({s.next, true});
    queue.push_back(std::move(fails));
    queue.push_back(std::move(p));
  }
  return batch;
}

SearchStatus run_search(const SearchSettings& settings, int width, const BatchEvaluator& evaluate,
                        std::vector<Step>& path, std::map<double, bool>& known) {
  for (;;) {
    const SearchStatus s = follow(settings, path, known);
    if (s.state != SearchState::running) return s;
    const std::vector<double> batch = speculative_batch(settings, path, known, std::max(1, width));
    const std::vector<bool> stable = evaluate(batch);
    for (std::size_t k = 0; k < batch.size() && k < stable.size(); ++k) known[batch[k]] = stable[k];
    if (stable.size() < batch.size()) throw std::logic_error("fos: the evaluator returned fewer outcomes than asked");
  }
}

}  // namespace rktsph::fos
