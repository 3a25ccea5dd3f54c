// V2's free surface (method-notes §3.6-3.7) on a spinning elastic square, free of any boundary
// entry: after a turn of about 34 degrees the flagged nodes are the square's faces, the
// detected normals are its rotated face normals, and the nodal stress is traction-free in the
// rotated frame. Keeping the faces of the initial lattice (global axes) instead leaves a
// traction of the order of the stress on the turned faces.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <tuple>

#include <fmt/format.h>

#include "../support/test_util.hpp"
#include "case/case_builder.hpp"
#include "case/case_reader.hpp"
#include "schemes/simulation.hpp"
#include "schemes/v2_stages.hpp"

namespace rktsph {
namespace {

struct SpinResult {
  double theta = 0.0;              // rad, the turn fitted to the node positions
  int face_nodes = 0;              // nodes on the square's faces, corners left out
  int wrongly_flagged = 0;         // interior nodes flagged, or face nodes not flagged
  double worst_normal_angle = 0;   // rad, detected against the rotated face normal
  double traction_residual = 0.0;  // max |sigma n| over the face nodes / max |sigma|, n exact
  double corner_residual = 0.0;    // max |sigma n| at the corners over both faces' n / max |sigma|
  double external_work = 0.0;      // J/m: no load acts on the free square
  double kinetic_start = 0.0, kinetic_end = 0.0;
};

SpinResult spin(bool detect, double end = 1.0) {
  const test::ThreadCount threads(1);
  const double omega = 0.6;  // rad/s
  CaseBuilder<2> b("spinning square");
  b.spacing(0.1)
      .origin(Vec<2>(-1.0, -1.0))
      .block(Vec<2>(-1.0, -1.0), Vec<2>(1.0, 1.0))
      .elastic(1.0e7, 0.3, 2000.0)
      .scheme("v2")
      .free_surface(detect)
      .initial_velocity(Vec<2>::Zero(), omega)
      .time(end, 0.5);
  Simulation<2> sim(b.build());
  const std::vector<Vec<2>> made = sim.nodes().position;
  SpinResult r;
  r.kinetic_start = sim.energy().kinetic;
  while (sim.time() < end - 1e-12) sim.step();
  // Where each node now started (V2 sorts its nodes as they move; ids are the made order).
  std::vector<Vec<2>> start(made.size());
  for (std::size_t i = 0; i < made.size(); ++i) {
    start[i] = made[static_cast<std::size_t>(sim.nodes().global_id[i])];
  }
  r.external_work = sim.energy().external_work;
  r.kinetic_end = sim.energy().kinetic;

  const auto& x = sim.nodes().position;
  double cross = 0.0, dot = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    cross += start[i][0] * x[i][1] - start[i][1] * x[i][0];
    dot += start[i].dot(x[i]);
  }
  r.theta = std::atan2(cross, dot);
  const double c = std::cos(r.theta), s = std::sin(r.theta);
  const auto stress = sim.node_stress();
  double scale = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double sxx = stress(i, StressComponent::xx), syy = stress(i, StressComponent::yy);
    const double sxy = stress(i, StressComponent::xy);
    scale = std::max(scale, std::sqrt(sxx * sxx + syy * syy + 2.0 * sxy * sxy));
  }
  const Field<double, 1> flag_field = sim.nodes().template find<double, 1>("free_surface");
  const Field<double, 2> normal_field = sim.nodes().template find<double, 2>("normal");
  for (std::size_t i = 0; i < x.size(); ++i) {
    const bool on_x_face = std::abs(std::abs(start[i][0]) - 1.0) < 1e-9;
    const bool on_y_face = std::abs(std::abs(start[i][1]) - 1.0) < 1e-9;
    if (detect) {
      const bool flagged = sim.nodes().view(flag_field)(i, 0) != 0.0;
      if (flagged != (on_x_face || on_y_face)) ++r.wrongly_flagged;
    }
    auto traction = [&](const Vec<2>& n) {
      const double tx = stress(i, StressComponent::xx) * n[0] + stress(i, StressComponent::xy) * n[1];
      const double ty = stress(i, StressComponent::xy) * n[0] + stress(i, StressComponent::yy) * n[1];
      return std::hypot(tx, ty) / scale;
    };
    const Vec<2> ex(c, s), ey(-s, c);  // the turned face normals
    if (on_x_face && on_y_face) {
      // A corner: free of traction on both faces, so of all in-plane stress.
      r.corner_residual = std::max({r.corner_residual, traction(ex), traction(ey)});
      continue;
    }
    if (!on_x_face && !on_y_face) continue;
    ++r.face_nodes;
    const Vec<2> n0 =
        on_x_face ? Vec<2>(std::copysign(1.0, start[i][0]), 0.0) : Vec<2>(0.0, std::copysign(1.0, start[i][1]));
    const Vec<2> n(c * n0[0] - s * n0[1], s * n0[0] + c * n0[1]);
    if (detect) {
      const auto nd = sim.nodes().view(normal_field);
      const Vec<2> found(nd(i, 0), nd(i, 1));
      r.worst_normal_angle = std::max(r.worst_normal_angle, std::acos(std::clamp(found.dot(n), -1.0, 1.0)));
    }
    r.traction_residual = std::max(r.traction_residual, traction(n));
  }
  return r;
}

