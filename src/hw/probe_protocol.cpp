// SPDX-License-Identifier: BSD-3-Clause
// The ASCII probe dialects (sylvac-, keyence-style) and the probe stream frame
// (probe_protocol.hpp).
#include "rotacal/hw/probe_protocol.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "rotacal/core/error.hpp"

namespace rotacal::hw {

namespace {

// A signed decimal "+012.3456": sign, at most 4 integer digits (a gauge reads well under 10 m),
// an optional point and at most 6 decimals; nothing else.
std::optional<double> parse_signed_decimal(const std::string& s) {
  if (s.size() < 2 || (s[0] != '+' && s[0] != '-')) return std::nullopt;
  int int_digits = 0, frac_digits = 0;
  bool point = false;
  for (std::size_t i = 1; i < s.size(); ++i) {
    if (s[i] >= '0' && s[i] <= '9') {
      (point ? frac_digits : int_digits) += 1;
    } else if (s[i] == '.' && !point) {
      point = true;
    } else {
      return std::nullopt;
    }
  }
  if (int_digits == 0 || int_digits > 4 || frac_digits > 6) return std::nullopt;
  return std::strtod(s.c_str(), nullptr);
}

std::string format_signed(double mm, const char* fmt) {
  char buf[32];
  std::snprintf(buf, sizeof buf, fmt, mm);
  return buf;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out(1);
  for (char c : s) {
    if (c == sep)
      out.emplace_back();
    else
      out.back() += c;
  }
  return out;
}

std::optional<int> channel_digit(const std::string& s, std::size_t pos, int lo, int hi) {
  if (s.size() != pos + 1 || s[pos] < '0' + lo || s[pos] > '0' + hi) return std::nullopt;
  return s[pos] - '0';
}

std::optional<GaugeValue> parse_keyence_value(const std::string& s) {
  if (s == "+FFFFFFF") return GaugeValue{GaugeValue::Kind::over_range, 0.0, 0};
  if (s == "-FFFFFFF") return GaugeValue{GaugeValue::Kind::under_range, 0.0, 0};
  const auto v = parse_signed_decimal(s);
  if (!v) return std::nullopt;
  return GaugeValue{GaugeValue::Kind::value, *v, 0};
}

std::string format_keyence_value(const GaugeValue& v) {
  switch (v.kind) {
    case GaugeValue::Kind::over_range:
      return "+FFFFFFF";
    case GaugeValue::Kind::under_range:
      return "-FFFFFFF";
    default:
      return format_signed(v.mm, "%+08.4f");
  }
}

}  // namespace

std::string to_string(ProbeMode m) {
  switch (m) {
    case ProbeMode::sylvac:
      return "sylvac";
    case ProbeMode::keyence:
      return "keyence";
    case ProbeMode::stream:
      return "stream";
  }
  return "?";
}

ProbeMode parse_probe_mode(const std::string& text) {
  if (text == "sylvac") return ProbeMode::sylvac;
  if (text == "keyence") return ProbeMode::keyence;
  if (text == "stream") return ProbeMode::stream;
  throw InvalidArgument("probe mode '" + text + "': expected sylvac, keyence or stream");
}

LineScan split_lines(const std::uint8_t* data, std::size_t n, std::size_t max_line) {
  LineScan scan;
  std::string current;
  std::size_t start = 0;  // first byte of the current line
  bool overlong = false;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t c = data[i];
    if (c == '\r' || c == '\n') {
      if (overlong)
        scan.garbage_bytes += current.size();
      else if (!current.empty())
        scan.lines.push_back(current);
      current.clear();
      overlong = false;
      start = i + 1;
      continue;
    }
    if (c < 0x20 || c > 0x7E) {
      ++scan.garbage_bytes;
      continue;
    }
    if (overlong) {
      ++scan.garbage_bytes;
      continue;
    }
    current += static_cast<char>(c);
    if (current.size() > max_line) overlong = true;
  }
  scan.consumed = overlong ? n : start;
  if (overlong) scan.garbage_bytes += current.size();
  return scan;
}

namespace {
// A request of either dialect: one prefix character and the channel digit.
std::string request_line(const char* who, char prefix, int channel, int lo, int hi) {
  if (channel < lo || channel > hi)
    throw InvalidArgument(std::string(who) + ": channel " + std::to_string(channel) + " is not " +
                          std::to_string(lo) + ".." + std::to_string(hi));
  return prefix + std::to_string(channel) + "\r";
}

std::optional<int> parse_request(const std::string& line, char prefix, int lo, int hi) {
  return line.size() == 2 && line[0] == prefix ? channel_digit(line, 1, lo, hi) : std::nullopt;
}
}  // namespace

