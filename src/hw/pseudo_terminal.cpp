// SPDX-License-Identifier: BSD-3-Clause
// Pseudo-terminals for the virtual instruments (pseudo_terminal.hpp).
#include "rotacal/hw/pseudo_terminal.hpp"

#include <fcntl.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#include "rotacal/hw/transport.hpp"

namespace rotacal::hw {

namespace {
[[noreturn]] void fail(const std::string& what) {
  throw SerialError("pseudo-terminal: " + what + ": " + std::strerror(errno));
}

int baud_of(speed_t s) {
  switch (s) {
    case B9600:
      return 9600;
    case B19200:
      return 19200;
    case B38400:
      return 38400;
    case B57600:
      return 57600;
    case B115200:
      return 115200;
    case B230400:
      return 230400;
    case B460800:
      return 460800;
    case B921600:
      return 921600;
    default:
      return 0;
  }
}
}  // namespace

PseudoTerminal::PseudoTerminal() {
  master_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (master_ < 0) fail("posix_openpt");
  if (::grantpt(master_) != 0) fail("grantpt");
  if (::unlockpt(master_) != 0) fail("unlockpt");
  char name[128];
  if (::ptsname_r(master_, name, sizeof name) != 0) fail("ptsname");
  slave_path_ = name;
  slave_keepalive_ = ::open(name, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (slave_keepalive_ < 0) fail("open " + slave_path_);
  termios t{};
  if (::tcgetattr(slave_keepalive_, &t) != 0) fail("tcgetattr");
  ::cfmakeraw(&t);
  if (::tcsetattr(slave_keepalive_, TCSANOW, &t) != 0) fail("tcsetattr");
  const int flags = ::fcntl(master_, F_GETFL);
  ::fcntl(master_, F_SETFL, flags | O_NONBLOCK);
}

PseudoTerminal::~PseudoTerminal() { hang_up(); }

int PseudoTerminal::host_baud() const {
  if (slave_keepalive_ < 0) return 0;
  termios t{};
  if (::tcgetattr(slave_keepalive_, &t) != 0) return 0;
  return baud_of(::cfgetospeed(&t));
}

std::size_t PseudoTerminal::unread() const {
  int n = 0;
  if (slave_keepalive_ < 0 || ::ioctl(slave_keepalive_, FIONREAD, &n) != 0 || n < 0) return 0;
  return static_cast<std::size_t>(n);
}

void PseudoTerminal::hang_up() {
  if (slave_keepalive_ >= 0) ::close(slave_keepalive_);
  if (master_ >= 0) ::close(master_);
  slave_keepalive_ = master_ = -1;
}

}  // namespace rotacal::hw
