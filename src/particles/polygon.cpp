#include "particles/polygon.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <fmt/format.h>

#include "core/error.hpp"
#include "operators/free_surface.hpp"

namespace rktsph {

namespace {

using P = Vec<2>;

double cross(const P& a, const P& b) { return a[0] * b[1] - a[1] * b[0]; }

// Area (doubled, signed) and first moments (times 6) of a closed polygon by the shoelace formula.
struct Moments {
  double area2 = 0.0;  // 2 A
  double mx6 = 0.0;    // 6 A x_c
  double my6 = 0.0;    // 6 A y_c
  void add(const std::vector<P>& poly) {
    const std::size_t n = poly.size();
    for (std::size_t i = 0; i < n; ++i) {
      const P& a = poly[i];
      const P& b = poly[(i + 1) % n];
      const double c = cross(a, b);
      area2 += c;
      mx6 += (a[0] + b[0]) * c;
      my6 += (a[1] + b[1]) * c;
    }
  }
};

// Sutherland-Hodgman clipping of a ring by the box [lo, hi]. The subject may be concave (and
// clockwise): the result may hold edges doubled along the box, but its winding, and so its
// signed area and moments, are those of the ring within the box.
void clip_to_box(const Ring& ring, const P& lo, const P& hi, std::vector<P>& out, std::vector<P>& work) {
  out = ring;
  for (int side = 0; side < 4; ++side) {
    const int axis = side / 2;
    const bool upper = side % 2 == 1;
    const double bound = upper ? hi[axis] : lo[axis];
    auto inside = [&](const P& p) { return upper ? p[axis] <= bound : p[axis] >= bound; };
    work.clear();
    const std::size_t n = out.size();
    for (std::size_t i = 0; i < n; ++i) {
      const P& a = out[i];
      const P& b = out[(i + 1) % n];
      const bool ia = inside(a), ib = inside(b);
      if (ia) work.push_back(a);
      if (ia != ib) {
        const double t = (bound - a[axis]) / (b[axis] - a[axis]);
        P x = a + t * (b - a);
        x[axis] = bound;
        work.push_back(x);
      }
    }
    std::swap(out, work);
    if (out.empty()) return;
  }
}

double segment_distance(const P& p, const P& a, const P& b) {
  const P ab = b - a;
  const double l2 = ab.squaredNorm();
  double t = l2 > 0.0 ? (p - a).dot(ab) / l2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

double boundary_distance(const PolygonBody& body, const P& p) {
  double d = std::numeric_limits<double>::infinity();
  for (int r = 0; r < body.rings(); ++r) {
    const Ring& ring = body.ring(r);
    for (std::size_t i = 0; i < ring.size(); ++i) d = std::min(d, segment_distance(p, ring[i], ring[(i + 1) % ring.size()]));
  }
  return d;
}

// Orientation of (a, b, c): > 0 left turn, < 0 right, 0 collinear (within tol).
int orientation(const P& a, const P& b, const P& c, double tol) {
  const double v = cross(b - a, c - a);
  return v > tol ? 1 : (v < -tol ? -1 : 0);
}

bool on_segment(const P& a, const P& b, const P& p, double tol) {
  return std::min(a[0], b[0]) - tol <= p[0] && p[0] <= std::max(a[0], b[0]) + tol &&
         std::min(a[1], b[1]) - tol <= p[1] && p[1] <= std::max(a[1], b[1]) + tol;
}

// Whether segments ab and cd share a point (touching counts).
bool segments_meet(const P& a, const P& b, const P& c, const P& d, double tol) {
  const int o1 = orientation(a, b, c, tol), o2 = orientation(a, b, d, tol);
  const int o3 = orientation(c, d, a, tol), o4 = orientation(c, d, b, tol);
  if (o1 != o2 && o3 != o4 && o1 * o2 <= 0 && o3 * o4 <= 0 && (o1 != 0 || o2 != 0)) return true;
  if (o1 == 0 && on_segment(a, b, c, tol)) return true;
  if (o2 == 0 && on_segment(a, b, d, tol)) return true;
  if (o3 == 0 && on_segment(c, d, a, tol)) return true;
  if (o4 == 0 && on_segment(c, d, b, tol)) return true;
  return false;
}

std::string ring_name(int r) { return r == 0 ? std::string("the outer boundary") : fmt::format("hole {}", r - 1); }

}  // namespace

bool point_in_polygon(const PolygonBody& body, const P& p) {
  bool in = false;
  for (int r = 0; r < body.rings(); ++r) {
    const Ring& ring = body.ring(r);
    const std::size_t n = ring.size();
    for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
      const P& a = ring[i];
      const P& b = ring[j];
      if ((a[1] > p[1]) != (b[1] > p[1])) {
        const double x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
        if (p[0] < x) in = !in;
      }
    }
  }
  return in;
}

double ring_double_area(const Ring& ring) {
  Moments m;
  m.add(ring);
  return m.area2;
}

double polygon_area(const PolygonBody& body) {
  double a2 = 0.0;
  for (int r = 0; r < body.rings(); ++r) a2 += ring_double_area(body.ring(r));
  return 0.5 * a2;
}

Ring open_ring(Ring ring) {
  if (ring.size() >= 2 && ring.front() == ring.back()) ring.pop_back();
  return ring;
}

std::optional<PolygonProblem> polygon_problem(const PolygonBody& body) {
  // A length scale for the tolerances: the outer boundary's extent.
  double extent = 0.0;
  for (const P& p : body.outer) {
    for (const P& q : body.outer) extent = std::max(extent, (p - q).cwiseAbs().maxCoeff());
  }
  const double tol = 1e-12 * std::max(extent, 1e-300);
  for (int r = 0; r < body.rings(); ++r) {
    const Ring& ring = body.ring(r);
    const std::size_t n = ring.size();
    for (std::size_t i = 0; i < n; ++i) {
      if ((ring[i] - ring[(i + 1) % n]).cwiseAbs().maxCoeff() <= tol && n >= 2) {
        return PolygonProblem{r, fmt::format("{}: vertex {} ({}, {}) repeats the vertex before it", ring_name(r),
                                             (i + 1) % n, ring[(i + 1) % n][0], ring[(i + 1) % n][1])};
      }
    }
    if (n < 3) {
      return PolygonProblem{r, fmt::format("{} is open: it has {} distinct vertices, a polygon needs at least 3",
                                           ring_name(r), n)};
    }
    double spread = 0.0;  // the largest distance of a vertex from the line through the first two
    const P u = (ring[1] - ring[0]).normalized();
    for (const P& p : ring) spread = std::max(spread, std::abs(cross(u, p - ring[0])));
    if (spread <= tol) {
      return PolygonProblem{r, fmt::format("{} encloses no area (its vertices are collinear)", ring_name(r))};
    }
  }
  // Crossings: every pair of edges but neighbours on one ring, which share their vertex only.
  for (int r = 0; r < body.rings(); ++r) {
    const Ring& a = body.ring(r);
    for (int s = r; s < body.rings(); ++s) {
      const Ring& b = body.ring(s);
      for (std::size_t i = 0; i < a.size(); ++i) {
        const P& a0 = a[i];
        const P& a1 = a[(i + 1) % a.size()];
        for (std::size_t j = (r == s ? i + 1 : 0); j < b.size(); ++j) {
          const P& b0 = b[j];
          const P& b1 = b[(j + 1) % b.size()];
          if (r == s) {
            const bool next = j == i + 1, wrap = i == 0 && j == a.size() - 1;
            if (next || wrap) {
              // Neighbours: they must not fold back onto each other.
              const P& shared = next ? a1 : a0;
              const P& other_a = next ? a0 : a1;
              const P& other_b = next ? b1 : b0;
              const P u = other_a - shared, v = other_b - shared;
              if (std::abs(cross(u, v)) <= tol * (u.norm() + v.norm()) && u.dot(v) > 0.0) {
                return PolygonProblem{r, fmt::format("{} crosses itself: edges {} and {} fold back onto each other",
                                                     ring_name(r), i, j)};
              }
              continue;
            }
          }
          if (segments_meet(a0, a1, b0, b1, tol * extent)) {
            if (r == s) {
              return PolygonProblem{r, fmt::format("{} crosses itself: edges {} and {} meet", ring_name(r), i, j)};
            }
            return PolygonProblem{s, fmt::format("{} crosses {}: its edge {} meets edge {} of {}", ring_name(s),
                                                 ring_name(r), j, i, ring_name(r))};
          }
        }
      }
    }
  }
  // Area and orientation (a ring crossing itself may have either, or none).
  for (int r = 0; r < body.rings(); ++r) {
    const Ring& ring = body.ring(r);
    const double a2 = ring_double_area(ring);
    if (std::abs(a2) <= tol * std::max(extent, 1e-300)) {
      return PolygonProblem{r, fmt::format("{} encloses no area (its vertices are collinear)", ring_name(r))};
    }
    if (r == 0 && a2 < 0.0) {
      return PolygonProblem{r, "the outer boundary is clockwise; give its vertices counter-clockwise "
                               "(the body on the left of each edge)"};
    }
    if (r > 0 && a2 > 0.0) {
      return PolygonProblem{r, fmt::format("hole {} is counter-clockwise; give a hole's vertices clockwise "
                                           "(the body on the left of each edge)",
                                           r - 1)};
    }
  }
  // Holes inside the outer boundary, and not inside each other (the edges do not cross, so
  // one vertex decides).
  PolygonBody outer_only;
  outer_only.outer = body.outer;
  for (std::size_t h = 0; h < body.holes.size(); ++h) {
    if (!point_in_polygon(outer_only, body.holes[h].front())) {
      return PolygonProblem{static_cast<int>(h) + 1,
                            fmt::format("hole {} lies outside the outer boundary", h)};
    }
    for (std::size_t k = 0; k < body.holes.size(); ++k) {
      if (k == h) continue;
      PolygonBody other;
      other.outer = body.holes[k];
      std::reverse(other.outer.begin(), other.outer.end());
      if (point_in_polygon(other, body.holes[h].front())) {
        return PolygonProblem{static_cast<int>(h) + 1, fmt::format("hole {} lies inside hole {}", h, k)};
      }
    }
  }
  return std::nullopt;
}

namespace {

// A boundary node before sorting: its faces (outward normal, tributary length, edge).
struct Face {
  P normal;
  double length = 0.0;
  EdgeRef edge;
};
struct EdgeNode {
  P x;
  int body = 0;
  std::vector<int> also;  // other bodies touching here (a seam); `body` is the last of them
  std::vector<Face> faces;
  bool vertex = false;
  bool convex = true;  // at a vertex: the boundary turns towards the body's side (left)
  bool merged = false;  // folded into another body's node at the same point
};

bool axis_aligned(const P& n) { return n[0] == 0.0 || n[1] == 0.0; }

// The face bit of an axis-aligned unit normal (-x: 0, +x: 1, -y: 2, +y: 3).
int face_bit(const P& n) {
  if (n[1] == 0.0) return n[0] < 0.0 ? 0 : 1;
  return n[1] < 0.0 ? 2 : 3;
}

}  // namespace

LatticeParticles<2> generate_polygon_particles(const std::vector<PolygonBody>& bodies, double dx,
                                               const Vec<2>& origin, const std::vector<double>& densities) {
  if (bodies.empty()) throw InputError("the geometry has no polygon");
  LatticeParticles<2> out;
  out.dx = dx;
  const double snap = 1e-9 * dx;

  // The lattice: the cells over the bodies' bounding box, on the lattice through `origin`.
  std::array<int, 2> lo{std::numeric_limits<int>::max(), std::numeric_limits<int>::max()};
  std::array<int, 2> hi{std::numeric_limits<int>::min(), std::numeric_limits<int>::min()};
  for (const PolygonBody& b : bodies) {
    for (const P& p : b.outer) {
      for (int d = 0; d < 2; ++d) {
        const double t = (p[d] - origin[d]) / dx;
        lo[static_cast<std::size_t>(d)] = std::min(lo[static_cast<std::size_t>(d)], static_cast<int>(std::floor(t + 1e-9)));
        hi[static_cast<std::size_t>(d)] = std::max(hi[static_cast<std::size_t>(d)], static_cast<int>(std::ceil(t - 1e-9)));
      }
    }
  }
  Lattice<2>& lat = out.lattice;
  lat.dx = dx;
  for (std::size_t d = 0; d < 2; ++d) {
    lat.origin[static_cast<int>(d)] = lattice_vertex(origin[static_cast<int>(d)], lo[d], dx);
    lat.cells[d] = std::max(1, hi[d] - lo[d]);
  }
  const int nx = lat.cells[0], ny = lat.cells[1];
  const auto ncells = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  lat.cell_material.assign(ncells, -1);
  auto cell_lo = [&](int i, int j) { return P(lattice_vertex(lat.origin[0], i, dx), lattice_vertex(lat.origin[1], j, dx)); };
  auto vertex_x = cell_lo;
  const double cell_area = dx * dx;

  // Cells near an edge (within one cell of a point of it): their share is clipped exactly.
  std::vector<std::uint8_t> near(ncells, 0);
  for (const PolygonBody& b : bodies) {
    for (int r = 0; r < b.rings(); ++r) {
      const Ring& ring = b.ring(r);
      for (std::size_t k = 0; k < ring.size(); ++k) {
        const P& a = ring[k];
        const P& e = ring[(k + 1) % ring.size()];
        const int samples = 1 + static_cast<int>(std::ceil(4.0 * (e - a).norm() / dx));
        for (int s = 0; s <= samples; ++s) {
          const P x = a + (static_cast<double>(s) / samples) * (e - a);
          const int ci = static_cast<int>(std::floor((x[0] - lat.origin[0]) / dx));
          const int cj = static_cast<int>(std::floor((x[1] - lat.origin[1]) / dx));
          for (int j = cj - 1; j <= cj + 1; ++j) {
            for (int i = ci - 1; i <= ci + 1; ++i) {
              if (i >= 0 && i < nx && j >= 0 && j < ny) near[lat.cell_index({i, j})] = 1;
            }
          }
        }
      }
    }
  }

  // The body's area in every cell, and its centroid.
  std::vector<double> area(ncells, 0.0);
  std::vector<P> centroid(ncells, P::Zero());
  std::vector<int> body_of(ncells, -1);
  std::vector<P> clipped, work;
  auto clip_cell = [&](const PolygonBody& b, const P& clo, const P& chi, double& a, P& c) {
    Moments m;
    for (int r = 0; r < b.rings(); ++r) {
      clip_to_box(b.ring(r), clo, chi, clipped, work);
      if (!clipped.empty()) m.add(clipped);
    }
    a = 0.5 * m.area2;
    c = a != 0.0 ? P(m.mx6 / (3.0 * m.area2), m.my6 / (3.0 * m.area2)) : P(0.5 * (clo + chi));
  };
  for (std::size_t bi = 0; bi < bodies.size(); ++bi) {
    const PolygonBody& b = bodies[bi];
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        const std::size_t c = lat.cell_index({i, j});
        const P clo = cell_lo(i, j), chi = clo + P(dx, dx);
        const P centre(lattice_cell_centre(lat.origin[0], i, dx), lattice_cell_centre(lat.origin[1], j, dx));
        double a = 0.0;
        P x = centre;
        if (near[c]) {
          clip_cell(b, clo, chi, a, x);
          if (a <= 1e-12 * cell_area) continue;
          if (std::abs(a - cell_area) <= 1e-12 * cell_area) {  // whole: the lattice's exact values
            a = cell_area;
            x = centre;
          }
        } else {
          if (!point_in_polygon(b, centre)) continue;
          a = cell_area;
        }
        if (body_of[c] >= 0) {
          throw InputError(fmt::format("{}: the polygon overlaps {}, or lies within a spacing of it", b.label,
                                       bodies[static_cast<std::size_t>(body_of[c])].label));
        }
        body_of[c] = static_cast<int>(bi);
        area[c] = a;
        centroid[c] = x;
        lat.cell_material[c] = b.material;
      }
    }
  }

  // Stress points: a cell holding less than kMergeFraction of a cell gives its part to the
  // neighbour (of the 8, same body) holding most, and that one on if it is small too, until a
  // cell that holds more than its neighbours; the stress point sits at the centroid of the union.
  std::vector<std::size_t> target(ncells);
  std::iota(target.begin(), target.end(), std::size_t{0});
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const std::size_t c = lat.cell_index({i, j});
      if (body_of[c] < 0 || area[c] >= kMergeFraction * cell_area) continue;
      std::size_t best = c;
      for (int q = j - 1; q <= j + 1; ++q) {
        for (int p = i - 1; p <= i + 1; ++p) {
          if (p < 0 || p >= nx || q < 0 || q >= ny) continue;
          const std::size_t n = lat.cell_index({p, q});
          if (body_of[n] != body_of[c]) continue;
          if (area[n] > area[best] || (area[n] == area[best] && n < best)) best = n;
        }
      }
      target[c] = best;
    }
  }
  auto root = [&](std::size_t c) {
    while (target[c] != c) c = target[c];
    return c;
  };
  {
    std::vector<double> volume(ncells, 0.0);
    std::vector<P> moment(ncells, P::Zero());
    std::vector<int> merged(ncells, 0);
    for (std::size_t c = 0; c < ncells; ++c) {
      if (body_of[c] < 0) continue;
      const std::size_t r = root(c);
      volume[r] += area[c];
      moment[r] += area[c] * centroid[c];
      if (r != c) ++merged[r];
    }
    for (std::size_t c = 0; c < ncells; ++c) {
      if (body_of[c] < 0 || root(c) != c) continue;
      const P x = merged[c] == 0 ? centroid[c] : P(moment[c] / volume[c]);
      const int m = lat.cell_material[c];
      out.stress_points.add(x, volume[c], densities[static_cast<std::size_t>(m)], m);
    }
  }

  // Boundary nodes: every vertex, and each edge cut into ceil(L / dx) equal pieces.
  std::vector<EdgeNode> edge_nodes;
  for (std::size_t bi = 0; bi < bodies.size(); ++bi) {
    const PolygonBody& b = bodies[bi];
    for (int r = 0; r < b.rings(); ++r) {
      const Ring& ring = b.ring(r);
      const std::size_t n = ring.size();
      std::vector<P> tangent(n), normal(n);
      std::vector<double> piece(n);
      std::vector<int> pieces(n);
      for (std::size_t k = 0; k < n; ++k) {
        const P d = ring[(k + 1) % n] - ring[k];
        const double length = d.norm();
        tangent[k] = d / length;
        normal[k] = P(tangent[k][1], -tangent[k][0]);  // the body is on the left
        pieces[k] = std::max(1, static_cast<int>(std::ceil(length / dx - 1e-9)));
        piece[k] = length / pieces[k];
        // An edge on the lattice: the lattice's face length, computed as generate_lattice does.
        if (std::abs(piece[k] - dx) <= snap) piece[k] = std::pow(dx, 2) / dx;
      }
      for (std::size_t k = 0; k < n; ++k) {
        const std::size_t before = (k + n - 1) % n;
        const EdgeRef ref{static_cast<int>(bi), r, static_cast<int>(k)};
        EdgeNode v;
        v.x = ring[k];
        v.body = static_cast<int>(bi);
        v.vertex = true;
        // The vertex's shares of the edge ending there and of the edge starting there.
        v.faces.push_back({normal[before], 0.5 * piece[before], EdgeRef{static_cast<int>(bi), r, static_cast<int>(before)}});
        v.faces.push_back({normal[k], 0.5 * piece[k], ref});
        v.convex = cross(tangent[before], tangent[k]) >= 0.0;
        edge_nodes.push_back(v);
        for (int s = 1; s < pieces[k]; ++s) {
          EdgeNode m;
          m.x = ring[k] + (static_cast<double>(s) / pieces[k]) * (ring[(k + 1) % n] - ring[k]);
          m.body = static_cast<int>(bi);
          m.faces.push_back({normal[k], piece[k], ref});
          edge_nodes.push_back(m);
        }
      }
    }
  }
  // Boundary nodes on lattice vertices take the vertex's exact coordinates.
  for (EdgeNode& v : edge_nodes) {
    for (int d = 0; d < 2; ++d) {
      const double t = (v.x[d] - lat.origin[d]) / dx;
      const double rt = std::round(t);
      if (std::abs(t - rt) * dx <= snap) v.x[d] = lattice_vertex(lat.origin[d], static_cast<int>(rt), dx);
    }
  }

  // Touching bodies (a layer): their nodes at one point of a seam become one node with the
  // faces of both, of the material a lattice gives it (its first cell in the lattice's order
  // that holds a body: below, then left), so that layers on the lattice are their blocks. A
  // seam's faces, opposite normals from two bodies, cancel (the part left over is the union's
  // boundary), so a node inside the union is on no face; faces along one line join.
  {
    std::vector<std::size_t> by_x(edge_nodes.size());
    std::iota(by_x.begin(), by_x.end(), std::size_t{0});
    std::sort(by_x.begin(), by_x.end(), [&](std::size_t a, std::size_t b) { return edge_nodes[a].x[0] < edge_nodes[b].x[0]; });
    for (std::size_t u = 0; u < by_x.size(); ++u) {
      EdgeNode& a = edge_nodes[by_x[u]];
      if (a.merged) continue;
      for (std::size_t w = u + 1; w < by_x.size() && edge_nodes[by_x[w]].x[0] - a.x[0] <= snap; ++w) {
        EdgeNode& b = edge_nodes[by_x[w]];
        if (b.merged || b.body == a.body || std::abs(b.x[1] - a.x[1]) > snap) continue;
        a.also.push_back(b.body);
        a.faces.insert(a.faces.end(), b.faces.begin(), b.faces.end());
        a.vertex = a.vertex || b.vertex;
        b.merged = true;
      }
    }
    for (EdgeNode& e : edge_nodes) {
      if (e.merged || e.also.empty()) continue;
      for (const P& off : {P(-1, -1), P(1, -1), P(-1, 1), P(1, 1)}) {
        const P q = e.x + 1e-6 * dx * off;
        const int i = static_cast<int>(std::floor((q[0] - lat.origin[0]) / dx));
        const int j = static_cast<int>(std::floor((q[1] - lat.origin[1]) / dx));
        if (i < 0 || i >= nx || j < 0 || j >= ny) continue;
        const int b = body_of[lat.cell_index({i, j})];
        const auto it = std::find(e.also.begin(), e.also.end(), b);
        if (b == e.body) break;
        if (it != e.also.end()) {
          *it = e.body;
          e.body = b;
          break;
        }
      }
      std::vector<Face> net;
      for (Face f : e.faces) {
        for (Face& g : net) {
          if (f.length <= 0.0) break;
          const double c = f.normal.dot(g.normal);
          if (c < -1.0 + 1e-12) {  // a seam: the shorter share cancels
            const double t = std::min(f.length, g.length);
            f.length -= t;
            g.length -= t;
          } else if (c > 1.0 - 1e-12) {
            g.length += f.length;
            f.length = 0.0;
          }
        }
        if (f.length > snap) net.push_back(f);
      }
      std::erase_if(net, [&](const Face& f) { return f.length <= snap; });
      e.faces = std::move(net);
      if (e.faces.size() == 2) {
        // Convex where the union is outside beyond the corner, along n0 - n1 (either order).
        const P probe = e.x + 1e-3 * dx * (e.faces[0].normal - e.faces[1].normal);
        e.convex = std::none_of(bodies.begin(), bodies.end(), [&](const PolygonBody& b) { return point_in_polygon(b, probe); });
      }
    }
    std::erase_if(edge_nodes, [](const EdgeNode& e) { return e.merged; });
  }
  auto in_body = [](int body, const std::vector<int>& also, int b) {
    return body == b || std::find(also.begin(), also.end(), b) != also.end();
  };

  // Nodes: the boundary nodes, then the lattice vertices inside a body and clear of its boundary.
  struct NodeRecord {
    P x;
    int body = 0;
    int edge_node = -1;  // index into edge_nodes, -1 for a lattice vertex
    double volume = 0.0, mass = 0.0;
    std::vector<int> also;  // other bodies it stands in (a seam)
  };
  std::vector<NodeRecord> nodes;
  const int vx = nx + 1, vy = ny + 1;
  std::vector<int> vertex_node(static_cast<std::size_t>(vx) * static_cast<std::size_t>(vy), -1);
  auto vertex_index = [&](int i, int j) { return static_cast<std::size_t>(j) * static_cast<std::size_t>(vx) + static_cast<std::size_t>(i); };
  for (std::size_t k = 0; k < edge_nodes.size(); ++k) {
    nodes.push_back({edge_nodes[k].x, edge_nodes[k].body, static_cast<int>(k), 0.0, 0.0, edge_nodes[k].also});
    const double ti = (edge_nodes[k].x[0] - lat.origin[0]) / dx, tj = (edge_nodes[k].x[1] - lat.origin[1]) / dx;
    const double ri = std::round(ti), rj = std::round(tj);
    if (std::abs(ti - ri) * dx <= snap && std::abs(tj - rj) * dx <= snap) {
      vertex_node[vertex_index(static_cast<int>(ri), static_cast<int>(rj))] = static_cast<int>(nodes.size() - 1);
    }
  }
  for (int j = 0; j < vy; ++j) {
    for (int i = 0; i < vx; ++i) {
      if (vertex_node[vertex_index(i, j)] >= 0) continue;
      // The body of the cells around the vertex; none: outside.
      int b = -1;
      bool by_edge = false;
      for (int q = j - 1; q <= j; ++q) {
        for (int p = i - 1; p <= i; ++p) {
          if (p < 0 || p >= nx || q < 0 || q >= ny) continue;
          const std::size_t c = lat.cell_index({p, q});
          if (body_of[c] >= 0) b = body_of[c];
          if (near[c]) by_edge = true;
        }
      }
      if (b < 0) continue;
      const P x = vertex_x(i, j);
      const PolygonBody& body = bodies[static_cast<std::size_t>(b)];
      if (by_edge && (!point_in_polygon(body, x) || boundary_distance(body, x) < kInteriorClearance * dx)) continue;
      if (!by_edge && !point_in_polygon(body, x)) continue;
      nodes.push_back({x, b, -1, 0.0, 0.0, {}});
      vertex_node[vertex_index(i, j)] = static_cast<int>(nodes.size() - 1);
    }
  }

  // Nodes by cell, for the nearest-node search of the volumes.
  std::vector<std::vector<int>> nodes_in_cell(ncells);
  auto cell_of = [&](const P& x, int& i, int& j) {
    i = std::clamp(static_cast<int>(std::floor((x[0] - lat.origin[0]) / dx)), 0, nx - 1);
    j = std::clamp(static_cast<int>(std::floor((x[1] - lat.origin[1]) / dx)), 0, ny - 1);
  };
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    int i = 0, j = 0;
    cell_of(nodes[k].x, i, j);
    nodes_in_cell[lat.cell_index({i, j})].push_back(static_cast<int>(k));
  }
  auto nearest_node = [&](const P& x, int body) {
    int ci = 0, cj = 0;
    cell_of(x, ci, cj);
    int best = -1;
    double best_d2 = std::numeric_limits<double>::infinity();
    for (int reach = 2; best < 0 && reach <= 2 * std::max(nx, ny); reach *= 2) {
      for (int j = cj - reach; j <= cj + reach; ++j) {
        for (int i = ci - reach; i <= ci + reach; ++i) {
          if (i < 0 || i >= nx || j < 0 || j >= ny) continue;
          for (const int k : nodes_in_cell[lat.cell_index({i, j})]) {
            const NodeRecord& n = nodes[static_cast<std::size_t>(k)];
            if (!in_body(n.body, n.also, body)) continue;
            const double d2 = (nodes[static_cast<std::size_t>(k)].x - x).squaredNorm();
            if (d2 < best_d2 || (d2 == best_d2 && k < best)) {
              best_d2 = d2;
              best = k;
            }
          }
        }
      }
    }
    return best;
  };

  // Volumes: a whole cell with nodes at its four corners gives each a quarter, as the lattice
  // does; any other cell gives each of its sub-squares' part of the body to the nearest node.
  const double sub = dx / kVolumeSubdivision;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const std::size_t c = lat.cell_index({i, j});
      if (body_of[c] < 0) continue;
      const int b = body_of[c];
      const double rho = densities[static_cast<std::size_t>(bodies[static_cast<std::size_t>(b)].material)];
      const int corners[4] = {vertex_node[vertex_index(i, j)], vertex_node[vertex_index(i + 1, j)],
                              vertex_node[vertex_index(i, j + 1)], vertex_node[vertex_index(i + 1, j + 1)]};
      const bool whole = area[c] == cell_area && std::all_of(std::begin(corners), std::end(corners), [&](int k) {
                           return k >= 0 && in_body(nodes[static_cast<std::size_t>(k)].body,
                                                    nodes[static_cast<std::size_t>(k)].also, b);
                         });
      if (whole) {
        const double quarter = cell_area / 4.0;
        for (const int k : corners) {
          nodes[static_cast<std::size_t>(k)].volume += quarter;
          nodes[static_cast<std::size_t>(k)].mass += quarter * rho;
        }
        continue;
      }
      const P clo = cell_lo(i, j);
      for (int q = 0; q < kVolumeSubdivision; ++q) {
        for (int p = 0; p < kVolumeSubdivision; ++p) {
          const P slo = clo + P(p * sub, q * sub);
          const P shi = (p + 1 == kVolumeSubdivision && q + 1 == kVolumeSubdivision)
                            ? P(clo + P(dx, dx))
                            : P(slo + P(sub, sub));
          double a = 0.0;
          P x;
          clip_cell(bodies[static_cast<std::size_t>(b)], slo, shi, a, x);
          if (a <= 0.0) continue;
          const int k = nearest_node(x, b);
          nodes[static_cast<std::size_t>(k)].volume += a;
          nodes[static_cast<std::size_t>(k)].mass += a * rho;
        }
      }
    }
  }
  for (const NodeRecord& n : nodes) {
    if (!(n.volume > 0.0)) {
      throw InputError(fmt::format("{}: the node at ({}, {}) gets no part of the body; the polygon has a "
                                   "feature finer than the spacing {} m there",
                                   bodies[static_cast<std::size_t>(n.body)].label, n.x[0], n.x[1], dx));
    }
  }

  // The lattice's order (y, then x), which a rectangle on the lattice shares with its block.
  std::vector<std::size_t> order(nodes.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const P& xa = nodes[a].x;
    const P& xb = nodes[b].x;
    if (xa[1] != xb[1]) return xa[1] < xb[1];
    return xa[0] < xb[0];
  });
  BoundaryNodes<2>& bn = out.boundary;
  for (const std::size_t k : order) {
    const NodeRecord& n = nodes[k];
    if (n.edge_node >= 0 && !edge_nodes[static_cast<std::size_t>(n.edge_node)].faces.empty()) {
      const EdgeNode& e = edge_nodes[static_cast<std::size_t>(n.edge_node)];
      std::uint8_t faces = 0;
      std::array<double, 4> face_area{};
      P inclined = P::Zero();
      bool any_inclined = false;
      for (const Face& f : e.faces) {
        if (axis_aligned(f.normal)) {
          const int bit = face_bit(f.normal);
          faces = static_cast<std::uint8_t>(faces | (1u << bit));
          face_area[static_cast<std::size_t>(bit)] += f.length;
        } else {
          inclined += f.length * f.normal;
          any_inclined = true;
        }
      }
      FaceCondition condition = FaceCondition::axes;
      P normal = P::Zero();
      const bool two = e.faces.size() == 2;
      const double turn =
          two ? std::atan2(std::abs(cross(e.faces[0].normal, e.faces[1].normal)), e.faces[0].normal.dot(e.faces[1].normal))
              : 0.0;
      if (!any_inclined) {
        // As a lattice: a re-entrant corner is on no face.
        if (two && !e.convex && turn > kCornerTurn) {
          faces = 0;
          face_area.fill(0.0);
        }
      } else if (!two || turn <= kCornerTurn) {
        condition = FaceCondition::normal;
        normal = two ? P((e.faces[0].normal + e.faces[1].normal).normalized()) : e.faces[0].normal;
      } else {
        condition = e.convex ? FaceCondition::corner : FaceCondition::none;
        normal = P((e.faces[0].normal + e.faces[1].normal).normalized());  // for a traction there
      }
      bn.node.push_back(out.nodes.size());
      bn.faces.push_back(faces);
      bn.area.push_back(face_area);
      bn.inclined.push_back(inclined);
      bn.normal.push_back(normal);
      bn.condition.push_back(condition);
      bn.edges.push_back({e.faces[0].edge, two ? e.faces[1].edge : EdgeRef{}});
    }
    out.nodes.add(n.x, n.volume, n.mass / n.volume, bodies[static_cast<std::size_t>(n.body)].material);
  }

  // No two particles of a set closer than kMinParticleDistance dx.
  auto check_spacing = [&](const ParticleSet<2>& set, const char* what) {
    const double limit = kMinParticleDistance * dx;
    std::vector<std::vector<Index>> bins(ncells);
    for (Index k = 0; k < set.size(); ++k) {
      int i = 0, j = 0;
      cell_of(set.position[static_cast<std::size_t>(k)], i, j);
      bins[lat.cell_index({i, j})].push_back(k);
    }
    for (Index k = 0; k < set.size(); ++k) {
      const P& x = set.position[static_cast<std::size_t>(k)];
      int ci = 0, cj = 0;
      cell_of(x, ci, cj);
      for (int j = cj - 1; j <= cj + 1; ++j) {
        for (int i = ci - 1; i <= ci + 1; ++i) {
          if (i < 0 || i >= nx || j < 0 || j >= ny) continue;
          for (const Index l : bins[lat.cell_index({i, j})]) {
            if (l <= k) continue;
            const P& y = set.position[static_cast<std::size_t>(l)];
            if ((x - y).norm() < limit) {
              const int m = set.material[static_cast<std::size_t>(k)];
              std::string label;
              for (const PolygonBody& b : bodies) {
                if (b.material == m) label = b.label;
              }
              throw InputError(fmt::format(
                  "{}: two {} at ({:.6g}, {:.6g}) and ({:.6g}, {:.6g}) are closer than {} spacings; the polygon "
                  "has a vertex too sharp or edges too close for the spacing {} m there (refine geometry.spacing)",
                  label, what, x[0], x[1], y[0], y[1], kMinParticleDistance, dx));
            }
          }
        }
      }
    }
  };
  check_spacing(out.nodes, "nodes");
  check_spacing(out.stress_points, "stress points");
  return out;
}

}  // namespace rktsph
