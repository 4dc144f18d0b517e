// SPDX-License-Identifier: BSD-3-Clause
// Tests of the output rule (rotacal/io/output_file.hpp): files replaced atomically, devices
// and FIFOs written through, symlinks followed, directories/inputs/other outputs refused.
#include <dirent.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <csignal>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <sstream>
#include <thread>

#include "rotacal/core/error.hpp"
#include "rotacal/io/output_file.hpp"

using namespace rotacal;

namespace {

struct TempDir {
  std::string path;
  TempDir() {
    char tmpl[] = "/tmp/rotacal-output-test-XXXXXX";
    REQUIRE(::mkdtemp(tmpl) != nullptr);
    path = tmpl;
  }
  ~TempDir() { (void)std::system(("rm -rf '" + path + "'").c_str()); }
  std::string operator/(const std::string& name) const { return path + "/" + name; }
  std::vector<std::string> entries() const {
    std::vector<std::string> out;
    DIR* d = ::opendir(path.c_str());
    while (dirent* e = ::readdir(d)) {
      const std::string n = e->d_name;
      if (n != "." && n != "..") out.push_back(n);
    }
    ::closedir(d);
    std::sort(out.begin(), out.end());
    return out;
  }
};

std::string slurp(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void put(const std::string& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

}  // namespace

TEST_CASE("a new path and an existing regular file are written whole, nothing else is left") {
  TempDir d;
  write_output(d / "a.txt", std::string("first\n"));
  CHECK(slurp(d / "a.txt") == "first\n");
  write_output(d / "a.txt", std::string("second, longer\n"));
  CHECK(slurp(d / "a.txt") == "second, longer\n");
  CHECK(d.entries() == std::vector<std::string>{"a.txt"});
  CHECK(check_output(d / "a.txt") == OutputKind::Replace);
}

TEST_CASE("a user's own OUT.tmp is never touched") {
  TempDir d;
  put(d / "out.csv.tmp", "mine");
  write_output(d / "out.csv", std::string("x"));
  CHECK(slurp(d / "out.csv.tmp") == "mine");
  CHECK(d.entries() == std::vector<std::string>{"out.csv", "out.csv.tmp"});
}

TEST_CASE("a temporary left by a killed run is removed by the next write, a live one is not") {
  TempDir d;
  const pid_t child = ::fork();  // a process id that is gone once waited for
  if (child == 0) ::_exit(0);
  REQUIRE(child > 0);
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  const std::string gone = std::to_string(child), mine = std::to_string(::getpid());
  auto aged = [&](const std::string& name, long seconds) {
    put(d / name, "rows");
    const timespec t[2] = {{std::time(nullptr) - seconds, 0}, {std::time(nullptr) - seconds, 0}};
    REQUIRE(::utimensat(AT_FDCWD, (d / name).c_str(), t, 0) == 0);
  };
  aged(".rotacal-" + gone + "-0123456789abcdef.part", kStaleTemporarySeconds + 60);  // stale
  aged(".rotacal-" + gone + "-fedcba9876543210.part", 5);     // too young: maybe another host's
  aged(".rotacal-" + mine + "-00112233aabbccdd.part", 3600);  // a live process's
  aged(".rotacal-0123456789abcdef.part", 3600);               // no process id: not rotacal's now
  write_output(d / "out.csv", std::string("x"));
  std::vector<std::string> kept = {".rotacal-" + gone + "-fedcba9876543210.part",
                                   ".rotacal-" + mine + "-00112233aabbccdd.part",
                                   ".rotacal-0123456789abcdef.part", "out.csv"};
  std::sort(kept.begin(), kept.end());
  CHECK(d.entries() == kept);
}

TEST_CASE("the old file keeps its permission bits") {
  TempDir d;
  put(d / "p", "old");
  REQUIRE(::chmod((d / "p").c_str(), 0640) == 0);
  write_output(d / "p", std::string("new"));
  struct stat st{};
  REQUIRE(::stat((d / "p").c_str(), &st) == 0);
  CHECK((st.st_mode & 0777) == 0640);
}

TEST_CASE("a 255-character file name can be written") {
  TempDir d;
  const std::string name(255, 'n');
  write_output(d / name, std::string("long"));
  CHECK(slurp(d / name) == "long");
  write_output(d / name, std::string("again"));
  CHECK(slurp(d / name) == "again");
  CHECK(d.entries() == std::vector<std::string>{name});
}

TEST_CASE("a character device is written through, not replaced") {
  TempDir d;
  const std::string dev = d / "mynull";
  if (::mknod(dev.c_str(), S_IFCHR | 0666, ::makedev(1, 3)) != 0) {
    WARN("mknod not permitted here; checking /dev/null instead");
    CHECK(check_output("/dev/null") == OutputKind::WriteThrough);
    write_output("/dev/null", std::string("discarded"));
    return;
  }
  CHECK(check_output(dev) == OutputKind::WriteThrough);
  write_output(dev, std::string("discarded\n"));
  struct stat st{};
  REQUIRE(::lstat(dev.c_str(), &st) == 0);
  CHECK(S_ISCHR(st.st_mode));
  CHECK(st.st_rdev == ::makedev(1, 3));
  CHECK(d.entries() == std::vector<std::string>{"mynull"});
}

TEST_CASE("a FIFO is written through to its reader") {
  TempDir d;
  const std::string fifo = d / "pipe";
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  std::string got;
  std::thread reader([&] { got = slurp(fifo); });
  write_output(fifo, std::string("through the pipe\n"));
  reader.join();
  CHECK(got == "through the pipe\n");
  struct stat st{};
  REQUIRE(::lstat(fifo.c_str(), &st) == 0);
  CHECK(S_ISFIFO(st.st_mode));
  CHECK(d.entries() == std::vector<std::string>{"pipe"});
}

TEST_CASE("a symlink is followed: the target changes, the link stays a link") {
  TempDir d;
  put(d / "target.txt", "old");
  REQUIRE(::symlink("target.txt", (d / "link").c_str()) == 0);
  write_output(d / "link", std::string("new"));
  struct stat st{};
  REQUIRE(::lstat((d / "link").c_str(), &st) == 0);
  CHECK(S_ISLNK(st.st_mode));
  CHECK(slurp(d / "target.txt") == "new");
  // A dangling link creates the file it names.
  REQUIRE(::symlink("created.txt", (d / "dangling").c_str()) == 0);
  write_output(d / "dangling", std::string("made"));
  CHECK(slurp(d / "created.txt") == "made");
  CHECK(d.entries() == std::vector<std::string>{"created.txt", "dangling", "link", "target.txt"});
}

TEST_CASE("directories, missing parents, inputs and other outputs are refused by name") {
  TempDir d;
  REQUIRE(::mkdir((d / "sub").c_str(), 0755) == 0);
  CHECK_THROWS_WITH(write_output(d / "sub", std::string("x")), Catch::Contains("is a directory"));
  CHECK_THROWS_AS(write_output(d.path + "/", std::string("x")), IoError);
  CHECK_THROWS_WITH(write_output(d / "missing/out.csv", std::string("x")),
                    Catch::Contains("missing") && Catch::Contains("does not exist"));
  CHECK_THROWS_AS(write_output("", std::string("x")), IoError);
  CHECK_THROWS_WITH(write_output(std::string("a\0b", 3), std::string("x")), Catch::Contains("NUL"));

  put(d / "session.csv", "measurements");
  OutputOptions o;
  o.inputs = {d / "session.csv"};
  CHECK_THROWS_WITH(write_output(d / "session.csv", std::string("x"), o),
                    Catch::Contains("session.csv") && Catch::Contains("input"));
  // The same file by another name (a relative path through "..", a hard link).
  CHECK_THROWS_AS(write_output(d / "sub/../session.csv", std::string("x"), o), IoError);
  REQUIRE(::link((d / "session.csv").c_str(), (d / "hard.csv").c_str()) == 0);
  CHECK_THROWS_AS(write_output(d / "hard.csv", std::string("x"), o), IoError);
  CHECK(slurp(d / "session.csv") == "measurements");

  OutputOptions two;
  two.other_outputs = {d / "sub/../x.json"};  // neither exists yet
  CHECK_THROWS_WITH(write_output(d / "x.json", std::string("x"), two),
                    Catch::Contains("another output"));
  two.other_outputs = {d / "y.json"};
  write_output(d / "x.json", std::string("x"), two);
  CHECK(d.entries() == std::vector<std::string>{"hard.csv", "session.csv", "sub", "x.json"});
}

TEST_CASE("an exception while producing the content leaves the old file and no leftovers") {
  TempDir d;
  put(d / "prog.ngc", "G0 X0\nM30\n");
  CHECK_THROWS_AS(
      write_output(d / "prog.ngc",
                   []() -> std::string { throw InvalidArgument("--length: out of range"); }),
      InvalidArgument);
  CHECK(slurp(d / "prog.ngc") == "G0 X0\nM30\n");
  write_output(d / "prog.ngc", [] { return std::string("G0 X1\nM30\n"); });
  CHECK(slurp(d / "prog.ngc") == "G0 X1\nM30\n");
  CHECK(d.entries() == std::vector<std::string>{"prog.ngc"});
}

TEST_CASE("a failing write (disk full) leaves the old file intact and no leftovers") {
  // /dev/full fails every write with ENOSPC; a directory we cannot write to fails the create.
  CHECK_THROWS_WITH(write_output("/dev/full", std::string("x")), Catch::Contains("/dev/full"));
  TempDir d;
  put(d / "keep.txt", "old");
  if (::geteuid() != 0) {
    REQUIRE(::chmod(d.path.c_str(), 0555) == 0);
    CHECK_THROWS_AS(write_output(d / "keep.txt", std::string("new")), IoError);
    REQUIRE(::chmod(d.path.c_str(), 0755) == 0);
    CHECK(slurp(d / "keep.txt") == "old");
    CHECK(d.entries() == std::vector<std::string>{"keep.txt"});
  }
}

TEST_CASE("a write cut off mid-file (file size limit) keeps the old file and leaves nothing") {
  TempDir d;
  put(d / "prog.ngc", "G0 X0\nM30\n");
  // RLIMIT_FSIZE makes the write fail with EFBIG part-way, as a full disk would.
  struct rlimit old{};
  REQUIRE(::getrlimit(RLIMIT_FSIZE, &old) == 0);
  auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  struct rlimit small = old;
  small.rlim_cur = 4096;
  REQUIRE(::setrlimit(RLIMIT_FSIZE, &small) == 0);
  bool threw = false;
  std::string message;
  try {
    write_output(d / "prog.ngc", std::string(100000, 'G'));
  } catch (const IoError& e) {
    threw = true;
    message = e.what();
  }
  ::setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
  CHECK(threw);
  CHECK_THAT(message, Catch::Contains("prog.ngc") && Catch::Contains("write failed"));
  CHECK(slurp(d / "prog.ngc") == "G0 X0\nM30\n");
  CHECK(d.entries() == std::vector<std::string>{"prog.ngc"});
}

TEST_CASE("a stream (a recording) replaces the target when it ends, however it ends") {
  TempDir d;
  put(d / "rec.csv", "previous recording\n");
  {
    OutputStream out(d / "rec.csv");
    out.write("row 1\n");
    // Written as it comes, into the temporary file; the old file is untouched meanwhile.
    CHECK(slurp(out.writing_path()) == "row 1\n");
    CHECK(slurp(d / "rec.csv") == "previous recording\n");
    out.write("row 2\n");
  }  // destroyed without commit (an exception unwinding the recorder): still committed
  CHECK(slurp(d / "rec.csv") == "row 1\nrow 2\n");
  CHECK(d.entries() == std::vector<std::string>{"rec.csv"});

  OutputStream twice(d / "rec.csv");
  twice.write("again\n");
  twice.commit();
  twice.commit();  // a second commit does nothing
  CHECK_THROWS_WITH(twice.write("late\n"), Catch::Contains("closed"));
  CHECK(slurp(d / "rec.csv") == "again\n");
}

TEST_CASE("a discarded stream leaves the target as it was and nothing behind") {
  // A recording that measured nothing (issue 32) must not replace the previous file.
  TempDir d;
  put(d / "rec.csv", "previous recording\n");
  OutputStream out(d / "rec.csv");
  out.write("# header only\n");
  out.discard();
  out.discard();  // a second discard does nothing
  out.commit();   // nor does a commit after it
  CHECK(slurp(d / "rec.csv") == "previous recording\n");
  CHECK(d.entries() == std::vector<std::string>{"rec.csv"});
  OutputStream fresh(d / "new.csv");
  fresh.discard();
  CHECK(d.entries() == std::vector<std::string>{"rec.csv"});
}

TEST_CASE("a stream refuses its inputs and writes devices through") {
  TempDir d;
  put(d / "port", "not a port");
  OutputOptions o;
  o.inputs = {d / "port"};
  CHECK_THROWS_WITH(OutputStream(d / "port", o), Catch::Contains("input"));
  CHECK_THROWS_WITH(OutputStream(d.path), Catch::Contains("directory"));
  OutputStream null("/dev/null");
  CHECK(null.writing_path() == "/dev/null");
  null.write("discarded\n");
  null.commit();
  struct stat st{};
  REQUIRE(::stat("/dev/null", &st) == 0);
  CHECK(S_ISCHR(st.st_mode));
  CHECK(d.entries() == std::vector<std::string>{"port"});
}