TEST(V2FreeSurface, ASpinningSquareKeepsItsFacesTractionFreeInTheTurnedFrame) {
  const SpinResult detected = spin(true);
  // The lattice faces' normals on a turned square are wrong: their "traction-free" condition
  // works on the body, which the simple scheme's numerical viscosity absorbed; with V2's
  // hourglass control it pumps energy in until the run stops at 0.76 s. Compared at 0.5 s.
  const SpinResult faces = spin(false, 0.5);
  EXPECT_NEAR(detected.theta, 0.6, 0.02);
  EXPECT_EQ(detected.face_nodes, 4 * 19);
  EXPECT_EQ(detected.wrongly_flagged, 0);
  // The normal of every face node, the corners' neighbours included, comes from the chords to
  // its two neighbours on the face; the four corners carry no in-plane stress. Measured: normals
  // within 0.021 degrees, residual 2e-4 of the peak stress (0.55 with the lattice faces), corners 0.
  EXPECT_LT(detected.worst_normal_angle, 0.5 * std::numbers::pi / 180.0);
  EXPECT_LT(detected.traction_residual, 0.01);
  EXPECT_LT(detected.corner_residual, 0.01);
  EXPECT_GT(faces.traction_residual, 0.2);
  // The turned faces do no work: their traction is zero in their own frame (with the lattice
  // normals the stress on a turned face would seem to work on it).
  EXPECT_EQ(detected.external_work, 0.0);
  EXPECT_NEAR(detected.kinetic_end / detected.kinetic_start, 1.0, 0.02);
  std::printf(
      "theta %.4f rad; normals within %.3f deg; traction residual %.4f (detected) %.4f (lattice faces);"
      " corners %.2g\n",
      detected.theta, detected.worst_normal_angle * 180.0 / std::numbers::pi, detected.traction_residual,
      faces.traction_residual, detected.corner_residual);
}

