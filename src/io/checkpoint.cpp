#include "io/checkpoint.hpp"

#include <fcntl.h>
#include <hdf5.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <mutex>
#include <sstream>

#include <fmt/format.h>

#include "io/output_files.hpp"
#include "rktsph/version.hpp"

namespace rktsph::io {

namespace {

// The serial HDF5 library is not thread-safe, and `rktsph fos` runs trials side by side on
// threads (an interrupted search checkpoints them all at once): one HDF5 call sequence at a time.
std::mutex& hdf5_mutex() {
  static std::mutex m;
  return m;
}

constexpr const char* kFormatName = "rktsph checkpoint";

// An HDF5 handle closed on scope exit.
struct Handle {
  hid_t id;
  herr_t (*close)(hid_t);
  Handle(hid_t h, herr_t (*c)(hid_t)) : id(h), close(c) {}
  ~Handle() {
    if (id >= 0) close(id);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
};

template <class T>
hid_t native_type() {
  if constexpr (std::is_same_v<T, double>) return H5T_NATIVE_DOUBLE;
  else if constexpr (std::is_same_v<T, std::int64_t>) return H5T_NATIVE_INT64;
  else return H5T_NATIVE_UINT8;
}

template <class T>
char type_code() {
  if constexpr (std::is_same_v<T, double>) return 'd';
  else if constexpr (std::is_same_v<T, std::int64_t>) return 'i';
  else return 'b';
}

template <class T>
void write_dataset(hid_t file, hid_t lcpl, const std::string& key, const std::vector<T>& v, const std::string& path) {
  const hsize_t dims[1] = {static_cast<hsize_t>(v.size())};
  Handle space(H5Screate_simple(1, dims, nullptr), H5Sclose);
  Handle set(H5Dcreate2(file, key.c_str(), native_type<T>(), space.id, lcpl, H5P_DEFAULT, H5P_DEFAULT), H5Dclose);
  const T dummy{};
  if (space.id < 0 || set.id < 0 ||
      H5Dwrite(set.id, native_type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, v.empty() ? &dummy : v.data()) < 0) {
    throw IoError(fmt::format("cannot write the checkpoint {} (dataset '{}')", path, key));
  }
}

template <class T>
std::vector<T> read_dataset(hid_t file, const std::string& key, const std::string& path) {
  Handle set(H5Dopen2(file, key.c_str(), H5P_DEFAULT), H5Dclose);
  if (set.id < 0) throw InputError(fmt::format("{}: a damaged checkpoint (no dataset '{}')", path, key));
  Handle space(H5Dget_space(set.id), H5Sclose);
  hsize_t dims[1] = {0};
  if (space.id < 0 || H5Sget_simple_extent_ndims(space.id) != 1 || H5Sget_simple_extent_dims(space.id, dims, nullptr) < 0) {
    throw InputError(fmt::format("{}: a damaged checkpoint (dataset '{}')", path, key));
  }
  std::vector<T> v(static_cast<std::size_t>(dims[0]));
  T dummy{};
  if (H5Dread(set.id, native_type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, v.empty() ? &dummy : v.data()) < 0) {
    throw InputError(fmt::format("{}: a damaged checkpoint (cannot read '{}')", path, key));
  }
  return v;
}

}  // namespace

void write_checkpoint(const std::string& path, const StateArchive& state) {
  const std::lock_guard<std::mutex> lock(hdf5_mutex());
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported by return codes, below
  StateArchive archive = state;
  archive.put_text("meta/format", kFormatName);
  archive.put_integer("meta/format_version", kCheckpointFormat);
  archive.put_text("meta/program", fmt::format("rktsph {} ({})", kVersion, kGitRevision));
  std::string keys;
  for (const auto& [key, value] : archive.values()) {
    std::visit([&](const auto& v) { keys += fmt::format("{} {}\n", type_code<typename std::decay_t<decltype(v)>::value_type>(), key); },
               value);
  }
  archive.put_text("meta/keys", keys);
  const std::uint64_t sum = archive.checksum();
  archive.put_integer("meta/checksum", static_cast<std::int64_t>(sum));

  const std::string tmp = fmt::format("{}.tmp{}", path, static_cast<long>(::getpid()));
  {
    Handle file(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
    if (file.id < 0) throw IoError(fmt::format("cannot write the checkpoint {} (HDF5 cannot create {})", path, tmp));
    Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
    H5Pset_create_intermediate_group(lcpl.id, 1);
    for (const auto& [key, value] : archive.values()) {
      std::visit([&](const auto& v) { write_dataset(file.id, lcpl.id, key, v, path); }, value);
    }
    if (H5Fflush(file.id, H5F_SCOPE_GLOBAL) < 0) throw IoError(fmt::format("cannot write the checkpoint {}", path));
  }
  const int fd = ::open(tmp.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0 || ::fsync(fd) != 0) {
    const int e = errno;
    if (fd >= 0) ::close(fd);
    ::unlink(tmp.c_str());
    throw IoError(system_error_text("write the checkpoint", path, e));
  }
  ::close(fd);
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int e = errno;
    ::unlink(tmp.c_str());
    throw IoError(system_error_text("replace the checkpoint", path, e));
  }
}

StateArchive read_checkpoint(const std::string& path) {
  const std::lock_guard<std::mutex> lock(hdf5_mutex());
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  if (::access(path.c_str(), R_OK) != 0) {
    throw InputError(system_error_text("read the checkpoint", path, errno));
  }
  if (H5Fis_hdf5(path.c_str()) <= 0) throw InputError(fmt::format("{}: not an rktsph checkpoint (not an HDF5 file)", path));
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (file.id < 0) throw InputError(fmt::format("{}: a damaged checkpoint (HDF5 cannot open it)", path));
  if (H5Lexists(file.id, "meta", H5P_DEFAULT) <= 0 || H5Lexists(file.id, "meta/format", H5P_DEFAULT) <= 0) {
    throw InputError(fmt::format("{}: not an rktsph checkpoint (an HDF5 file without its 'meta/format')", path));
  }
  const auto format = read_dataset<std::uint8_t>(file.id, "meta/format", path);
  if (std::string(format.begin(), format.end()) != kFormatName) {
    throw InputError(fmt::format("{}: not an rktsph checkpoint", path));
  }
  const auto version = read_dataset<std::int64_t>(file.id, "meta/format_version", path);
  if (version.size() != 1 || version[0] != kCheckpointFormat) {
    throw InputError(fmt::format("{}: a checkpoint of format {}, this program reads format {}", path,
                                 version.empty() ? -1 : version[0], kCheckpointFormat));
  }
  const auto key_bytes = read_dataset<std::uint8_t>(file.id, "meta/keys", path);
  StateArchive archive;
  std::istringstream keys(std::string(key_bytes.begin(), key_bytes.end()));
  std::string line;
  while (std::getline(keys, line)) {
    if (line.size() < 3 || line[1] != ' ') throw InputError(fmt::format("{}: a damaged checkpoint (its key list)", path));
    const std::string key = line.substr(2);
    switch (line[0]) {
      case 'd': archive.put(key, read_dataset<double>(file.id, key, path)); break;
      case 'i': archive.put(key, read_dataset<std::int64_t>(file.id, key, path)); break;
      case 'b': archive.put(key, read_dataset<std::uint8_t>(file.id, key, path)); break;
      default: throw InputError(fmt::format("{}: a damaged checkpoint (its key list)", path));
    }
  }
  archive.put_text("meta/keys", std::string(key_bytes.begin(), key_bytes.end()));
  const auto sum = read_dataset<std::int64_t>(file.id, "meta/checksum", path);
  if (sum.size() != 1 || static_cast<std::uint64_t>(sum[0]) != archive.checksum()) {
    throw InputError(fmt::format("{}: a damaged checkpoint (its checksum does not match its contents)", path));
  }
  return archive;
}

}  // namespace rktsph::io