std::string sylvac_request(int channel) {
  return request_line("sylvac_request", '?', channel, 1, 3);
}

std::optional<int> parse_sylvac_request(const std::string& line) {
  return parse_request(line, '?', 1, 3);
}

std::optional<GaugeValue> parse_sylvac_reply(const std::string& line) {
  if (line == "Err01") return GaugeValue{GaugeValue::Kind::over_range, 0.0, 1};
  if (line.size() == 5 && line.rfind("Err", 0) == 0 && std::isdigit(line[3]) &&
      std::isdigit(line[4]))
    return GaugeValue{GaugeValue::Kind::error, 0.0, std::atoi(line.c_str() + 3)};
  if (line == "?") return GaugeValue{GaugeValue::Kind::error, 0.0, -1};
  const auto v = parse_signed_decimal(line);
  if (!v) return std::nullopt;
  return GaugeValue{GaugeValue::Kind::value, *v, 0};
}

std::string format_sylvac_reply(const GaugeValue& v) {
  switch (v.kind) {
    case GaugeValue::Kind::value:
      return format_signed(v.mm, "%+09.4f") + "\r";
    case GaugeValue::Kind::over_range:
    case GaugeValue::Kind::under_range:
      return "Err01\r";
    case GaugeValue::Kind::error: {
      if (v.code < 0) return "?\r";
      char buf[16];
      std::snprintf(buf, sizeof buf, "Err%02d\r", v.code % 100);
      return buf;
    }
  }
  return "?\r";
}

std::string keyence_request(int channel) {
  return request_line("keyence_request", 'M', channel, 0, 3);
}

std::optional<int> parse_keyence_request(const std::string& line) {
  return parse_request(line, 'M', 0, 3);
}

std::optional<KeyenceReply> parse_keyence_reply(const std::string& line) {
  const auto f = split(line, ',');
  if (f.size() == 3 && f[0] == "ER") {  // "ER,M1,02"
    if (f[1].size() != 2 || f[1][0] != 'M') return std::nullopt;
    const auto ch = channel_digit(f[1], 1, 0, 3);
    if (!ch || f[2].size() != 2 || !std::isdigit(f[2][0]) || !std::isdigit(f[2][1]))
      return std::nullopt;
    return KeyenceReply{*ch, {GaugeValue{GaugeValue::Kind::error, 0.0, std::atoi(f[2].c_str())}}};
  }
  if (f.empty() || f[0].size() != 2 || f[0][0] != 'M') return std::nullopt;
  const auto ch = channel_digit(f[0], 1, 0, 3);
  if (!ch) return std::nullopt;
  const std::size_t expected = *ch == 0 ? 3 : 1;
  if (f.size() != expected + 1) return std::nullopt;
  KeyenceReply r{*ch, {}};
  for (std::size_t i = 1; i < f.size(); ++i) {
    const auto v = parse_keyence_value(f[i]);
    if (!v) return std::nullopt;
    r.values.push_back(*v);
  }
  return r;
}

std::string format_keyence_reply(const KeyenceReply& r) {
  if (r.values.size() == 1 && r.values[0].kind == GaugeValue::Kind::error) {
    char buf[24];
    std::snprintf(buf, sizeof buf, "ER,M%d,%02d\r", r.channel, r.values[0].code % 100);
    return buf;
  }
  std::string out = "M" + std::to_string(r.channel);
  for (const auto& v : r.values) out += "," + format_keyence_value(v);
  return out + "\r";
}

Bytes encode_probe_sample(const ProbeFrame& f) {
  Bytes p;
  put_u16(p, f.seq);
  put_u32(p, f.t_us);
  for (std::int32_t v : f.nm) put_u32(p, static_cast<std::uint32_t>(v));
  p.push_back(f.status);
  return encode_frame(kProbeSampleFrame, p);
}

std::optional<ProbeFrame> decode_probe_sample(const Frame& f) {
  if (f.type != kProbeSampleFrame || f.payload.size() != 19) return std::nullopt;
  const std::uint8_t* p = f.payload.data();
  ProbeFrame s;
  s.seq = get_u16(p);
  s.t_us = get_u32(p + 2);
  for (int i = 0; i < 3; ++i) s.nm[i] = static_cast<std::int32_t>(get_u32(p + 6 + 4 * i));
  s.status = p[18];
  return s;
}

}  // namespace rotacal::hw
