// SPDX-License-Identifier: BSD-3-Clause
// Transports: pseudo-terminal open, read timeouts, hang-up as a disconnect.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>

#include "rotacal/hw/pseudo_terminal.hpp"
#include "rotacal/hw/transport.hpp"

using namespace rotacal;
using namespace rotacal::hw;

TEST_CASE("a pty carries bytes both ways through the termios backend", "[hw]") {
  PseudoTerminal pty;
  auto port = open_port(pty.slave_path(), {});
  CHECK(port->path() == pty.slave_path());
  port->write("ID?\n", 100);
  char buf[16] = {};
  ssize_t n = 0;
  for (int i = 0; i < 100 && n <= 0; ++i) {
    n = ::read(pty.master(), buf, sizeof buf);
    if (n <= 0) ::usleep(1000);
  }
  CHECK(std::string(buf, static_cast<std::size_t>(std::max<ssize_t>(n, 0))) == "ID?\n");
  const std::uint8_t reply[] = {0xAA, 0x55, 0x00, 0x0D,
                                0x0A};  // binary passes unchanged (raw mode)
  REQUIRE(::write(pty.master(), reply, sizeof reply) == 5);
  std::uint8_t got[8] = {};
  std::size_t total = 0;
  for (int i = 0; i < 10 && total < 5; ++i)
    total += port->read(got + total, sizeof got - total, 50);
  CHECK(total == 5);
  CHECK(std::equal(reply, reply + 5, got));
  CHECK(port->read(got, sizeof got, 20) == 0);  // silence is a timeout, not an error
  CHECK(pty.host_baud() == 115200);
}

TEST_CASE("an unplugged device is reported as disconnected", "[hw]") {
  PseudoTerminal pty;
  auto port = open_port(pty.slave_path(), {});
  pty.hang_up();
  std::uint8_t buf[4];
  CHECK_THROWS_AS(port->read(buf, sizeof buf, 200), DeviceDisconnected);
}

TEST_CASE("symlinks such as /dev/serial/by-id are resolved before opening", "[hw]") {
  PseudoTerminal pty;
  const std::string link =
      (std::filesystem::temp_directory_path() / "rotacal-test-port-link").string();
  std::filesystem::remove(link);
  std::filesystem::create_symlink(pty.slave_path(), link);
  CHECK(resolve_port_path(link) == pty.slave_path());
  auto port = open_port(link, {});
  CHECK(port->path() == pty.slave_path());
  std::filesystem::remove(link);
}

TEST_CASE("errors name the port and the reason", "[hw]") {
  try {
    open_port("/dev/rotacal-no-such-port", {});
    FAIL("opened a port that does not exist");
  } catch (const SerialError& e) {
    CHECK_THAT(e.what(), Catch::Contains("/dev/rotacal-no-such-port"));
  }
  PseudoTerminal pty;
  SerialSettings bad;
  bad.data_bits = 9;
  CHECK_THROWS_AS(open_port(pty.slave_path(), bad), InvalidArgument);
  bad = {};
  bad.baud = 12345;
  CHECK_THROWS_WITH(open_port(pty.slave_path(), bad), Catch::Contains("12345"));
  // libserialport 0.1.1 refuses ptys; its refusal comes through with its own words.
  try {
    open_libserialport(pty.slave_path(), {});
    SUCCEED("this libserialport accepts ptys");
  } catch (const SerialError& e) {
    CHECK_THAT(e.what(), Catch::Contains(pty.slave_path()) && Catch::Contains("libserialport"));
  }
}

TEST_CASE("listing serial ports works without hardware", "[hw]") {
  const auto ports = list_serial_ports();  // may be empty in a container; must not throw
  for (const auto& p : ports) CHECK_FALSE(p.path.empty());
}
