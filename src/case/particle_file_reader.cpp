#include "case/particle_file_reader.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <fstream>
#include <numeric>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/error.hpp"

namespace rktsph {

namespace {

std::string trimmed(std::string_view s) {
  std::size_t a = 0, z = s.size();
  while (a < z && (s[a] == ' ' || s[a] == '\t' || s[a] == '\r')) ++a;
  while (z > a && (s[z - 1] == ' ' || s[z - 1] == '\t' || s[z - 1] == '\r')) --z;
  return std::string(s.substr(a, z - a));
}

std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    out.push_back(trimmed(std::string_view(line).substr(start, comma == std::string::npos ? comma : comma - start)));
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

bool blank_or_comment(const std::string& line) {
  const std::string t = trimmed(line);
  return t.empty() || t.front() == '#';
}

}  // namespace

std::string face_column_name(std::size_t side) {
  return fmt::format("face_{}{}", side % 2 == 0 ? '-' : '+', kAxisNames[side / 2]);
}

template <int Dim>
std::vector<long> read_particle_file(const std::string& path, const std::string& label, const std::string& where,
                                     const ParticleFileMaterials& materials, ParticleSet<Dim>& set,
                                     BoundaryNodes<Dim>* faces, bool* faces_given) {
  auto fail = [&](long line, const std::string& column, const std::string& message) {
    throw InputError(fmt::format("{}: {}, line {}{}: {}", where, label, line,
                                 column.empty() ? std::string() : fmt::format(", column '{}'", column), message));
  };
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot open the particle file {} ({})", where, label, path));

  // The header: the first line that is neither blank nor a comment.
  std::string text;
  long line = 0;
  bool have_header = false;
  while (std::getline(in, text)) {
    ++line;
    if (!blank_or_comment(text)) {
      have_header = true;
      break;
    }
  }
  if (!have_header) fail(std::max(line, 1L), "", "no header line (expected x,y,volume,material; the file is empty)");
  const std::vector<std::string> header = split_fields(text);
  std::vector<std::string> accepted;
  for (int d = 0; d < Dim; ++d) accepted.emplace_back(kAxisNames[static_cast<std::size_t>(d)]);
  accepted.insert(accepted.end(), {"volume", "material", "density"});
  constexpr std::size_t kDensity = Dim + 2;  // the optional columns: density, then the faces
  constexpr std::size_t kFirstFace = Dim + 3;
  if (faces != nullptr) {
    for (std::size_t side = 0; side < 2 * Dim; ++side) accepted.push_back(face_column_name(side));
  }
  std::vector<int> column_of(accepted.size(), -1);  // accepted name -> column index
  for (std::size_t k = 0; k < header.size(); ++k) {
    const auto it = std::find(accepted.begin(), accepted.end(), header[k]);
    if (it == accepted.end()) {
      fail(line, header[k],
           fmt::format("unknown column{} (a {}D {} file has the columns {}; {} optional)",
                       header[k].empty() ? " (an empty name)" : "", Dim, faces != nullptr ? "node" : "stress-point",
                       fmt::join(accepted, ", "), faces != nullptr ? "density and the faces are" : "density is"));
    }
    const auto a = static_cast<std::size_t>(it - accepted.begin());
    if (column_of[a] >= 0) fail(line, header[k], "appears twice in the header");
    column_of[a] = static_cast<int>(k);
  }
  for (std::size_t a = 0; a < kDensity; ++a) {
    if (column_of[a] < 0) {
      fail(line, accepted[a],
           fmt::format("missing from the header '{}' (needed: {})", trimmed(text),
                       fmt::join(accepted.begin(), accepted.begin() + static_cast<std::ptrdiff_t>(kDensity), ", ")));
    }
  }

  // The faces: every face column or none.
  bool with_faces = false;
  if (faces != nullptr) {
    for (std::size_t a = kFirstFace; a < accepted.size(); ++a) with_faces = with_faces || column_of[a] >= 0;
    for (std::size_t a = kFirstFace; a < accepted.size() && with_faces; ++a) {
      if (column_of[a] < 0) {
        fail(line, accepted[a],
             fmt::format("missing from the header: the face columns come all together ({})",
                         fmt::join(accepted.begin() + static_cast<std::ptrdiff_t>(kFirstFace), accepted.end(), ", ")));
      }
    }
    *faces_given = with_faces;
  }

  auto number = [&](const std::vector<std::string>& fields, std::size_t a) {
    const std::string& s = fields[static_cast<std::size_t>(column_of[a])];
    double v = 0.0;
    const char* begin = s.data() + (s.size() > 1 && s[0] == '+' ? 1 : 0);  // from_chars takes no '+'
    const char* end = s.data() + s.size();
    const auto r = std::from_chars(begin, end, v);
    if (s.empty() || r.ec == std::errc::invalid_argument || r.ptr != end) {
      fail(line, accepted[a], fmt::format("'{}' is not a number", s));
    }
    if (r.ec == std::errc::result_out_of_range || !std::isfinite(v)) {
      fail(line, accepted[a], fmt::format("'{}' is not a finite number", s));
    }
    return v;
  };

  std::vector<long> lines;
  while (std::getline(in, text)) {
    ++line;
    if (blank_or_comment(text)) continue;
    const std::vector<std::string> fields = split_fields(text);
    if (fields.size() != header.size()) {
      fail(line, "", fmt::format("{} values, but the header has {} columns", fields.size(), header.size()));
    }
    Vec<Dim> x;
    for (std::size_t d = 0; d < Dim; ++d) x[static_cast<int>(d)] = number(fields, d);
    const double volume = number(fields, Dim);
    if (!(volume > 0.0)) fail(line, "volume", fmt::format("must be > 0 (m^{}), got {}", Dim, volume));
    const std::string& name = fields[static_cast<std::size_t>(column_of[Dim + 1])];
    const auto m = std::find(materials.names.begin(), materials.names.end(), name);
    if (m == materials.names.end()) {
      fail(line, "material",
           fmt::format("no material named '{}' (defined: {})", name, fmt::join(materials.names, ", ")));
    }
    const auto material = static_cast<std::size_t>(m - materials.names.begin());
    double density = materials.densities[material];
    if (column_of[kDensity] >= 0) {
      density = number(fields, kDensity);
      if (!(density > 0.0)) fail(line, "density", fmt::format("must be > 0 (kg/m^3), got {}", density));
    }
    if (with_faces) {
      std::uint8_t bits = 0;
      std::array<double, 2 * Dim> area{};
      for (std::size_t side = 0; side < 2 * Dim; ++side) {
        area[side] = number(fields, kFirstFace + side);
        if (!(area[side] >= 0.0)) {
          fail(line, accepted[kFirstFace + side],
               fmt::format("must be >= 0 (the node's area of that face, m^{}; 0 = not on it), got {}", Dim - 1,
                           area[side]));
        }
        if (area[side] > 0.0) bits = static_cast<std::uint8_t>(bits | (1u << side));
      }
      if (bits != 0) {
        faces->node.push_back(set.size());
        faces->faces.push_back(bits);
        faces->area.push_back(area);
      }
    }
    set.add(x, volume, density, static_cast<int>(material));
    lines.push_back(line);
  }
  if (lines.empty()) fail(line, "", "no particle after the header");
  return lines;
}

template <int Dim>
std::pair<Index, Index> coincident_particles(const ParticleSet<Dim>& set, double tolerance) {
  // Sorted along x, a pair closer than the tolerance lies within a window of it.
  std::vector<Index> order(static_cast<std::size_t>(set.size()));
  std::iota(order.begin(), order.end(), Index{0});
  const auto& x = set.position;
  std::sort(order.begin(), order.end(), [&](Index a, Index b) {
    const auto& xa = x[static_cast<std::size_t>(a)];
    const auto& xb = x[static_cast<std::size_t>(b)];
    return xa[0] != xb[0] ? xa[0] < xb[0] : a < b;
  });
  for (std::size_t k = 0; k < order.size(); ++k) {
    const auto& xa = x[static_cast<std::size_t>(order[k])];
    for (std::size_t l = k + 1; l < order.size(); ++l) {
      const auto& xb = x[static_cast<std::size_t>(order[l])];
      if (xb[0] - xa[0] > tolerance) break;
      if ((xb - xa).norm() <= tolerance) return std::minmax(order[k], order[l]);
    }
  }
  return {-1, -1};
}

#define RKTSPH_PARTICLE_FILE(D)                                                                                      \
  template std::vector<long> read_particle_file<D>(const std::string&, const std::string&, const std::string&,       \
                                                   const ParticleFileMaterials&, ParticleSet<D>&, BoundaryNodes<D>*, \
                                                   bool*);                                                           \
  template std::pair<Index, Index> coincident_particles<D>(const ParticleSet<D>&, double);
RKTSPH_PARTICLE_FILE(1)
RKTSPH_PARTICLE_FILE(2)
RKTSPH_PARTICLE_FILE(3)
#undef RKTSPH_PARTICLE_FILE

}  // namespace rktsph
