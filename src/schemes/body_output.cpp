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
  out.emplace_back(name + ".free_corners", static_cast<double>(st.free_corners));
  out.emplace_back(name + ".displacement_x", st.offset[0]);
  out.emplace_back(name + ".displacement_y", st.offset[1]);
  out.emplace_back(name + ".work", st.work);
}

std::string contact_csv_header() { return "t,body,node,s,x,y,nx,ny,width,normal_stress,shear_stress\n"; }

std::string contact_csv_rows(double t, const std::vector<std::string>& body_names,
                             const std::vector<ContactPoint>& profile) {
  std::string rows;
  for (const ContactPoint& p : profile) {
    rows += fmt::format("{:.10g},{},{},{:.10g},{:.10g},{:.10g},{:.8g},{:.8g},{:.6g},{:.8g},{:.8g}\n", t,
                        body_names[static_cast<std::size_t>(p.body)], p.node, p.s, p.x[0], p.x[1], p.normal[0],
                        p.normal[1], p.width, p.normal_stress, p.shear_stress);
  }
  return rows;
}

}  // namespace rktsph
