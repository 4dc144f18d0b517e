// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Recorders: read an instrument through a ByteTransport and write a session file as they go.
/// Every row is flushed before the next read, so stopping (Ctrl-C, crash, unplug) never loses
/// what was read. Lost, corrupt and garbled data are counted and marked in the file with `#`
/// lines (`# gap: ...`, `# corrupt: ...`), never silently skipped.
/// A recording that ends with no row (an instrument that never answers) writes nothing: a
/// previous file at the path is left as it was (RecordSummary::rows is 0).

#include <Eigen/Core>
#include <functional>
#include <string>

#include "rotacal/ballbar/timeline.hpp"
#include "rotacal/circular/timeline.hpp"
#include "rotacal/hw/pose_window.hpp"
#include "rotacal/hw/probe_protocol.hpp"
#include "rotacal/hw/transport.hpp"
#include "rotacal/session/session.hpp"

namespace rotacal::hw {

/// Progress of a recording, passed to the callback a few times a second.
struct RecordProgress {
  std::size_t rows = 0;        ///< rows written
  std::size_t lost = 0;        ///< samples known lost (sequence gaps, missing poses)
  std::size_t corrupt = 0;     ///< frames / replies that failed their check
  double device_time_s = 0.0;  ///< how far into the program
  double program_duration_s = 0.0;
};

enum class StopReason {
  end_of_program,  ///< the instrument said END / every pose was read
  stopped,         ///< the progress callback asked to stop (Ctrl-C)
  disconnected,    ///< the line went away
  silence,         ///< nothing arrived for `silence_timeout_s`
  no_valid_data,   ///< bytes arrived but none decoded: wrong baud rate or protocol
};
std::string to_string(StopReason r);

struct RecordSummary {
  std::size_t rows = 0;
  std::size_t frames = 0;         ///< valid sample frames / replies decoded
  std::size_t lost = 0;           ///< samples lost (sequence gaps) or poses without readings
  std::size_t crc_errors = 0;     ///< frames that failed their checksum
  std::size_t malformed = 0;      ///< well-framed but unusable frames / unparsable replies
  std::size_t garbage_bytes = 0;  ///< bytes between frames that were not part of any frame
  std::size_t over_range = 0;     ///< readings the instrument flagged out of range (not written)
  std::size_t timeouts = 0;       ///< reads or requests that timed out
  /// Polled R-test: readings that may have been taken outside their pose's read window
  /// (the host was late), marked in the file and not used.
  std::size_t outside_window = 0;
  StopReason reason = StopReason::end_of_program;
  std::string detail;  ///< the error text for disconnected / no_valid_data
  /// One line for the console and the file's last `#` line.
  std::string describe() const;
};

struct RecordOptions {
  int read_timeout_ms = 100;
  double silence_timeout_s = 3.0;
  /// Garbage bytes with no valid frame in between before giving up (wrong baud / protocol).
  std::size_t max_garbage_without_data = 4096;
  double rate_hz = 1000.0;  ///< stream modes: requested sample rate
  bool zero = false;        ///< ballbar: send ZERO before START
  /// Virtual seconds per wall second of the instrument (polled modes pace on the host clock).
  double speed = 1.0;
  std::function<bool(const RecordProgress&)> progress;  ///< return false to stop
  double progress_interval_s = 0.25;
};

/// Record a ballbar test. Rows get the commanded pose of `program` at each sample's time and
/// length = L0 + displacement. Metadata names the port; stops at END, on the callback's
/// request, on disconnect or silence, leaving a valid file at `path` if a row was read.
RecordSummary record_ballbar(ByteTransport& port, const ProgramTimeline& program,
                             const std::string& path, const RecordOptions& options = {});
/// The same for an ISO 230-4 circular program: rows on a data arc get the run's label
/// (circular_XY_ccw, ...), every other row "transition" (circular/timeline.hpp), so the file is
/// what `rotacal circular analyze` reads.
RecordSummary record_ballbar(ByteTransport& port, const CircularTimeline& program,
                             const std::string& path, const RecordOptions& options = {});

/// Record an R-test. `program` holds the commanded rows (set-up, time, B, C, X, Y, Z) and the
/// nests; `dwell_s` is the time between poses. The readings taken inside each pose's read
/// window (pose_window.hpp: the middle 80 % of its dwell, when the program holds the table at
/// rest) are averaged into one row of raw d1,d2,d3 (with probe.N.dir metadata from
/// `probe_dirs`, so readers convert them to dx,dy,dz), with extra columns `n` (readings
/// averaged), `std_um` (their largest per-channel standard deviation), `t_s` (their mean
/// program time) and `margin_s` (the smallest distance, program s, between a reading and the
/// window's edges). Polled modes place a reading by the whole interval in which it may have
/// been taken (request sent .. reply received, widened by the uncertainty of the program
/// clock's start); one not surely inside its window is counted in `outside_window`, marked
/// `# outside: ...` and not used. A pose with no reading inside its window (the machine moved
/// on before the host could read) is marked `# missing: ...` and counted as lost.
RecordSummary record_rtest(ByteTransport& port, ProbeMode mode, const RtestSession& program,
                           double dwell_s, const Eigen::Matrix3d& probe_dirs,
                           const std::string& path, const RecordOptions& options = {});

}  // namespace rotacal::hw
