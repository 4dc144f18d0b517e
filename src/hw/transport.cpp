// SPDX-License-Identifier: BSD-3-Clause
// ByteTransport: termios for pseudo-terminals, port listing and opening (transport.hpp).
#include "rotacal/hw/transport.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdlib>
#include <cstring>

namespace rotacal::hw {

void validate(const SerialSettings& s) {
  if (s.baud <= 0)
    throw InvalidArgument("serial baud rate " + std::to_string(s.baud) + " must be positive");
  if (s.data_bits < 5 || s.data_bits > 8)
    throw InvalidArgument("serial data bits " + std::to_string(s.data_bits) + " must be 5..8");
  if (s.stop_bits != 1 && s.stop_bits != 2)
    throw InvalidArgument("serial stop bits " + std::to_string(s.stop_bits) + " must be 1 or 2");
}

std::string resolve_port_path(const std::string& path) {
  char buf[PATH_MAX];
  if (!::realpath(path.c_str(), buf))
    throw SerialError("serial port " + path + ": " + std::strerror(errno));
  return buf;
}

bool is_pseudo_terminal(const std::string& resolved_path) {
  return resolved_path.rfind("/dev/pts/", 0) == 0;
}

namespace {

speed_t termios_speed(int baud, const std::string& path) {
  switch (baud) {
    case 9600:
      return B9600;
    case 19200:
      return B19200;
    case 38400:
      return B38400;
    case 57600:
      return B57600;
    case 115200:
      return B115200;
    case 230400:
      return B230400;
    case 460800:
      return B460800;
    case 921600:
      return B921600;
    default:
      throw InvalidArgument("serial port " + path + ": baud rate " + std::to_string(baud) +
                            " is not one of 9600 .. 921600");
  }
}

class TermiosTransport final : public ByteTransport {
 public:
  TermiosTransport(const std::string& path, const SerialSettings& s) : path_(path) {
    validate(s);
    fd_ = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0)
      throw SerialError("serial port " + path + ": cannot open: " + std::strerror(errno));
    termios t{};
    if (::tcgetattr(fd_, &t) != 0) fail("tcgetattr");
    ::cfmakeraw(&t);
    const speed_t sp = termios_speed(s.baud, path);
    ::cfsetispeed(&t, sp);
    ::cfsetospeed(&t, sp);
    t.c_cflag &= ~(CSIZE | PARENB | PARODD | CSTOPB | CRTSCTS);
    t.c_cflag |= CLOCAL | CREAD;
    t.c_cflag |= s.data_bits == 5 ? CS5 : s.data_bits == 6 ? CS6 : s.data_bits == 7 ? CS7 : CS8;
    if (s.parity != Parity::none) t.c_cflag |= PARENB | (s.parity == Parity::odd ? PARODD : 0);
    if (s.stop_bits == 2) t.c_cflag |= CSTOPB;
    t.c_iflag &= ~(IXON | IXOFF | IXANY);
    if (s.flow == FlowControl::xon_xoff) t.c_iflag |= IXON | IXOFF;
    if (s.flow == FlowControl::rts_cts) t.c_cflag |= CRTSCTS;
    t.c_cc[VMIN] = 0;
    t.c_cc[VTIME] = 0;
    if (::tcsetattr(fd_, TCSANOW, &t) != 0) fail("tcsetattr");
  }
  ~TermiosTransport() override { close(); }

  std::size_t read(std::uint8_t* buf, std::size_t max, int timeout_ms) override {
    check_open();
    pollfd p{fd_, POLLIN, 0};
    const int r = ::poll(&p, 1, timeout_ms);
    if (r < 0) {
      if (errno == EINTR) return 0;
      fail("poll");
    }
    if (r == 0) return 0;
    if (p.revents & (POLLHUP | POLLERR) && !(p.revents & POLLIN))
      throw DeviceDisconnected("serial port " + path_ + ": the device closed the line");
    const ssize_t n = ::read(fd_, buf, max);
    if (n > 0) return static_cast<std::size_t>(n);
    if (n == 0 || errno == EIO)  // EOF / EIO: the other end is gone (pty master closed, unplug)
      throw DeviceDisconnected("serial port " + path_ + ": the device closed the line");
    if (errno == EAGAIN || errno == EINTR) return 0;
    fail("read");
  }

  void write(const std::uint8_t* data, std::size_t n, int timeout_ms) override {
    check_open();
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    std::size_t done = 0;
    while (done < n) {
      const ssize_t w = ::write(fd_, data + done, n - done);
      if (w > 0) {
        done += static_cast<std::size_t>(w);
        continue;
      }
      if (w < 0 && errno == EIO)
        throw DeviceDisconnected("serial port " + path_ + ": the device closed the line");
      if (w < 0 && errno != EAGAIN && errno != EINTR) fail("write");
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                            deadline - std::chrono::steady_clock::now())
                            .count();
      if (left <= 0) throw SerialError("serial port " + path_ + ": write timed out");
      pollfd p{fd_, POLLOUT, 0};
      ::poll(&p, 1, static_cast<int>(left));
    }
  }

  void flush_input() override {
    check_open();
    ::tcflush(fd_, TCIFLUSH);
  }

  void close() override {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  const std::string& path() const override { return path_; }

 private:
  [[noreturn]] void fail(const char* what) const {
    throw SerialError("serial port " + path_ + ": " + what + ": " + std::strerror(errno));
  }
  void check_open() const {
    if (fd_ < 0) throw SerialError("serial port " + path_ + ": used after close");
  }
  std::string path_;
  int fd_ = -1;
};

}  // namespace

std::unique_ptr<ByteTransport> open_termios(const std::string& path,
                                            const SerialSettings& settings) {
  return std::make_unique<TermiosTransport>(resolve_port_path(path), settings);
}

std::unique_ptr<ByteTransport> open_port(const std::string& path, const SerialSettings& settings) {
  const std::string resolved = resolve_port_path(path);
  if (is_pseudo_terminal(resolved)) return open_termios(resolved, settings);
  return open_libserialport(resolved, settings);
}

}  // namespace rotacal::hw
