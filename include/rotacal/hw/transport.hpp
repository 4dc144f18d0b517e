// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Byte transport under the protocol code: a serial port through libserialport, or a
/// pseudo-terminal through plain POSIX termios (Debian's libserialport 0.1.1 refuses ptys with
/// SP_ERR_ARG). Every read is bounded by a timeout; a device that went away raises
/// DeviceDisconnected instead of looking like silence.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rotacal/core/error.hpp"

namespace rotacal::hw {

/// A serial-port failure; the message names the port and carries the OS / libserialport text.
class SerialError : public IoError {
 public:
  using IoError::IoError;
};

/// The device closed the line or was unplugged.
class DeviceDisconnected : public SerialError {
 public:
  using SerialError::SerialError;
};

enum class Parity { none, odd, even };
enum class FlowControl { none, xon_xoff, rts_cts };

struct SerialSettings {
  int baud = 115200;
  int data_bits = 8;  ///< 5..8
  Parity parity = Parity::none;
  int stop_bits = 1;  ///< 1 or 2
  FlowControl flow = FlowControl::none;
};

/// Throws InvalidArgument naming the setting that is out of range.
void validate(const SerialSettings& s);

class ByteTransport {
 public:
  virtual ~ByteTransport() = default;
  /// Up to `max` bytes; waits at most `timeout_ms` for the first one; 0 means timeout.
  /// Throws DeviceDisconnected if the line is gone, SerialError on other failures.
  virtual std::size_t read(std::uint8_t* buf, std::size_t max, int timeout_ms) = 0;
  /// All `n` bytes within `timeout_ms`, or SerialError.
  virtual void write(const std::uint8_t* data, std::size_t n, int timeout_ms) = 0;
  void write(const std::string& text, int timeout_ms) {
    write(reinterpret_cast<const std::uint8_t*>(text.data()), text.size(), timeout_ms);
  }
  /// Discard unread input (stale bytes from before a command).
  virtual void flush_input() = 0;
  virtual void close() = 0;
  virtual const std::string& path() const = 0;
};

/// Follow symlinks such as /dev/serial/by-id/... to the device node (libserialport 0.1.1 does
/// not). Throws SerialError naming the path if it does not exist.
std::string resolve_port_path(const std::string& path);
/// True for pseudo-terminal slaves (/dev/pts/N) after resolving.
bool is_pseudo_terminal(const std::string& resolved_path);

/// Open a port: ptys through termios, everything else through libserialport.
std::unique_ptr<ByteTransport> open_port(const std::string& path, const SerialSettings& settings);
/// The two backends, for callers that must choose.
std::unique_ptr<ByteTransport> open_termios(const std::string& path,
                                            const SerialSettings& settings);
std::unique_ptr<ByteTransport> open_libserialport(const std::string& path,
                                                  const SerialSettings& settings);

struct PortInfo {
  std::string path;
  std::string description;
  std::string transport;  ///< "native", "usb", "bluetooth"
};
/// Serial ports libserialport finds (ptys are not listed).
std::vector<PortInfo> list_serial_ports();

}  // namespace rotacal::hw
