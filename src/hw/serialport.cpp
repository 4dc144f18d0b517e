// SPDX-License-Identifier: BSD-3-Clause
// libserialport backend of ByteTransport (real serial ports, USB adapters).
#include <libserialport.h>

#include <chrono>
#include <memory>

#include "rotacal/hw/transport.hpp"

namespace rotacal::hw {

namespace {

// libserialport's text for the last failure: its own for SP_ERR_ARG / SP_ERR_SUPP, the OS
// message for SP_ERR_FAIL.
std::string sp_message(sp_return r) {
  switch (r) {
    case SP_ERR_ARG:
      return "invalid argument (libserialport SP_ERR_ARG)";
    case SP_ERR_MEM:
      return "out of memory (libserialport SP_ERR_MEM)";
    case SP_ERR_SUPP:
      return "not supported by this port (libserialport SP_ERR_SUPP)";
    case SP_ERR_FAIL: {
      char* msg = sp_last_error_message();
      std::string text = msg ? msg : "unknown failure";
      sp_free_error_message(msg);
      return text + " (libserialport SP_ERR_FAIL)";
    }
    default:
      return "libserialport error " + std::to_string(static_cast<int>(r));
  }
}

class SerialPortTransport final : public ByteTransport {
 public:
  SerialPortTransport(const std::string& path, const SerialSettings& s) : path_(path) {
    validate(s);
    check(sp_get_port_by_name(path.c_str(), &port_), "find");
    check(sp_open(port_, SP_MODE_READ_WRITE), "open");
    open_ = true;
    check(sp_set_baudrate(port_, s.baud), "set baud rate " + std::to_string(s.baud));
    check(sp_set_bits(port_, s.data_bits), "set data bits");
    check(sp_set_parity(port_, s.parity == Parity::none  ? SP_PARITY_NONE
                               : s.parity == Parity::odd ? SP_PARITY_ODD
                                                         : SP_PARITY_EVEN),
          "set parity");
    check(sp_set_stopbits(port_, s.stop_bits), "set stop bits");
    check(sp_set_flowcontrol(port_, s.flow == FlowControl::none       ? SP_FLOWCONTROL_NONE
                                    : s.flow == FlowControl::xon_xoff ? SP_FLOWCONTROL_XONXOFF
                                                                      : SP_FLOWCONTROL_RTSCTS),
          "set flow control");
  }
  ~SerialPortTransport() override {
    close();
    if (port_) sp_free_port(port_);
  }

  // sp_blocking_read returns 0 both on timeout and, at once, on end-of-file after an unplug.
  // An empty read that came back well before its timeout is therefore counted, and a few in a
  // row are taken as a disconnect.
  std::size_t read(std::uint8_t* buf, std::size_t max, int timeout_ms) override {
    check_open();
    const auto t0 = std::chrono::steady_clock::now();
    const int r = sp_blocking_read(port_, buf, max, static_cast<unsigned>(timeout_ms));
    if (r < 0)
      throw SerialError("serial port " + path_ +
                        ": read: " + sp_message(static_cast<sp_return>(r)));
    if (r > 0) {
      quick_empty_reads_ = 0;
      return static_cast<std::size_t>(r);
    }
    const auto waited =
        std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - t0)
            .count();
    if (timeout_ms > 0 && waited < timeout_ms / 2) {
      if (++quick_empty_reads_ >= 3)
        throw DeviceDisconnected("serial port " + path_ + ": end of file (device unplugged?)");
    } else {
      quick_empty_reads_ = 0;
    }
    return 0;
  }

  void write(const std::uint8_t* data, std::size_t n, int timeout_ms) override {
    check_open();
    const int r = sp_blocking_write(port_, data, n, static_cast<unsigned>(timeout_ms));
    if (r < 0)
      throw SerialError("serial port " + path_ +
                        ": write: " + sp_message(static_cast<sp_return>(r)));
    if (static_cast<std::size_t>(r) != n)
      throw SerialError("serial port " + path_ + ": write timed out");
  }

  void flush_input() override {
    check_open();
    check(sp_flush(port_, SP_BUF_INPUT), "flush");
  }

  void close() override {
    if (open_) sp_close(port_);
    open_ = false;
  }
  const std::string& path() const override { return path_; }

 private:
  void check(sp_return r, const std::string& what) const {
    if (r != SP_OK) throw SerialError("serial port " + path_ + ": " + what + ": " + sp_message(r));
  }
  void check_open() const {
    if (!open_) throw SerialError("serial port " + path_ + ": used after close");
  }
  std::string path_;
  sp_port* port_ = nullptr;
  bool open_ = false;
  int quick_empty_reads_ = 0;
};

}  // namespace

std::unique_ptr<ByteTransport> open_libserialport(const std::string& path,
                                                  const SerialSettings& settings) {
  return std::make_unique<SerialPortTransport>(resolve_port_path(path), settings);
}

std::vector<PortInfo> list_serial_ports() {
  sp_port** ports = nullptr;
  const sp_return r = sp_list_ports(&ports);
  if (r != SP_OK) throw SerialError("listing serial ports: " + sp_message(r));
  std::vector<PortInfo> out;
  for (sp_port** p = ports; *p; ++p) {
    const char* desc = sp_get_port_description(*p);
    const sp_transport t = sp_get_port_transport(*p);
    out.push_back({sp_get_port_name(*p), desc ? desc : "",
                   t == SP_TRANSPORT_USB         ? "usb"
                   : t == SP_TRANSPORT_BLUETOOTH ? "bluetooth"
                                                 : "native"});
  }
  sp_free_port_list(ports);
  return out;
}

}  // namespace rotacal::hw
