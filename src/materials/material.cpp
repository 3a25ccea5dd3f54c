#include "materials/material.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/error.hpp"
#include "materials/source_integrator.hpp"

namespace rktsph {

ElasticConstants ElasticConstants::from_E_nu(double E, double nu, double density) {
  ElasticConstants c;
  c.E = E;
  c.nu = nu;
  c.density = density;
  c.lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  c.G = E / (2.0 * (1.0 + nu));
  c.K = E / (3.0 * (1.0 - 2.0 * nu));
  c.M = c.lambda + 2.0 * c.G;
  return c;
}

ElasticConstants ElasticConstants::from_K_G(double K, double G, double density) {
  return from_E_nu(9.0 * K * G / (3.0 * K + G), (3.0 * K - 2.0 * G) / (2.0 * (3.0 * K + G)), density);
}

double ElasticConstants::p_wave_speed() const { return std::sqrt((K + 4.0 * G / 3.0) / density); }

Sym6 ElasticConstants::apply(const Sym6& e) const {
  const double tr = e[0] + e[1] + e[2];
  return {lambda * tr + 2.0 * G * e[0],
          lambda * tr + 2.0 * G * e[1],
          lambda * tr + 2.0 * G * e[2],
          2.0 * G * e[3],
          2.0 * G * e[4],
          2.0 * G * e[5]};
}

Sym6 ElasticConstants::apply_inverse(const Sym6& s) const {
  const double tr = s[0] + s[1] + s[2];
  const double a = -nu / E * tr;
  const double b = (1.0 + nu) / E;
  return {a + b * s[0], a + b * s[1], a + b * s[2], b * s[3], b * s[4], b * s[5]};
}

void Material::source_rate(const Sym6& /*sigma*/, const double* /*state*/, Sym6& dsigma, double* dstate) const {
  dsigma.fill(0.0);
  for (int i = 0; i < state_size(); ++i) dstate[i] = 0.0;
}

double Material::relaxation_rate(const Sym6& /*sigma*/, const double* /*state*/) const { return 0.0; }

SourceStats Material::advance_source(double tau, const SourceBatch& b) const {
  return detail::integrate_source_batch(
      tau, b, state_size(), [this](const Sym6& s, const double* k, Sym6& ds, double* dk) { source_rate(s, k, ds, dk); },
      [this](const Sym6& s, const double* k) { return relaxation_rate(s, k); });
}

}  // namespace rktsph
