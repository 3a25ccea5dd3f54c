#include "schemes/registry.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/error.hpp"

namespace rktsph {

namespace {

template <int Dim>
struct Entry {
  SchemeInfo info;
  SchemeFactory<Dim> make;
};

template <int Dim>
std::vector<Entry<Dim>>& entries() {
  static std::vector<Entry<Dim>> list = [] {
    std::vector<Entry<Dim>> builtin;
    builtin.push_back({{"v1", "dry soil, small deformation: the staggered RKT-SPH step (method-notes §5.1)", false},
                       make_v1_scheme<Dim>});
    builtin.push_back(
        {{"v3", "saturated soil, small deformation: v-p_w fractional step with PCG (method-notes §5.3)", true},
         make_v3_scheme<Dim>});
    builtin.push_back({{"v2",
                        "dry soil, large deformation: moving particles, Jaumann rate, simple second step "
                        "(method-notes §5.2)",
                        false},
                       make_v2_scheme<Dim>});
    return builtin;
  }();
  return list;
}

}  // namespace

template <int Dim>
void register_scheme(SchemeInfo info, SchemeFactory<Dim> factory) {
  if (find_scheme<Dim>(info.name) != nullptr) {
    throw SolverError(fmt::format("a scheme named '{}' is already registered for {}D", info.name, Dim));
  }
  entries<Dim>().push_back({std::move(info), std::move(factory)});
}

template <int Dim>
const SchemeInfo* find_scheme(const std::string& name) {
  for (const auto& e : entries<Dim>()) {
    if (e.info.name == name) return &e.info;
  }
  return nullptr;
}

template <int Dim>
std::vector<SchemeInfo> registered_schemes() {
  std::vector<SchemeInfo> out;
  for (const auto& e : entries<Dim>()) out.push_back(e.info);
  return out;
}

template <int Dim>
std::vector<std::string> scheme_names() {
  std::vector<std::string> out;
  for (const auto& e : entries<Dim>()) out.push_back(e.info.name);
  return out;
}

template <int Dim>
std::unique_ptr<Scheme> create_scheme(const std::string& name, StaggeredModel<Dim>& model) {
  for (const auto& e : entries<Dim>()) {
    if (e.info.name == name) return e.make(model);
  }
  throw InputError(fmt::format("{}: unknown solver version '{}' for a {}D case (available: {})", model.setup.file, name,
                               Dim, fmt::join(scheme_names<Dim>(), ", ")));
}

#define RKTSPH_INSTANTIATE(D)                                     \
  template void register_scheme<D>(SchemeInfo, SchemeFactory<D>); \
  template const SchemeInfo* find_scheme<D>(const std::string&);  \
  template std::vector<SchemeInfo> registered_schemes<D>();       \
  template std::vector<std::string> scheme_names<D>();            \
  template std::unique_ptr<Scheme> create_scheme<D>(const std::string&, StaggeredModel<D>&);
RKTSPH_INSTANTIATE(1)
RKTSPH_INSTANTIATE(2)
RKTSPH_INSTANTIATE(3)
#undef RKTSPH_INSTANTIATE

}  // namespace rktsph
