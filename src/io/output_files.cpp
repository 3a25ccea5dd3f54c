#include "io/output_files.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "core/error.hpp"

namespace rktsph::io {

namespace {

// Write all of `data`, retrying short writes and EINTR.
bool write_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace

std::string system_error_text(const std::string& what, const std::string& path, int error_number) {
  return fmt::format("cannot {} {}: {}", what, path, std::strerror(error_number));
}

void write_file_atomically(const std::string& path, std::string_view content, bool durable) {
  const std::string tmp = fmt::format("{}.tmp{}", path, static_cast<long>(::getpid()));
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw IoError(system_error_text("write", path, errno));
  const bool ok = write_all(fd, content.data(), content.size());
  const int write_errno = errno;
  // fsync: without it a power loss can leave the renamed name pointing at an empty file.
  const bool synced = ok && (!durable || ::fsync(fd) == 0);
  const int sync_errno = errno;
  ::close(fd);
  if (!ok || !synced) {
    ::unlink(tmp.c_str());
    throw IoError(system_error_text("write", path, ok ? sync_errno : write_errno));
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int e = errno;
    ::unlink(tmp.c_str());
    throw IoError(system_error_text("replace", path, e));
  }
}

RowFile::RowFile(std::string path, std::int64_t keep_bytes) : path_(std::move(path)) {
  const int flags = O_WRONLY | O_CREAT | O_CLOEXEC | (keep_bytes < 0 ? O_TRUNC : 0);
  fd_ = ::open(path_.c_str(), flags, 0644);
  if (fd_ < 0) throw IoError(system_error_text("write", path_, errno));
  if (keep_bytes >= 0) {
    struct stat st {};
    if (::fstat(fd_, &st) != 0 || st.st_size < keep_bytes) {
      ::close(fd_);
      fd_ = -1;
      throw IoError(fmt::format("cannot resume {}: it holds fewer bytes than the checkpoint recorded", path_));
    }
    if (S_ISREG(st.st_mode) && ::ftruncate(fd_, static_cast<off_t>(keep_bytes)) != 0) {
      const int e = errno;
      ::close(fd_);
      fd_ = -1;
      throw IoError(system_error_text("truncate", path_, e));
    }
    written_ = keep_bytes;
  }
  if (::lseek(fd_, 0, SEEK_END) < 0 && errno != ESPIPE) {
    const int e = errno;
    ::close(fd_);
    fd_ = -1;
    throw IoError(system_error_text("write", path_, e));
  }
}

RowFile::~RowFile() {
  if (fd_ >= 0) ::close(fd_);
}

void RowFile::append(std::string_view row) { pending_.append(row); }

void RowFile::flush() {
  if (pending_.empty()) return;
  if (!write_all(fd_, pending_.data(), pending_.size())) {
    const int e = errno;
    // A part of the rows may have reached the file (a disk that filled up mid-way): cut it back
    // to the last complete row, so the file stays a valid table; the caller stops the run.
    if (::ftruncate(fd_, static_cast<off_t>(written_)) == 0) ::lseek(fd_, 0, SEEK_END);
    throw IoError(system_error_text("write", path_, e));
  }
  written_ += static_cast<std::int64_t>(pending_.size());
  pending_.clear();
}

}  // namespace rktsph::io
