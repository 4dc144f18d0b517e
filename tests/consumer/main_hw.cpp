// SPDX-License-Identifier: BSD-3-Clause
// Uses the installed serial layer: a frame through a pseudo-terminal and back.
#include <unistd.h>

#include <iostream>
#include <rotacal/hw/ballbar_protocol.hpp>
#include <rotacal/hw/pseudo_terminal.hpp>
#include <rotacal/hw/transport.hpp>

int main() {
  using namespace rotacal::hw;
  PseudoTerminal pty;
  auto port = open_port(pty.slave_path(), {});
  const Bytes frame = encode_ballbar_sample({7, 1000, -1234, 0});
  if (::write(pty.master(), frame.data(), frame.size()) != static_cast<ssize_t>(frame.size()))
    return 1;
  std::uint8_t buf[64];
  std::size_t n = 0;
  for (int i = 0; i < 20 && n < frame.size(); ++i) n += port->read(buf + n, sizeof buf - n, 50);
  const FrameScan scan = scan_frames(buf, n);
  const auto s = scan.frames.size() == 1 ? decode_ballbar_sample(scan.frames[0]) : std::nullopt;
  std::cout << "sample through " << pty.slave_path() << ": seq " << (s ? s->seq : -1) << ", "
            << (s ? s->displacement_nm : 0) << " nm\n";
  return s && s->seq == 7 && s->displacement_nm == -1234 ? 0 : 1;
}
