#pragma once
// ParaView output: VTK XML unstructured grids (.vtu) of particles as vertex cells, with
// base64-encoded binary data, and a .pvd collection that ties the files to simulation time.
#include <string>
#include <vector>

namespace rktsph::io {

struct PointField {
  std::string name;
  int components = 1;          // 1 (scalar) or 3 (vector)
  std::vector<double> values;  // components * points
};

/// Write particles at `points` (x, y, z per point) with their fields.
void write_vtu(const std::string& path, const std::vector<double>& points, const std::vector<PointField>& fields);

/// A ParaView collection (.pvd): one entry per output time.
class PvdCollection {
 public:
  using Entry = std::pair<double, std::string>;
  explicit PvdCollection(std::string path) : path_(std::move(path)) {}
  /// Record a file (relative to the .pvd's folder) and replace the collection atomically, so
  /// that a run that stops at any moment leaves a readable collection.
  void add(double time, const std::string& relative_file);
  const std::vector<Entry>& entries() const { return entries_; }
  /// Restart from the entries of a checkpoint (resume), rewriting the file.
  void restore(std::vector<Entry> entries);

 private:
  void write() const;
  std::string path_;
  std::vector<std::pair<double, std::string>> entries_;
};

std::string base64_encode(const unsigned char* data, std::size_t size);

}  // namespace rktsph::io
