// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The one rule by which every rotacal writer (C++ and Python) puts a file on disk.
///
/// - A regular file, or a path that does not exist yet, is written to a uniquely named
///   temporary file in the same directory (O_EXCL, mode 0666 & ~umask or the old file's mode),
///   fsynced, renamed over the target and the directory fsynced: a reader, a crash or a full
///   disk sees the old file or the new one, never half of one.
/// - A character device or a FIFO (`-o /dev/null`, a pipe) is written through, never replaced.
/// - A symbolic link is followed to its target, which is then written by the rules above.
/// - Refused with IoError naming the path: a directory, a block device or socket, a path with a
///   NUL byte, a missing parent directory, an existing file the caller may not write, one of
///   the command's own inputs, or another output of the same command (same st_dev/st_ino, or
///   the same canonical path for files that do not exist yet).
/// - Nothing is left behind on any failure, including an exception thrown while the content is
///   produced (the content is produced before anything is opened).
/// - A file written as it comes (OutputStream, the recorders) follows the same rule: its rows
///   go to the temporary file, which replaces the target when the stream ends, however it ends
///   (a recording's rows are measurements that cannot be taken again), unless the writer
///   discards it (a recording that ended with no row: the old file stays, as after any failed
///   write). Only a process that is killed leaves its rows behind, in the hidden
///   `.rotacal-<pid>-<hex>.part` of the target's folder; the next replacing write into that
///   folder removes such a file once its process is gone and it is older than
///   kStaleTemporarySeconds (and it is the user's own regular file).

#include <functional>
#include <string>
#include <vector>

namespace rotacal {

/// Age (s) after which a temporary of a process that is gone is removed (see above).
inline constexpr long kStaleTemporarySeconds = 600;

/// The other paths of the command that writes an output; none of them may be the output.
struct OutputOptions {
  std::vector<std::string> inputs;         ///< files the command reads
  std::vector<std::string> other_outputs;  ///< the command's other outputs
};

/// How an output path will be written (see check_output).
enum class OutputKind {
  Replace,       ///< regular file or new path: temporary file + rename
  WriteThrough,  ///< character device or FIFO: opened and written, never replaced
};

/// Check an output path by the rule above without writing anything (so a command can refuse
/// a bad `-o` before a long computation); returns how it would be written. Throws IoError.
OutputKind check_output(const std::string& path, const OutputOptions& options = {});

/// Write `data` to `path` by the rule above. Throws IoError naming the path.
void write_output(const std::string& path, const std::string& data,
                  const OutputOptions& options = {});

/// Produce the content with `produce` (which may throw: then nothing is written and the old
/// file stays), then write it by the rule above.
void write_output(const std::string& path, const std::function<std::string()>& produce,
                  const OutputOptions& options = {});

/// A file written piece by piece by the rule above: each write() reaches the operating system
/// before it returns; commit() (or the destructor) makes the file the target.
class OutputStream {
 public:
  /// Checks the path (check_output) and opens the temporary file or the device.
  OutputStream(const std::string& path, const OutputOptions& options = {});
  ~OutputStream();  ///< commits if commit() was not called; errors are then swallowed
  OutputStream(const OutputStream&) = delete;
  OutputStream& operator=(const OutputStream&) = delete;
  void write(const std::string& text);  ///< throws IoError naming the path
  void commit();                        ///< fsync, rename over the target; throws IoError
  /// Close without touching the target: the temporary file is removed (a device written
  /// through keeps what it was sent). After commit() or discard(), does nothing.
  void discard();
  const std::string& path() const { return path_; }
  /// Where the rows are until commit(): the temporary file, or the device written through.
  const std::string& writing_path() const { return temporary_.empty() ? target_ : temporary_; }

 private:
  std::string path_;       ///< as the caller named it
  std::string target_;     ///< canonical target
  std::string directory_;  ///< its directory (fsynced after the rename)
  std::string temporary_;  ///< empty when written through
  int fd_ = -1;
};

}  // namespace rotacal