// The same in 3D (geometry.dimension = 3): an elastic cube spinning about z, free of any
// boundary entry. After a turn of about 34 degrees the flagged nodes are those that started on
// its faces, the detected normals are the turned face normals up to the edges, and the faces,
// edges and corners carry no traction in the turned frame.
TEST(V2FreeSurface, ASpinningCubeIsFlaggedOnItsFacesAndKeepsThemTractionFree) {
  const test::ThreadCount threads(1);
  const double omega = 1.0, end = 0.6;  // rad/s, s
  CaseBuilder<3> b("spinning cube");
  b.spacing(0.1)
      .origin(Vec<3>(-0.5, -0.5, -0.5))
      .block(Vec<3>(-0.5, -0.5, -0.5), Vec<3>(0.5, 0.5, 0.5))
      .elastic(1.0e7, 0.3, 2000.0)
      .scheme("v2")
      .free_surface(true)
      .initial_velocity(Vec<3>::Zero(), Vec<3>(0.0, 0.0, omega), Vec<3>::Zero())
      .time(end, 0.5);
  Simulation<3> sim(b.build());
  const std::vector<Vec<3>> made = sim.nodes().position;
  const double kinetic_start = sim.energy().kinetic;
  while (sim.time() < end - 1e-12) sim.step();
  std::vector<Vec<3>> start(made.size());
  for (std::size_t i = 0; i < made.size(); ++i) start[i] = made[static_cast<std::size_t>(sim.nodes().global_id[i])];
  const auto& x = sim.nodes().position;
  double cross = 0.0, dot = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    cross += start[i][0] * x[i][1] - start[i][1] * x[i][0];
    dot += start[i][0] * x[i][0] + start[i][1] * x[i][1];
  }
  const double theta = std::atan2(cross, dot), c = std::cos(theta), s = std::sin(theta);
  const auto stress = sim.node_stress();
  auto sigma = [&](std::size_t i) {
    Eigen::Matrix3d m;
    m << stress(i, StressComponent::xx), stress(i, StressComponent::xy), stress(i, StressComponent::xz),
        stress(i, StressComponent::xy), stress(i, StressComponent::yy), stress(i, StressComponent::yz),
        stress(i, StressComponent::xz), stress(i, StressComponent::yz), stress(i, StressComponent::zz);
    return m;
  };
  double scale = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) scale = std::max(scale, sigma(i).norm());
  const Field<double, 1> flag_field = sim.nodes().template find<double, 1>("free_surface");
  const Field<double, 3> normal_field = sim.nodes().template find<double, 3>("normal");
  int flagged = 0, wrongly_flagged = 0, face_nodes = 0;
  double worst_angle = 0.0, residual = 0.0, edge_residual = 0.0;
  std::array<double, 4> band_angle{}, band_residual{};  // by distance to an edge: 1, 2, 3+ spacings
  for (std::size_t i = 0; i < x.size(); ++i) {
    int faces = 0;
    Vec<3> n0 = Vec<3>::Zero();
    for (int d = 0; d < 3; ++d) {
      if (std::abs(std::abs(start[i][d]) - 0.5) < 1e-9) {
        ++faces;
        n0[d] = std::copysign(1.0, start[i][d]);
      }
    }
    const bool is_flagged = sim.nodes().view(flag_field)(i, 0) != 0.0;
    flagged += is_flagged ? 1 : 0;
    if (is_flagged != (faces > 0)) ++wrongly_flagged;
    if (faces == 0) continue;
    const Eigen::Matrix3d sig = sigma(i);
    if (faces > 1) {  // an edge or a corner: free of traction on each of its faces
      for (int d = 0; d < 3; ++d) {
        if (n0[d] == 0.0) continue;
        Vec<3> e = Vec<3>::Zero();
        e[d] = n0[d];
        const Vec<3> n(c * e[0] - s * e[1], s * e[0] + c * e[1], e[2]);
        edge_residual = std::max(edge_residual, (sig * n).norm() / scale);
      }
      continue;
    }
    ++face_nodes;
    const Vec<3> n(c * n0[0] - s * n0[1], s * n0[0] + c * n0[1], n0[2]);
    const auto nd = sim.nodes().view(normal_field);
    const Vec<3> found(nd(i, 0), nd(i, 1), nd(i, 2));
    // The face nodes' distance to the nearest edge of their face, in spacings.
    double to_edge = 1e9;
    for (int d = 0; d < 3; ++d)
      if (n0[d] == 0.0) to_edge = std::min(to_edge, (0.5 - std::abs(start[i][d])) / 0.1);
    const int band = std::min(3, static_cast<int>(std::lround(to_edge)));
    const double angle = std::acos(std::clamp(found.dot(n), -1.0, 1.0));
    band_angle[static_cast<std::size_t>(band)] = std::max(band_angle[static_cast<std::size_t>(band)], angle);
    band_residual[static_cast<std::size_t>(band)] =
        std::max(band_residual[static_cast<std::size_t>(band)], (sig * n).norm() / scale);
    worst_angle = std::max(worst_angle, angle);
    residual = std::max(residual, (sig * n).norm() / scale);
  }
  for (int k = 1; k <= 3; ++k)
    std::printf("face nodes %d%s spacings from an edge: normals within %.3f deg, residual %.2g\n", k, k == 3 ? "+" : "",
                band_angle[static_cast<std::size_t>(k)] * 180.0 / std::numbers::pi,
                band_residual[static_cast<std::size_t>(k)]);
  std::printf(
      "3D: theta %.4f rad; %d flagged, %d wrongly; %d face nodes, normals within %.3f deg, traction residual %.2g; "
      "edges and corners %.2g; kinetic energy end / start %.5f\n",
      theta, flagged, wrongly_flagged, face_nodes, worst_angle * 180.0 / std::numbers::pi, residual, edge_residual,
      sim.energy().kinetic / kinetic_start);
  EXPECT_NEAR(theta, omega * end, 0.02);
  EXPECT_EQ(flagged, 11 * 11 * 11 - 9 * 9 * 9);
  EXPECT_EQ(wrongly_flagged, 0);
  EXPECT_EQ(face_nodes, 6 * 9 * 9);
  // The improved normal in 3D (the four quarters' chords, method-notes eq. (3.6.6)) holds up to
  // the edges. Measured: every face node within 0.035 degrees, |sigma n| 3e-4 of the peak stress
  // (with the first normals the row beside an edge leaned 17.8 degrees towards the other face,
  // 0.07). On the edges and at the corners both faces are traction-free (eq. (3.7.4)): 3e-4
  // (0.21 with the bisecting normal as a face's).
  for (int band = 1; band <= 3; ++band) {
    EXPECT_LT(band_angle[static_cast<std::size_t>(band)], 0.5 * std::numbers::pi / 180.0) << band;
    EXPECT_LT(band_residual[static_cast<std::size_t>(band)], 0.01) << band;
  }
  EXPECT_LT(edge_residual, 0.01);
  EXPECT_EQ(sim.energy().external_work, 0.0);
  EXPECT_NEAR(sim.energy().kinetic / kinetic_start, 1.0, 0.01);
}

