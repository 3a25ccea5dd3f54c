#include "io/vtu_writer.hpp"

#include <cstdint>
#include <cstring>
#include <sstream>

#include <fmt/format.h>

#include "core/error.hpp"
#include "io/output_files.hpp"

namespace rktsph::io {

std::string base64_encode(const unsigned char* data, std::size_t size) {
  static constexpr char kTable[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve(((size + 2) / 3) * 4);
  std::size_t i = 0;
  for (; i + 2 < size; i += 3) {
    const std::uint32_t n = (std::uint32_t{data[i]} << 16) | (std::uint32_t{data[i + 1]} << 8) | data[i + 2];
    out.push_back(kTable[(n >> 18) & 63]);
    out.push_back(kTable[(n >> 12) & 63]);
    out.push_back(kTable[(n >> 6) & 63]);
    out.push_back(kTable[n & 63]);
  }
  if (i < size) {
    std::uint32_t n = std::uint32_t{data[i]} << 16;
    if (i + 1 < size) n |= std::uint32_t{data[i + 1]} << 8;
    out.push_back(kTable[(n >> 18) & 63]);
    out.push_back(kTable[(n >> 12) & 63]);
    out.push_back(i + 1 < size ? kTable[(n >> 6) & 63] : '=');
    out.push_back('=');
  }
  return out;
}

namespace {

// VTK "binary" inline encoding: a UInt32 byte count, then the raw data, each part base64-coded.
template <class T>
std::string encode_block(const std::vector<T>& values) {
  const auto bytes = static_cast<std::uint32_t>(values.size() * sizeof(T));
  unsigned char header[sizeof(std::uint32_t)];
  std::memcpy(header, &bytes, sizeof(bytes));
  return base64_encode(header, sizeof(header)) +
         base64_encode(reinterpret_cast<const unsigned char*>(values.data()), bytes);
}

}  // namespace

void write_vtu(const std::string& path, const std::vector<double>& points, const std::vector<PointField>& fields) {
  const std::size_t n = points.size() / 3;
  std::ostringstream out(std::ios::binary);
  out << "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt32\">\n<UnstructuredGrid>\n";
  out << fmt::format("<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", n, n);
  out << "<PointData>\n";
  for (const PointField& f : fields) {
    out << fmt::format(
        "<DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\" "
        "format=\"binary\">\n",
        f.name, f.components);
    out << encode_block(f.values) << "\n</DataArray>\n";
  }
  out << "</PointData>\n<Points>\n"
         "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"binary\">\n";
  out << encode_block(points) << "\n</DataArray>\n</Points>\n<Cells>\n";
  std::vector<std::int64_t> connectivity(n), offsets(n);
  std::vector<std::uint8_t> types(n, 1);  // VTK_VERTEX
  for (std::size_t i = 0; i < n; ++i) {
    connectivity[i] = static_cast<std::int64_t>(i);
    offsets[i] = static_cast<std::int64_t>(i + 1);
  }
  out << "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"binary\">\n"
      << encode_block(connectivity) << "\n</DataArray>\n";
  out << "<DataArray type=\"Int64\" Name=\"offsets\" format=\"binary\">\n"
      << encode_block(offsets) << "\n</DataArray>\n";
  out << "<DataArray type=\"UInt8\" Name=\"types\" format=\"binary\">\n" << encode_block(types) << "\n</DataArray>\n";
  out << "</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  write_file_atomically(path, out.str(), false);
}

void PvdCollection::add(double time, const std::string& relative_file) {
  entries_.emplace_back(time, relative_file);
  write();
}

void PvdCollection::restore(std::vector<Entry> entries) {
  entries_ = std::move(entries);
  write();
}

void PvdCollection::write() const {
  std::string out = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  for (const auto& [t, file] : entries_) {
    out += fmt::format("<DataSet timestep=\"{:.10g}\" part=\"0\" file=\"{}\"/>\n", t, file);
  }
  out += "</Collection>\n</VTKFile>\n";
  write_file_atomically(path_, out, false);
}

}  // namespace rktsph::io
