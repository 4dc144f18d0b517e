// SPDX-License-Identifier: BSD-3-Clause
// Hardware-layer benchmark.
//  1. Decoder throughput (MB/s): scan_frames + sample decoding over a recorded-like stream with
//     a little line noise, and the ASCII probe-reply parsers.
//  2. Sustained streams over ptys: a 1 kHz ballbar and a 1 kHz 3-channel probe stream at the
//     same time, each recorded to a file, for `--seconds` of instrument time (default 600 =
//     10 minutes) at `--speed` (default 1 = real time: the full run takes 10 minutes). Prints
//     the samples sent, written and lost for each (target: zero lost).
//     --smoke: 20 s of instrument time at speed 10, for CI.
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>

#include "rotacal/hw/ballbar_protocol.hpp"
#include "rotacal/hw/recorder.hpp"
#include "rotacal/hw/virtual_instrument.hpp"

using namespace rotacal;
using namespace rotacal::hw;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void decoder_throughput() {
  Bytes stream;
  for (std::uint32_t k = 0; stream.size() < (64u << 20); ++k) {
    const Bytes f = encode_ballbar_sample(
        {static_cast<std::uint16_t>(k), k * 1000u, static_cast<std::int32_t>(k), 0});
    stream.insert(stream.end(), f.begin(), f.end());
    if (k % 1000 == 0) stream.insert(stream.end(), {0x13, 0xAA, 0x00});  // a little line noise
  }
  const auto t0 = std::chrono::steady_clock::now();
  std::size_t samples = 0, pos = 0;
  while (pos < stream.size()) {  // 4 KiB reads, as the recorder does
    const std::size_t n = std::min<std::size_t>(4096 + 64, stream.size() - pos);
    const FrameScan s = scan_frames(stream.data() + pos, n);
    for (const Frame& f : s.frames) samples += decode_ballbar_sample(f).has_value();
    pos += s.consumed == 0 ? n : s.consumed;
  }
  const double dt = seconds_since(t0);
  std::printf("frame decoder: %.0f MB/s (%zu samples from %.0f MiB in %.3f s)\n",
              static_cast<double>(stream.size()) / dt / 1e6, samples,
              static_cast<double>(stream.size()) / (1 << 20), dt);

  std::string replies;
  while (replies.size() < (16u << 20)) replies += "M0,+01.2345,-00.1234,+FFFFFFF\r+012.3456\r";
  const auto t1 = std::chrono::steady_clock::now();
  const LineScan ls =
      split_lines(reinterpret_cast<const std::uint8_t*>(replies.data()), replies.size());
  std::size_t ok = 0;
  for (const std::string& line : ls.lines)
    ok += line[0] == 'M' ? parse_keyence_reply(line).has_value()
                         : parse_sylvac_reply(line).has_value();
  const double dt1 = seconds_since(t1);
  std::printf("probe reply parser: %.0f MB/s (%zu replies, all parsed: %s)\n",
              static_cast<double>(replies.size()) / dt1 / 1e6, ls.lines.size(),
              ok == ls.lines.size() ? "yes" : "NO");
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 600.0, speed = 1.0;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--smoke"))
      seconds = 20.0, speed = 10.0;
    else if (!std::strcmp(argv[i], "--seconds") && i + 1 < argc)
      seconds = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--speed") && i + 1 < argc)
      speed = std::atof(argv[++i]);
  }
  decoder_throughput();

  // Ballbar: the default test program with its feeds scaled so that it lasts `seconds`.
  BallbarSetup setup;
  const double natural = plan_ballbar_test(setup).duration();
  setup.feed_mm_per_min *= natural / seconds;
  setup.feed_deg_per_min *= natural / seconds;
  const BallbarPlan plan = plan_ballbar_test(setup);
  VirtualBallbarOptions bo;
  bo.truth.machine = setup.machine;
  bo.truth.pivot = setup.pivot;
  bo.rate_hz = 1000.0;
  bo.speed = speed;
  VirtualBallbar ballbar(ProgramTimeline(plan), bo);

  // R-test: the paper's 168 poses with the dwell that makes them last `seconds`, streamed at 1 kHz.
  VirtualRtestOptions ro;
  ro.mode = ProbeMode::stream;
  ro.rate_hz = 1000.0;
  ro.speed = speed;
  ro.sim.pattern.dwell_s = seconds / 168.0;
  VirtualRtest rtest(ro);

  ballbar.start();
  rtest.start();
  const std::string dir = std::filesystem::temp_directory_path().string();
  RecordOptions opt;
  opt.rate_hz = 1000.0;
  opt.speed = speed;
  RecordSummary sb, sr;
  std::printf("streaming %.0f s of 1 kHz ballbar and 1 kHz 3-channel probe data at speed x%g ...\n",
              seconds, speed);
  std::fflush(stdout);
  const auto t0 = std::chrono::steady_clock::now();
  std::thread tb([&] {
    auto port = open_port(ballbar.port(), {});
    sb = record_ballbar(*port, ProgramTimeline(plan), dir + "/rotacal-bench-ballbar.csv", opt);
  });
  std::thread tr([&] {
    auto port = open_port(rtest.port(), {});
    sr = record_rtest(*port, ProbeMode::stream, rtest.program(), ro.sim.pattern.dwell_s,
                      ro.probe_dirs, dir + "/rotacal-bench-rtest.csv", opt);
  });
  tb.join();
  tr.join();
  const double wall = seconds_since(t0);
  ballbar.stop();
  rtest.stop();
  const VirtualStats vb = ballbar.stats(), vr = rtest.stats();
  std::printf("ballbar: %llu samples sent, %zu written, %zu lost, %zu checksum errors (%s)\n",
              static_cast<unsigned long long>(vb.frames_sent), sb.rows, sb.lost, sb.crc_errors,
              to_string(sb.reason).c_str());
  std::printf(
      "probes:  %llu samples sent, %zu decoded, %zu lost, %zu checksum errors, %zu poses written "
      "(%s)\n",
      static_cast<unsigned long long>(vr.frames_sent), sr.frames, sr.lost, sr.crc_errors, sr.rows,
      to_string(sr.reason).c_str());
  std::printf("wall time %.1f s for %.0f s of data (speed x%g)\n", wall, seconds, speed);
  const bool ok =
      sb.lost == 0 && sr.lost == 0 && sb.rows == vb.frames_sent && sr.frames == vr.frames_sent;
  std::printf("lost samples: %zu (target 0): %s\n", sb.lost + sr.lost, ok ? "met" : "NOT MET");
  return ok ? 0 : 1;
}