// The detected surface against the lattice's own faces (method-notes §3.7): Case 4(b)'s block
// under sudden gravity, axis-aligned so that the lattice faces are exact, run by V2 both ways to
// 0.4 s. With fix (a) at the surface nodes and the corners the detected run follows the faces
// run closely (measured: sigma_yy rms 2.9e-7 rho g H, velocity 8.3e-5 of its peak); without
// them the corner region's velocity departed by 0.6 of the peak.
TEST(V2FreeSurface, ADetectedSurfaceFollowsTheLatticeFacesOnAnAlignedBlock) {
  const test::ThreadCount threads(1);
  auto run = [](const char* mode) {
    const std::string file = std::string(RKTSPH_SOURCE_DIR) + "/cases/thesis/04b_elastic_cut_closed_form_2d.toml";
    Simulation<2> sim(
        read_case<2>(load_case_document(file, {"geometry.spacing=0.25", "solver.version=\"v2\"",
                                               fmt::format("solver.free_surface=\"{}\"", mode), "output.times=[]"})));
    while (sim.time() < 0.4 - 1e-12) sim.step();
    std::vector<double> syy, v;
    for (std::size_t i = 0; i < sim.nodes().position.size(); ++i) {
      syy.push_back(sim.node_stress()(i, StressComponent::yy));
      v.push_back(std::hypot(sim.node_velocity()(i, 0), sim.node_velocity()(i, 1)));
    }
    return std::pair{syy, v};
  };
  const auto [syy_d, v_d] = run("detect");
  const auto [syy_f, v_f] = run("faces");
  ASSERT_EQ(syy_d.size(), syy_f.size());
  const double rho_g_H = 2000.0 * 9.81 * 10.0;
  double sum = 0.0, dv = 0.0, vmax = 0.0;
  for (std::size_t i = 0; i < syy_d.size(); ++i) {
    sum += (syy_d[i] - syy_f[i]) * (syy_d[i] - syy_f[i]);
    dv = std::max(dv, std::abs(v_d[i] - v_f[i]));
    vmax = std::max(vmax, v_f[i]);
  }
  const double rms = std::sqrt(sum / static_cast<double>(syy_d.size())) / rho_g_H;
  std::printf("detected against lattice faces: sigma_yy rms %.2g rho g H, velocity %.2g of its peak\n", rms, dv / vmax);
  EXPECT_LT(rms, 1e-4);
  EXPECT_LT(dv / vmax, 1e-2);
}

