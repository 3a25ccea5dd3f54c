#pragma once
// What a stage that carries rigid bodies gives the output: bodies.csv rows (docs/output.md) and
// the per-body figures of the log and summary.json. Implemented by V2's contact stage and by the
// small-deformation bodies of V1 and V3, so that both write the same file.
#include <string>
#include <utility>
#include <vector>

#include "bodies/contact.hpp"

namespace rktsph {

class BodyOutput {
 public:
  virtual ~BodyOutput() = default;
  /// One row per body at time t.
  virtual std::string csv_rows(double t) const = 0;
  /// contact.csv (V2's contact only): one row per contact node of every body at time t.
  virtual bool has_contact_profile() const { return false; }
  virtual std::string contact_rows(double /*t*/) const { return {}; }
};

/// contact.csv: the header, and the rows of the contact nodes in `profile` at time t.
std::string contact_csv_header();
std::string contact_csv_rows(double t, const std::vector<std::string>& body_names,
                             const std::vector<ContactPoint>& profile);

/// bodies.csv: the header, and the row of body `name` in state `st` at time t.
std::string body_csv_header();
std::string body_csv_row(double t, const std::string& name, const BodyState& st);
/// The figures of one body for the log and summary.json ("<name>.Fx", ...).
void add_body_report(const std::string& name, const BodyState& st, std::vector<std::pair<std::string, double>>& out);

}  // namespace rktsph
