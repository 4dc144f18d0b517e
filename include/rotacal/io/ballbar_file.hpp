// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// `rotacal-ballbar/1` and `rotacal-rtest/1` files (../shared/spec/formats.md): strict readers
/// whose errors name file, line, column and what is wrong; writers whose output reads back
/// bit-identical (shortest round-trip decimal for every double); appending writers for
/// recorders, which flush every row so a crash never loses what was already read.

#include <istream>
#include <memory>
#include <string>
#include <variant>

#include "rotacal/io/output_file.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal {

/// Limits of what a session file may hold. Beyond them a value cannot come from a machine
/// tool (a typo, wrong units, binary data): the reader refuses it naming file, line and column,
/// before any numeric kernel sees it.
inline constexpr std::size_t kMaxLineBytes = 65536;  ///< one line, bytes
inline constexpr std::size_t kMaxLabelBytes = 256;   ///< a test or set-up label, a column name
inline constexpr double kMaxAbsPositionMm = 1.0e5;   ///< X, Y, Z, pivot, nests (100 m)
inline constexpr double kMaxAbsAngleDeg = 1.0e6;     ///< rotary angles (2778 turns)
inline constexpr double kMinLengthMm = 1.0e-3;       ///< ballbar lengths and L0
inline constexpr double kMaxLengthMm = 1.0e4;
inline constexpr double kMaxAbsTimeS = 1.0e9;           ///< time column (31 years)
inline constexpr double kMaxAbsDisplacementMm = 1.0e2;  ///< R-test dx, dy, dz and d1, d2, d3
inline constexpr double kMaxNoiseUm = 1.0e5;            ///< noise_um metadata

/// Read a ballbar session; throws ParseError (file, line, column, what) or IoError.
BallbarSession read_ballbar(const std::string& path);
/// Parse a ballbar session from a stream; `name` is used in error messages.
BallbarSession parse_ballbar(std::istream& in, const std::string& name);
/// Write a ballbar session by the output rule of rotacal/io/output_file.hpp (regular files
/// replaced atomically, devices written through); throws IoError naming the path,
/// InvalidArgument for a session that breaks the format.
void write_ballbar(const BallbarSession& session, const std::string& path);
/// The file text of a session.
std::string format_ballbar(const BallbarSession& session);

RtestSession read_rtest(const std::string& path);
RtestSession parse_rtest(std::istream& in, const std::string& name);
void write_rtest(const RtestSession& session, const std::string& path);
std::string format_rtest(const RtestSession& session);

/// Either kind of session, chosen by the file's `# format:` line.
using AnySession = std::variant<BallbarSession, RtestSession>;
AnySession read_session(const std::string& path);

/// Appending writer for recorders: writes the metadata and header at once, then one row per
/// append(), passed to the operating system before append() returns. The file follows the
/// output rule (io/output_file.hpp, OutputStream): it replaces the target when the writer is
/// closed or destroyed; `options` names the command's inputs and other outputs.
class BallbarWriter {
 public:
  /// `header` supplies machine, metadata and extra columns; its samples are not written.
  BallbarWriter(const std::string& path, const BallbarSession& header,
                const OutputOptions& options = {});
  BallbarWriter(const BallbarWriter&) = delete;
  BallbarWriter& operator=(const BallbarWriter&) = delete;
  void append(const BallbarSample& sample);
  /// A `# text` line at this point of the file (e.g. a gap marker).
  void annotate(const std::string& text);
  std::size_t rows() const { return rows_; }
  /// Where the rows are while the writer is open (io/output_file.hpp, OutputStream).
  std::string writing_path() const { return file_ ? file_->writing_path() : path_; }
  void close();
  /// Close without replacing the target (OutputStream::discard): the old file stays.
  void discard();

 private:
  std::unique_ptr<OutputStream> file_;
  std::string path_;
  MachineType machine_;  // rotary columns in its chain order
  std::size_t columns_ = 0;
  std::size_t rows_ = 0;
  double last_time_ = -1e300;
};

class RtestWriter {
 public:
  /// `header` supplies machine, nests, probe directions and metadata; `raw` selects d1,d2,d3
  /// columns (probe readings) instead of dx,dy,dz.
  RtestWriter(const std::string& path, const RtestSession& header, bool raw,
              const OutputOptions& options = {});
  RtestWriter(const RtestWriter&) = delete;
  RtestWriter& operator=(const RtestWriter&) = delete;
  void append(const RtestSample& sample);
  void annotate(const std::string& text);
  std::size_t rows() const { return rows_; }
  /// Where the rows are while the writer is open (io/output_file.hpp, OutputStream).
  std::string writing_path() const { return file_ ? file_->writing_path() : path_; }
  void close();
  /// Close without replacing the target (OutputStream::discard): the old file stays.
  void discard();

 private:
  std::unique_ptr<OutputStream> file_;
  std::string path_;
  MachineType machine_;
  bool raw_ = false;
  std::size_t extra_ = 0;
  std::size_t rows_ = 0;
  double last_time_ = -1e300;
};

/// Shortest decimal text that reads back as exactly `v`.
std::string format_number(double v);

}  // namespace rotacal