// The settled interior (method-notes §3.6): a detection that skips the nodes found well inside
// the body at its last full pass, until some node has moved surface_refresh dx, gives the flags
// and normals of a full detection every step. Case 9's collapsing slope (the block falls and
// spreads along the base against the wall; its surface changes everywhere) run to 1 s both ways
// is bit-identical, while most detections skipped the interior.
TEST(V2FreeSurface, TheSettledInteriorGivesTheSurfaceOfAFullDetectionEveryStep) {
  const test::ThreadCount threads(1);
  auto run = [](double refresh) {
    const std::string file = std::string(RKTSPH_SOURCE_DIR) + "/cases/thesis/09_low_cohesion_slope_2d.toml";
    auto sim = std::make_unique<Simulation<2>>(read_case<2>(load_case_document(
        file, {"geometry.spacing=0.5", fmt::format("solver.surface_refresh={}", refresh), "output.times=[]"})));
    long steps = 0, surface_steps = 0;
    const Field<double, 1> flag = sim->nodes().template find<double, 1>("free_surface");
    while (sim->time() < 1.0 - 1e-12) {
      sim->step();
      ++steps;
      for (Index i = 0; i < sim->nodes().size(); ++i) surface_steps += sim->nodes().view(flag)(i, 0) != 0.0 ? 1 : 0;
    }
    double full = 0.0, partial = 0.0;
    for (const auto& [key, value] : sim->scheme().find<DetectFreeSurface<2>>()->report()) {
      if (key == "detection_full_passes") full = value;
      if (key == "detection_partial_passes") partial = value;
    }
    std::printf("surface_refresh %.2f: %ld steps, %.0f full and %.0f partial detections, %ld surface node-steps\n",
                refresh, steps, full, partial, surface_steps);
    return std::tuple{std::move(sim), full, partial};
  };
  const auto [every, full_every, partial_every] = run(0.0);
  const auto [settled, full_settled, partial_settled] = run(0.1);
  EXPECT_EQ(partial_every, 0.0);
  EXPECT_GT(partial_settled, 2.0 * full_settled) << "most detections skip the settled interior";
  const auto& a = every->model();
  const auto& b = settled->model();
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  const auto sa = std::as_const(a.nodes).view(a.fields.stress), sb = std::as_const(b.nodes).view(b.fields.stress);
  const auto va = std::as_const(a.nodes).view(a.fields.velocity), vb = std::as_const(b.nodes).view(b.fields.velocity);
  long differ = 0;
  for (Index i = 0; i < a.nodes.size(); ++i) {
    const auto iu = static_cast<std::size_t>(i);
    differ += a.nodes.position[iu] != b.nodes.position[iu] ? 1 : 0;
    for (int k = 0; k < 4; ++k) differ += sa(i, k) != sb(i, k) ? 1 : 0;
    for (int k = 0; k < 2; ++k) differ += va(i, k) != vb(i, k) ? 1 : 0;
  }
  EXPECT_EQ(differ, 0) << "positions, stresses and velocities bit for bit";
}

}  // namespace
}  // namespace rktsph
