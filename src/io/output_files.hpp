#pragma once
// Output files that survive an interruption (docs/output.md, "Interrupted runs"):
//   * write_file_atomically: a whole file (a frame, a .pvd, summary.json, a checkpoint) is
//     written to a temporary name in the same folder and renamed over the old one, so the
//     name holds either the old or the new complete file, whatever kills the program;
//   * RowFile: a table (probes.csv, energy.csv) that only ever holds complete rows: rows are
//     kept in memory and written by whole rows with write(2), at flush().
// Every write is checked: a failure throws IoError with the path and the system's text.
#include <cstdint>
#include <string>
#include <string_view>

namespace rktsph::io {

/// Replace `path` by `content` atomically (temporary file, rename). `durable`: fsync before the
/// rename, so that the file survives a power loss too (checkpoints, summary.json; frames skip
/// it, their cost would grow with the output rate).
void write_file_atomically(const std::string& path, std::string_view content, bool durable = true);

/// The message of a failed system call on `path`: "cannot write PATH: No space left on device".
std::string system_error_text(const std::string& what, const std::string& path, int error_number);

class RowFile {
 public:
  /// Open `path` for appending rows. `keep_bytes` < 0: start an empty file; >= 0: keep the first
  /// keep_bytes of an existing file and drop the rest (resuming from a checkpoint).
  RowFile(std::string path, std::int64_t keep_bytes = -1);
  ~RowFile();
  RowFile(const RowFile&) = delete;
  RowFile& operator=(const RowFile&) = delete;

  /// Queue one complete row (it must end with '\n').
  void append(std::string_view row);
  /// Write the queued rows to the file (whole rows, one system call).
  void flush();
  /// Bytes in the file once flushed.
  std::int64_t size() const { return written_ + static_cast<std::int64_t>(pending_.size()); }
  std::int64_t written() const { return written_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
  std::string pending_;
  std::int64_t written_ = 0;
};

}  // namespace rktsph::io
