#include "schemes/body_output.hpp"

#include <cmath>

#include <fmt/format.h>

namespace rktsph {

std::string body_csv_header() {
  return "t,body,ux,uy,vx,vy,Fx,Fy,contact_width,contact_nodes,node_projections,stress_point_projections,work,"
         "min_gap\n";
}

std::string body_csv_row(double t, const std::string& name, const BodyState& st) {
  const double gap = std::isfinite(st.min_gap) ? st.min_gap : 0.0;
  return fmt::format("{:.10g},{},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{},{},{},{:.10g},{:.10g}\n", t,
                     name, st.offset[0], st.offset[1], st.velocity[0], st.velocity[1], st.force[0], st.force[1],
                     st.width, st.contact_nodes, st.node_projections, st.stress_point_projections, st.work, gap);
}

void add_body_report(const std::string& name, const BodyState& st, std::vector<std::pair<std::string, double>>& out) {
  out.emplace_back(name + ".Fx", st.force[0]);
  out.emplace_back(name + ".Fy", st.force[1]);
  out.emplace_back(name + ".contact_width", st.width);
  out.emplace_back(name + ".contact_nodes", static_cast<double>(st.contact_nodes));
  out.emplace_back(name + ".node_projections", static_cast<double>(st.node_projections));
  out.emplace_back(name + ".stress_point_projections", static_cast<double>(st.stress_point_projections));
  out.emplace_back(name + ".displacement_x", st.offset[0]);
  out.emplace_back(name + ".displacement_y", st.offset[1]);
  out.emplace_back(name + ".work", st.work);
}

}  // namespace rktsph
