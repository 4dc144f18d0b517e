// SPDX-License-Identifier: BSD-3-Clause
// The output rule: regular files replaced atomically, devices and FIFOs written through,
// everything else (directories, the command's inputs, its other outputs) refused.
#include "rotacal/io/output_file.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <random>
#include <vector>

#include "rotacal/core/error.hpp"

namespace rotacal {

namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw IoError(path + ": " + what);
}

[[noreturn]] void fail_errno(const std::string& path, const std::string& what, int err) {
  throw IoError(path + ": " + what + ": " + std::strerror(err));
}

std::string dir_of(const std::string& p) {
  const std::size_t slash = p.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return p.substr(0, slash);
}

std::string base_of(const std::string& p) {
  const std::size_t slash = p.find_last_of('/');
  return slash == std::string::npos ? p : p.substr(slash + 1);
}

// Follow symbolic links in the last component (a dangling link names the file it will
// create); the directories on the way are resolved by realpath later.
std::string follow_links(const std::string& user_path, const std::string& path0) {
  std::string p = path0;
  for (int hops = 0; hops < 40; ++hops) {
    struct stat st{};
    if (::lstat(p.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return p;
    std::string buf(PATH_MAX, '\0');
    const ssize_t n = ::readlink(p.c_str(), buf.data(), buf.size());
    if (n < 0) fail_errno(user_path, "cannot read symbolic link", errno);
    buf.resize(static_cast<std::size_t>(n));
    p = (!buf.empty() && buf[0] == '/') ? buf : dir_of(p) + "/" + buf;
  }
  fail(user_path, "too many levels of symbolic links");
}

// Absolute, with "." and ".." removed by text (for paths whose directory does not exist).
std::string lexically_normal(const std::string& p) {
  std::string abs = p;
  if (abs.empty() || abs[0] != '/') {
    char cwd[PATH_MAX];
    if (::getcwd(cwd, sizeof cwd) != nullptr) abs = std::string(cwd) + "/" + p;
  }
  std::vector<std::string> parts;
  std::size_t i = 0;
  while (i <= abs.size()) {
    const std::size_t j = std::min(abs.find('/', i), abs.size());
    const std::string part = abs.substr(i, j - i);
    if (part == "..") {
      if (!parts.empty()) parts.pop_back();
    } else if (!part.empty() && part != ".") {
      parts.push_back(part);
    }
    i = j + 1;
  }
  std::string out;
  for (const std::string& part : parts) out += "/" + part;
  return out.empty() ? "/" : out;
}

// What a path refers to: its canonical name and, if it exists, its device and inode.
struct Resolved {
  std::string canonical;  // realpath of the directory + "/" + final name, links followed
  std::string dir;        // realpath of the directory
  bool exists = false;
  struct stat st{};
};

Resolved resolve(const std::string& user_path, bool require_parent) {
  if (user_path.empty()) fail("(empty path)", "an output path must not be empty");
  if (user_path.find('\0') != std::string::npos)
    throw IoError(std::string(user_path.c_str()) + "...: path contains a NUL byte");
  Resolved r;
  const std::string target = follow_links(user_path, user_path);
  const std::string base = base_of(target);
  if (base.empty() || base == "." || base == "..") fail(user_path, "is a directory, not a file");
  char dir_buf[PATH_MAX];
  if (::realpath(dir_of(target).c_str(), dir_buf) == nullptr) {
    if (!require_parent) {
      r.canonical = lexically_normal(target);
      return r;
    }
    if (errno == ENOENT || errno == ENOTDIR)
      fail(user_path, "the directory " + dir_of(target) + " does not exist");
    fail_errno(user_path, "cannot resolve directory " + dir_of(target), errno);
  }
  r.dir = dir_buf;
  r.canonical = (r.dir == "/" ? "" : r.dir) + "/" + base;
  if (::stat(r.canonical.c_str(), &r.st) == 0) {
    r.exists = true;
  } else if (errno != ENOENT) {
    fail_errno(user_path, "cannot stat", errno);
  }
  return r;
}

bool same_file(const Resolved& a, const Resolved& b) {
  if (a.exists && b.exists) return a.st.st_dev == b.st.st_dev && a.st.st_ino == b.st.st_ino;
  return a.canonical == b.canonical;
}

OutputKind classify(const std::string& path, const OutputOptions& options, Resolved& out) {
  out = resolve(path, /*require_parent=*/true);
  OutputKind kind = OutputKind::Replace;
  if (out.exists) {
    const mode_t m = out.st.st_mode;
    if (S_ISDIR(m)) fail(path, "is a directory, not a file");
    if (S_ISCHR(m) || S_ISFIFO(m)) {
      kind = OutputKind::WriteThrough;
    } else if (!S_ISREG(m)) {
      fail(path, S_ISBLK(m) ? "is a block device: refusing to write to it"
                            : "is not a regular file, "
                              "character device or FIFO");
    }
    if (::access(out.canonical.c_str(), W_OK) != 0) fail_errno(path, "cannot write", errno);
  }
  if (kind == OutputKind::Replace && ::access(out.dir.c_str(), W_OK | X_OK) != 0)
    fail_errno(path, "cannot create files in " + out.dir, errno);
  // Devices such as /dev/null may be named as input and output alike; only files are compared.
  if (kind == OutputKind::Replace) {
    for (const std::string& in : options.inputs) {
      if (in.empty()) continue;
      if (same_file(out, resolve(in, false)))
        fail(path, "is also an input of this command (" + in + "): refusing to overwrite it");
    }
    for (const std::string& other : options.other_outputs) {
      if (other.empty()) continue;
      if (same_file(out, resolve(other, false)))
        fail(path, "is also another output of this command (" + other + ")");
    }
  }
  return kind;
}

void write_all(int fd, const std::string& data, const std::string& path) {
  const char* p = data.data();
  std::size_t left = data.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      fail_errno(path, "write failed", errno);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
}

void write_through(const std::string& path, const Resolved& r, const std::string& data) {
  int fd;
  do {
    fd = ::open(r.canonical.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
  } while (fd < 0 && errno == EINTR);
  if (fd < 0) fail_errno(path, "cannot open for writing", errno);
  try {
    write_all(fd, data, path);
  } catch (...) {
    ::close(fd);
    throw;
  }
  if (::close(fd) != 0 && errno != EINTR) fail_errno(path, "write failed", errno);
}

// A temporary of a run killed before its rename (kill -9, power loss) stays behind: the next
// write into that directory removes it when its name's process is gone and it is older than
// kStaleTemporarySeconds (a live write takes seconds; a directory shared with another host
// may hold a live one whose process this host cannot see), and it is this user's own file.
void remove_stale_temporaries(const std::string& dir) {
  DIR* d = ::opendir(dir.c_str());
  if (d == nullptr) return;
  const std::time_t now = std::time(nullptr);
  while (const dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    const std::size_t dash = name.find('-', 9);
    if (name.rfind(".rotacal-", 0) != 0 || dash == std::string::npos || name.size() < 6 ||
        name.compare(name.size() - 5, 5, ".part") != 0)
      continue;
    const std::string digits = name.substr(9, dash - 9);
    if (digits.empty() || digits.size() > 9 ||
        digits.find_first_not_of("0123456789") != std::string::npos)
      continue;
    const pid_t pid = static_cast<pid_t>(std::stol(digits));
    if (pid == ::getpid() || ::kill(pid, 0) == 0 || errno != ESRCH) continue;
    const std::string full = (dir == "/" ? "" : dir) + "/" + name;
    struct stat st{};
    if (::lstat(full.c_str(), &st) != 0 || !S_ISREG(st.st_mode) || st.st_uid != ::geteuid() ||
        now - st.st_mtime < kStaleTemporarySeconds)
      continue;
    (void)::unlink(full.c_str());
  }
  ::closedir(d);
}

// A temporary name in the target's directory: short (fits beside a 255-byte target name),
// hidden, unique per process and attempt, created with O_EXCL so no existing file is touched;
// the process id in the name lets a later run tell a temporary left by a killed one.
int create_temporary(const std::string& path, const Resolved& r, std::string& tmp) {
  remove_stale_temporaries(r.dir);
  std::random_device rd;
  std::mt19937_64 gen((static_cast<std::uint64_t>(rd()) << 32) ^ rd() ^
                      static_cast<std::uint64_t>(::getpid()));
  static const char hex[] = "0123456789abcdef";
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::uint64_t x = gen();
    std::string name = ".rotacal-" + std::to_string(::getpid()) + "-";
    for (int i = 0; i < 16; ++i, x >>= 4) name += hex[x & 15];
    tmp = (r.dir == "/" ? "" : r.dir) + "/" + name + ".part";
    const mode_t mode = r.exists ? (r.st.st_mode & 07777) : 0666;
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, mode);
    if (fd >= 0) {
      if (r.exists) (void)::fchmod(fd, r.st.st_mode & 07777);  // not narrowed by the umask
      return fd;
    }
    if (errno != EEXIST && errno != EINTR)
      fail_errno(path, "cannot create a temporary file in " + r.dir, errno);
  }
  fail(path, "cannot find a free temporary file name in " + r.dir);
}

void replace(const std::string& path, const Resolved& r, const std::string& data) {
  std::string tmp;
  const int fd = create_temporary(path, r, tmp);
  try {
    write_all(fd, data, path);
    if (::fsync(fd) != 0) fail_errno(path, "fsync failed", errno);
  } catch (...) {
    ::close(fd);
    ::unlink(tmp.c_str());
    throw;
  }
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    fail_errno(path, "write failed", err);
  }
  if (::rename(tmp.c_str(), r.canonical.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    fail_errno(path, "cannot replace", err);
  }
  // The rename is durable only once the directory entry is on disk.
  const int dfd = ::open(r.dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    (void)::fsync(dfd);
    ::close(dfd);
  }
}

}  // namespace

