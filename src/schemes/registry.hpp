#pragma once
// The one registry of schemes, keyed by name and dimension (solver.version = "v1", "v3", ...).
// A scheme is made from a model by a factory that registers the fields it needs and lists its
// stages; the built-in schemes are registered on first use, and a new one is added with
// register_scheme() without touching the others (tests/schemes/test_registry.cpp does).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "schemes/scheme.hpp"
#include "schemes/staggered_model.hpp"

namespace rktsph {

struct SchemeInfo {
  std::string name;         // the solver.version key, e.g. "v1"
  std::string description;  // one line, for `rktsph --help` and error messages
  bool pore_fluid = false;  // the scheme needs a [fluid] table (saturated soil)
};

template <int Dim>
using SchemeFactory = std::function<std::unique_ptr<Scheme>(StaggeredModel<Dim>& model)>;

/// Add a scheme for dimension Dim. Throws SolverError if the name is taken.
template <int Dim>
void register_scheme(SchemeInfo info, SchemeFactory<Dim> factory);

/// Make the scheme `name` for a model. Throws InputError naming the known schemes if there is
/// no such scheme in this dimension.
template <int Dim>
std::unique_ptr<Scheme> create_scheme(const std::string& name, StaggeredModel<Dim>& model);

/// The registered schemes of dimension Dim, in registration order.
template <int Dim>
std::vector<SchemeInfo> registered_schemes();
template <int Dim>
std::vector<std::string> scheme_names();
/// The scheme `name`, or nullptr.
template <int Dim>
const SchemeInfo* find_scheme(const std::string& name);

// The built-in schemes (schemes/v1_scheme.cpp, v2_scheme.cpp, v3_scheme.cpp).
template <int Dim>
std::unique_ptr<Scheme> make_v1_scheme(StaggeredModel<Dim>& model);
template <int Dim>
std::unique_ptr<Scheme> make_v3_scheme(StaggeredModel<Dim>& model);
template <int Dim>
std::unique_ptr<Scheme> make_v2_scheme(StaggeredModel<Dim>& model);

}  // namespace rktsph
