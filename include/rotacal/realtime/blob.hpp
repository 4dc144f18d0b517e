// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The model blob: a realtime::Model as bytes, written by `rotacal export --controller realtime`
/// and read by a controller at start-up. Reading is the only step that may fail; it fails with
/// the field named and leaves the caller's model untouched (no partial load). The blob holds
/// numbers and one-letter codes only: no text of the model reaches the controller.
///
/// Layout (little-endian; f64 = IEEE 754 binary64, u8..u32 unsigned):
///   header   "RCRTBLOB" (8 bytes), u32 version (kBlobVersion), u32 payload bytes,
///            u32 CRC-32 (IEEE 802.3) of the payload
///   payload  u64 machine fingerprint (machine_fingerprint), u8 table axes, u8 rot index,
///            f64 pivot length; per axis: u8 letter, u8 on head, u8 principal + 1,
///            f64 x 24 (direction, point, position basis, direction basis column-major,
///            radial1, radial2); f64 x 8 location errors; f64 x 16 thermal gains (column-major
///            8 x 2); f64 x 3 linear reference; u16 effects, per effect u8 kind, u8 axis, u8
///            harmonic, u8 direction; u16 parameters, f64 each.

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include "rotacal/realtime/model.hpp"

namespace rotacal {
namespace realtime {

constexpr std::uint32_t kBlobVersion = 1;
constexpr char kBlobMagic[8] = {'R', 'C', 'R', 'T', 'B', 'L', 'O', 'B'};
constexpr std::size_t kBlobHeaderBytes = 20;

/// CRC-32 (the polynomial of zlib and IEEE 802.3), bit by bit: it runs once per load.
inline std::uint32_t crc32(const unsigned char* p, std::size_t n) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i) {
    c ^= p[i];
    for (int b = 0; b < 8; ++b) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return ~c;
}

/// FNV-1a (64 bit) of the nominal kinematics: the axes' letters, sides, directions and points,
/// and the pivot length. A controller configured for one machine refuses another's blob.
inline std::uint64_t machine_fingerprint(const Model& m) {
  std::uint64_t h = 1469598103934665603ull;
  const auto byte = [&h](unsigned char b) { h = (h ^ b) * 1099511628211ull; };
  const auto real = [&byte](double v) {
    std::uint64_t u;
    std::memcpy(&u, &v, 8);
    for (int i = 0; i < 8; ++i) byte(static_cast<unsigned char>(u >> (8 * i)));
  };
  byte(static_cast<unsigned char>(m.table_axes));
  byte(static_cast<unsigned char>(m.rot));
  real(m.pivot_length);
  for (const Axis& a : m.axes) {
    byte(static_cast<unsigned char>(a.name));
    byte(a.on_head ? 1 : 0);
    for (int i = 0; i < 3; ++i) real(a.direction[i]);
    for (int i = 0; i < 3; ++i) real(a.point[i]);
  }
  return h;
}

/// The blob of a model.
inline std::string encode(const Model& m) {
  std::string pay;
  const auto uint = [&pay](std::uint64_t v, int bytes) {
    for (int i = 0; i < bytes; ++i) pay.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  };
  const auto real = [&uint](double v) {
    std::uint64_t u;
    std::memcpy(&u, &v, 8);
    uint(u, 8);
  };
  uint(machine_fingerprint(m), 8);
  uint(static_cast<std::uint64_t>(m.table_axes), 1);
  uint(static_cast<std::uint64_t>(m.rot), 1);
  real(m.pivot_length);
  for (const Axis& a : m.axes) {
    uint(static_cast<unsigned char>(a.name), 1);
    uint(a.on_head ? 1 : 0, 1);
    uint(static_cast<std::uint64_t>(a.principal + 1), 1);
    for (int i = 0; i < 3; ++i) real(a.direction[i]);
    for (int i = 0; i < 3; ++i) real(a.point[i]);
    for (int i = 0; i < 6; ++i) real(a.position_basis.data()[i]);
    for (int i = 0; i < 6; ++i) real(a.direction_basis.data()[i]);
    for (int i = 0; i < 3; ++i) real(a.radial1[i]);
    for (int i = 0; i < 3; ++i) real(a.radial2[i]);
  }
  for (int i = 0; i < 8; ++i) real(m.errors.v[i]);
  for (int i = 0; i < 16; ++i) real(m.thermal_gain.data()[i]);
  for (int i = 0; i < 3; ++i) real(m.linear_reference[i]);
  uint(static_cast<std::uint64_t>(m.num_effects), 2);
  for (int i = 0; i < m.num_effects; ++i) {
    const Term& f = m.effects[i];
    uint(static_cast<std::uint64_t>(f.kind), 1);
    uint(static_cast<unsigned char>(f.axis), 1);
    uint(static_cast<std::uint64_t>(f.harmonic), 1);
    uint(static_cast<unsigned char>(f.direction), 1);
  }
  uint(static_cast<std::uint64_t>(m.num_params), 2);
  for (int i = 0; i < m.num_params; ++i) real(m.params[i]);
  std::string out(kBlobMagic, 8);
  const auto head = [&out](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  };
  head(kBlobVersion);
  head(static_cast<std::uint32_t>(pay.size()));
  head(crc32(reinterpret_cast<const unsigned char*>(pay.data()), pay.size()));
  return out + pay;
}

/// Outcome of decode: ok, or the field that is wrong and why (static strings).
struct LoadResult {
  bool ok = false;
  const char* field = "";
  const char* reason = "";
  int index = -1;  ///< the entry of an array field (effects, parameters, errors...), else -1
};

namespace detail {
// Reads the payload in order; the first failure is kept.
struct BlobReader {
  const unsigned char* p;
  std::size_t n, at = 0;
  LoadResult fail{true, "", "", -1};

