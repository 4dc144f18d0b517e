// SPDX-License-Identifier: BSD-3-Clause
// Recorders: the summary of a recording, and the ballbar recorder (recorder.hpp); the stream reader
// it shares with the R-test recorder is recording.hpp, the R-test recorder record_rtest.cpp.
#include "rotacal/hw/recorder.hpp"

#include "recording.hpp"
#include "rotacal/io/ballbar_file.hpp"

namespace rotacal::hw {

using namespace recording;

std::string to_string(StopReason r) {
  switch (r) {
    case StopReason::end_of_program:
      return "end of program";
    case StopReason::stopped:
      return "stopped";
    case StopReason::disconnected:
      return "device disconnected";
    case StopReason::silence:
      return "silence (timeout)";
    case StopReason::no_valid_data:
      return "no valid data";
  }
  return "?";
}

std::string RecordSummary::describe() const {
  std::string s = std::to_string(rows) + " rows; " + std::to_string(lost) + " lost, " +
                  std::to_string(crc_errors) + " checksum errors, " + std::to_string(malformed) +
                  " malformed, " + std::to_string(garbage_bytes) + " garbage bytes, " +
                  std::to_string(over_range) + " over range, " + std::to_string(timeouts) +
                  " timeouts";
  if (outside_window > 0)
    s += ", " + std::to_string(outside_window) + " polled readings outside their pose's window";
  s += "; stopped: " + to_string(reason);
  if (!detail.empty()) s += " (" + detail + ")";
  return s;
}

// ---------------------------------------------------------------------------------- ballbar

namespace {

// A ballbar recording against any program with header(), at(t) and duration().
template <typename Program>
RecordSummary record_ballbar_program(ByteTransport& port, const Program& program,
                                     const std::string& path, const RecordOptions& opt) {
  BallbarSession header = program.header();
  header.metadata = {{"recorded_from", port.path()},
                     {"recorded_at", utc_now()},
                     {"sample_rate_hz", fixed(opt.rate_hz, 0)}};
  BallbarWriter out(path, header, OutputOptions{{port.path()}, {}});
  const double L0 = header.ballbar_length;
  return run_recording(port, out, [&](RecordSummary& sum) {
    read_stream(
        port, opt, opt.zero, out, sum, decode_ballbar_sample,
        [&](double t, const BallbarFrame& s) {
          BallbarSample row = program.at(t);
          row.length = L0 + 1e-6 * s.displacement_nm;
          out.append(row);
        },
        program.duration());
  });
}

}  // namespace

RecordSummary record_ballbar(ByteTransport& port, const ProgramTimeline& program,
                             const std::string& path, const RecordOptions& opt) {
  return record_ballbar_program(port, program, path, opt);
}

RecordSummary record_ballbar(ByteTransport& port, const CircularTimeline& program,
                             const std::string& path, const RecordOptions& opt) {
  return record_ballbar_program(port, program, path, opt);
}

}  // namespace rotacal::hw
