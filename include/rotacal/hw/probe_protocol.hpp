// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// R-test probe protocols (docs/protocols.md): three displacement probes behind one interface,
/// read in a polled ASCII mode (two dialects, modelled on common digital gauge interfaces) or
/// in a streamed binary mode. Pure encode/decode functions over bytes.
///
/// sylvac   host "?1\r" (channel 1..3)     ->  "+012.3456\r" (mm) | "Err01\r" over range |
///                                              "Err02\r" probe not connected | "?\r" unknown
/// keyence  host "M0\r" (all channels)     ->  "M0,+01.2345,-00.1234,+00.0012\r"
///          host "M1\r" .. "M3\r"          ->  "M1,+01.2345\r"
///          a value "+FFFFFFF" / "-FFFFFFF" is over / under range; "ER,M1,02\r" is an error
/// stream   frame type 0x03 (19 bytes): seq u16 | t_us u32 | d1,d2,d3 nm i32 | status u8
///          (bit i: channel i+1 out of range); started and stopped with the stream commands of
///          stream_protocol.hpp, as the ballbar stream.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "rotacal/hw/frame.hpp"

namespace rotacal::hw {

enum class ProbeMode { sylvac, keyence, stream };
std::string to_string(ProbeMode m);
/// "sylvac", "keyence" or "stream"; throws InvalidArgument otherwise.
ProbeMode parse_probe_mode(const std::string& text);

/// One channel's answer.
struct GaugeValue {
  enum class Kind { value, over_range, under_range, error };
  Kind kind = Kind::value;
  double mm = 0.0;  ///< for Kind::value
  int code = 0;     ///< for Kind::error (the device's error number)
  bool ok() const { return kind == Kind::value; }
};

/// Complete lines in data[0..n) (terminated by CR or LF; an empty line between CR and LF is
/// skipped). Bytes outside printable ASCII and lines longer than `max_line` are garbage.
struct LineScan {
  std::vector<std::string> lines;
  std::size_t consumed = 0;
  std::size_t garbage_bytes = 0;
};
LineScan split_lines(const std::uint8_t* data, std::size_t n, std::size_t max_line = 80);

// --- sylvac-style polled mode
std::string sylvac_request(int channel);
/// The reply to a request; nullopt if the line is not a reply of this dialect.
std::optional<GaugeValue> parse_sylvac_reply(const std::string& line);
std::string format_sylvac_reply(const GaugeValue& v);
/// A request line seen by the device: the channel (1..3), nullopt if it is not one.
std::optional<int> parse_sylvac_request(const std::string& line);

// --- keyence-style polled mode
/// "M0" (channel 0: all three) or "M1".."M3".
std::string keyence_request(int channel);
struct KeyenceReply {
  int channel = 0;                 ///< 0 = all
  std::vector<GaugeValue> values;  ///< 3 for M0, 1 otherwise; one error value for "ER"
};
std::optional<KeyenceReply> parse_keyence_reply(const std::string& line);
std::string format_keyence_reply(const KeyenceReply& r);
std::optional<int> parse_keyence_request(const std::string& line);

// --- streamed binary mode
inline constexpr std::uint8_t kProbeSampleFrame = 0x03;
struct ProbeFrame {
  std::uint16_t seq = 0;
  std::uint32_t t_us = 0;
  std::array<std::int32_t, 3> nm{};  ///< d1, d2, d3, nm
  std::uint8_t status = 0;           ///< bit i: channel i+1 out of range
};
Bytes encode_probe_sample(const ProbeFrame& f);
std::optional<ProbeFrame> decode_probe_sample(const Frame& f);

}  // namespace rotacal::hw