OutputKind check_output(const std::string& path, const OutputOptions& options) {
  Resolved r;
  return classify(path, options, r);
}

void write_output(const std::string& path, const std::string& data, const OutputOptions& options) {
  Resolved r;
  if (classify(path, options, r) == OutputKind::WriteThrough)
    write_through(path, r, data);
  else
    replace(path, r, data);
}

void write_output(const std::string& path, const std::function<std::string()>& produce,
                  const OutputOptions& options) {
  check_output(path, options);  // refuse a bad path before the work
  const std::string data = produce();
  write_output(path, data, options);
}

OutputStream::OutputStream(const std::string& path, const OutputOptions& options) : path_(path) {
  Resolved r;
  const OutputKind kind = classify(path, options, r);
  target_ = r.canonical;
  directory_ = r.dir;
  if (kind == OutputKind::WriteThrough) {
    do {
      fd_ = ::open(r.canonical.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
    } while (fd_ < 0 && errno == EINTR);
    if (fd_ < 0) fail_errno(path, "cannot open for writing", errno);
  } else {
    fd_ = create_temporary(path, r, temporary_);
  }
}

OutputStream::~OutputStream() {
  try {
    commit();
  } catch (...) {  // NOLINT(bugprone-empty-catch): a destructor must not throw; commit() named it
  }
}

void OutputStream::write(const std::string& text) {
  if (fd_ < 0) fail(path_, "the output is already closed");
  write_all(fd_, text, path_);
}

void OutputStream::discard() {
  if (fd_ < 0) return;
  ::close(fd_);
  fd_ = -1;
  if (!temporary_.empty()) ::unlink(temporary_.c_str());
}

void OutputStream::commit() {
  if (fd_ < 0) return;
  const int fd = fd_;
  fd_ = -1;
  if (temporary_.empty()) {
    if (::close(fd) != 0 && errno != EINTR) fail_errno(path_, "write failed", errno);
    return;
  }
  const bool synced = ::fsync(fd) == 0;
  const int sync_err = errno;
  if (::close(fd) != 0 || !synced) {
    // The rows are measurements: keep them under the temporary name rather than delete them.
    fail_errno(path_, "write failed (the rows so far are in " + temporary_ + ")",
               synced ? errno : sync_err);
  }
  if (::rename(temporary_.c_str(), target_.c_str()) != 0)
    fail_errno(path_, "cannot replace (the rows are in " + temporary_ + ")", errno);
  const int dfd = ::open(directory_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {
    (void)::fsync(dfd);
    ::close(dfd);
  }
}

}  // namespace rotacal