  bool bad() const { return !fail.ok; }
  void refuse(const char* field, const char* reason, int index = -1) {
    if (fail.ok) fail = LoadResult{false, field, reason, index};
  }
  std::uint64_t uint(int bytes, const char* field) {
    if (bad()) return 0;
    if (at + static_cast<std::size_t>(bytes) > n) {
      refuse(field, "the payload ends before this field");
      return 0;
    }
    std::uint64_t v = 0;
    for (int i = 0; i < bytes; ++i) v |= static_cast<std::uint64_t>(p[at + i]) << (8 * i);
    at += static_cast<std::size_t>(bytes);
    return v;
  }
  double real(const char* field, int index = -1) {
    const std::uint64_t u = uint(8, field);
    double v;
    std::memcpy(&v, &u, 8);
    if (!bad() && !std::isfinite(v)) refuse(field, "not a finite number", index);
    return v;
  }
};

inline bool valid_letter(char c, const char* allowed) {
  for (; *allowed; ++allowed)
    if (c == *allowed) return true;
  return false;
}
}  // namespace detail

/// Reads a blob into `out`. `expected_machine`: the fingerprint of the machine the controller is
/// configured for (machine_fingerprint of its nominal model), 0 to accept any. On failure `out`
/// is unchanged. No allocation, no exception (it may run in a controller's start-up code).
inline LoadResult decode(const void* data, std::size_t size, std::uint64_t expected_machine,
                         Model& out) {
  const unsigned char* b = static_cast<const unsigned char*>(data);
  if (size < kBlobHeaderBytes) return {false, "header", "shorter than the 20-byte header", -1};
  if (std::memcmp(b, kBlobMagic, 8) != 0) return {false, "magic", "not a rotacal model blob", -1};
  const auto u32 = [b](std::size_t at) {
    return static_cast<std::uint32_t>(b[at]) | static_cast<std::uint32_t>(b[at + 1]) << 8 |
           static_cast<std::uint32_t>(b[at + 2]) << 16 |
           static_cast<std::uint32_t>(b[at + 3]) << 24;
  };
  if (u32(8) != kBlobVersion) return {false, "version", "written by another blob version", -1};
  const std::size_t n = u32(12);
  if (size - kBlobHeaderBytes < n) return {false, "length", "truncated", -1};
  if (size - kBlobHeaderBytes > n) return {false, "length", "bytes after the payload", -1};
  if (crc32(b + kBlobHeaderBytes, n) != u32(16))
    return {false, "checksum", "the payload does not match its CRC-32 (corrupt)", -1};

  Model m;  // read here, copied to `out` only when every field is valid (about 5 kB of stack)
  detail::BlobReader r{b + kBlobHeaderBytes, n};
  const std::uint64_t fingerprint = r.uint(8, "machine");
  m.table_axes = static_cast<int>(r.uint(1, "table_axes"));
  if (!r.bad() && m.table_axes > 2) r.refuse("table_axes", "more than 2");
  m.rot = static_cast<int>(r.uint(1, "rot_index"));
  if (!r.bad() && m.rot > 1) r.refuse("rot_index", "neither 0 nor 1");
  m.pivot_length = r.real("pivot_length");
  for (int k = 0; k < 2; ++k) {
    Axis& a = m.axes[k];
    a.name = static_cast<char>(r.uint(1, "axes.name"));
    if (!r.bad() && !detail::valid_letter(a.name, "ABC")) r.refuse("axes.name", "not A, B or C", k);
    a.on_head = r.uint(1, "axes.on_head") != 0;
    a.principal = static_cast<int>(r.uint(1, "axes.principal")) - 1;
    if (!r.bad() && a.principal > 2) r.refuse("axes.principal", "not -1, 0, 1 or 2", k);
    for (int i = 0; i < 3; ++i) a.direction[i] = r.real("axes.direction", k);
    for (int i = 0; i < 3; ++i) a.point[i] = r.real("axes.point", k);
    for (int i = 0; i < 6; ++i) a.position_basis.data()[i] = r.real("axes.position_basis", k);
    for (int i = 0; i < 6; ++i) a.direction_basis.data()[i] = r.real("axes.direction_basis", k);
    for (int i = 0; i < 3; ++i) a.radial1[i] = r.real("axes.radial1", k);
    for (int i = 0; i < 3; ++i) a.radial2[i] = r.real("axes.radial2", k);
    if (!r.bad() && std::abs(a.direction.norm() - 1.0) > 1e-9)
      r.refuse("axes.direction", "not a unit vector", k);
  }
  for (int i = 0; i < 8; ++i) m.errors.v[i] = r.real("errors", i);
  for (int i = 0; i < 16; ++i) m.thermal_gain.data()[i] = r.real("thermal_gain", i);
  for (int i = 0; i < 3; ++i) m.linear_reference[i] = r.real("linear_reference", i);
  m.num_effects = static_cast<int>(r.uint(2, "num_effects"));
  if (!r.bad() && m.num_effects > kMaxEffects) r.refuse("num_effects", "more than kMaxEffects");
  int params = 0;
  for (int i = 0; i < m.num_effects && !r.bad(); ++i) {
    Term& f = m.effects[i];
    const std::uint64_t kind = r.uint(1, "effects.kind");
    if (!r.bad() && kind >= static_cast<std::uint64_t>(kEffectKinds))
      r.refuse("effects.kind", "not a catalogue kind", i);
    f.kind = static_cast<EffectKind>(kind);
    f.axis = static_cast<char>(r.uint(1, "effects.axis"));
    if (!r.bad() && !detail::valid_letter(f.axis, "ABCXYZ") && f.axis != 0)
      r.refuse("effects.axis", "not an axis letter", i);
    f.harmonic = static_cast<int>(r.uint(1, "effects.harmonic"));
    f.direction = static_cast<char>(r.uint(1, "effects.direction"));
    if (!r.bad() && !detail::valid_letter(f.direction, "ABXYZ") && f.direction != 0)
      r.refuse("effects.direction", "not a direction letter", i);
    params += effect_num_params(f.kind);
  }
  m.num_params = static_cast<int>(r.uint(2, "num_params"));
  if (!r.bad() && m.num_params != params)
    r.refuse("num_params", "does not match the effects' parameter count");
  if (!r.bad() && m.num_params > kMaxParams) r.refuse("num_params", "more than kMaxParams");
  for (int i = 0; i < m.num_params && !r.bad(); ++i) m.params[i] = r.real("params", i);
  if (!r.bad() && r.at != n) r.refuse("length", "the payload is longer than its fields");
  if (r.bad()) return r.fail;
  if (fingerprint != machine_fingerprint(m))
    return {false, "machine", "the fingerprint does not match the stored kinematics", -1};
  if (expected_machine != 0 && fingerprint != expected_machine)
    return {false, "machine", "the blob is for another machine", -1};
  out = m;
  return {true, "", "", -1};
}

}  // namespace realtime
}  // namespace rotacal
