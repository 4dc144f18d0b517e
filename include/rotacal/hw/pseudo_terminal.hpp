// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// A pseudo-terminal pair for virtual instruments: the instrument holds the master side, the
/// host opens `slave_path()` as if it were a serial port. Both sides are raw (no echo, no line
/// editing) so binary frames pass unchanged.

#include <cstddef>
#include <string>

namespace rotacal::hw {

class PseudoTerminal {
 public:
  /// Throws SerialError with the OS message if no pty can be allocated.
  PseudoTerminal();
  ~PseudoTerminal();
  PseudoTerminal(const PseudoTerminal&) = delete;
  PseudoTerminal& operator=(const PseudoTerminal&) = delete;

  int master() const { return master_; }
  const std::string& slave_path() const { return slave_path_; }
  /// Baud rate the host last configured on its side. A pty passes bytes unchanged at any
  /// rate, so a virtual instrument compares this with its own rate to act out a wrong-baud
  /// link (a real UART would deliver garbage). 0 if unknown.
  int host_baud() const;
  /// Bytes written by the instrument that the host has not read yet (0 once hung up).
  std::size_t unread() const;
  /// Close the master: the host's next read sees the line go away (an unplugged device).
  void hang_up();

 private:
  int master_ = -1;
  int slave_keepalive_ =
      -1;  ///< our own slave fd: keeps the master usable while no host is attached
  std::string slave_path_;
};

}  // namespace rotacal::hw
