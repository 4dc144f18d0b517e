// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Virtual instruments: a ballbar and an R-test that open a pseudo-terminal and speak the
/// protocols of stream_protocol.hpp, ballbar_protocol.hpp and probe_protocol.hpp, driven by the
/// machine simulator.
/// They run on their own thread until stopped, and can act out the faults a real link has
/// (garbage, corrupt and lost frames, split writes, unplug, silence, wrong baud rate).

#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "rotacal/ballbar/model.hpp"
#include "rotacal/ballbar/timeline.hpp"
#include "rotacal/circular/simulate.hpp"
#include "rotacal/circular/timeline.hpp"
#include "rotacal/hw/frame.hpp"
#include "rotacal/hw/pose_window.hpp"
#include "rotacal/hw/probe_protocol.hpp"
#include "rotacal/hw/pseudo_terminal.hpp"
#include "rotacal/rtest/simulate.hpp"

namespace rotacal::hw {

/// Faults to act out, counted in streamed frames (0 / -1: never).
struct FaultInjection {
  int garbage_every = 0;      ///< after every Nth frame, 7 bytes of line noise
  int corrupt_every = 0;      ///< every Nth frame has one bit flipped (checksum fails)
  int drop_every = 0;         ///< every Nth frame is not sent (sequence gap)
  bool split_frames = false;  ///< every frame in two writes, 1 ms apart
  long close_after =
      -1;  ///< hang up the line after this many frames, once the host has read them (unplug)
  long silence_after = -1;  ///< stop sending after this many frames, line stays open
};

/// What an instrument did, for tests and the `virtual` command's summary.
struct VirtualStats {
  std::uint64_t frames_sent = 0;
  std::uint64_t frames_dropped = 0;
  std::uint64_t frames_corrupted = 0;
  std::uint64_t replies_sent = 0;  ///< text replies / polled answers
  bool finished = false;           ///< the program ran to its end
};

/// Common part: the pty, the serving thread, pacing, fault injection, and the stream protocol
/// both instruments speak (stream_protocol.hpp: ID?, RATE, START, STOP, samples, END).
class VirtualInstrument {
 public:
  virtual ~VirtualInstrument();
  /// The path a host opens, e.g. /dev/pts/7.
  const std::string& port() const { return pty_.slave_path(); }
  /// Serve on a background thread.
  void start();
  /// Stop serving and join the thread (idempotent). Rethrows an error the thread died of.
  void stop();
  /// The program has run to its end and the host has read everything sent (or 10 s have
  /// passed since the end, for a host that stopped reading), or the instrument has stopped.
  /// A caller that hangs up when this turns true does not cut off the last samples and END.
  bool finished() const;
  VirtualStats stats() const;

 protected:
  /// `rate_hz`: the stream's sample rate until the host sends RATE (1..1000 Hz).
  VirtualInstrument(int baud, double speed, double rate_hz, const FaultInjection& faults);
  /// Stop and join the thread without throwing. Every derived destructor calls it first: the
  /// thread calls serve_once(), which must not outlive the derived object.
  void halt() noexcept;
  /// One pass of the serving loop, called every millisecond or so: answer the lines that
  /// arrived (answer()), then send the stream's samples that are due (serve_stream()).
  virtual void serve_once();
  /// One host line. Here: the stream protocol's commands; ZERO goes to zero().
  virtual void answer(const std::string& line);
  /// "<model> <firmware>" for the ID reply.
  virtual std::string identity() const = 0;
  /// ZERO at the current pose; false if the instrument has no such command (it answers ERR).
  virtual bool zero() { return false; }
  /// Program time after which the stream ends with END.
  virtual double stream_end() const = 0;
  /// The sample frame at program time t.
  virtual Bytes sample_frame(double t, std::uint16_t seq) = 0;
  /// Virtual time, s, since `clock_start()` (wall time times speed).
  double now() const;
  void clock_start();
  bool clock_running() const { return clock_running_; }
  /// Command lines that arrived from the host since the last call.
  std::vector<std::string> read_lines();
  /// A reply (text frame or ASCII line): never faulted, except by a wrong baud rate.
  void send_reply(const Bytes& bytes);
  void send_reply(const std::string& text) { send_reply(Bytes(text.begin(), text.end())); }
  void mark_finished();

 private:
  /// Every sample frame due by now(), at most 200 a pass; END once past stream_end().
  void serve_stream();
  /// A streamed frame: faults applied, counted.
  void send_frame(Bytes frame);
  void write_all(const Bytes& bytes);
  void run();

  PseudoTerminal pty_;
  int baud_;
  double speed_;
  FaultInjection faults_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> finished_{false};     ///< the program has run to its end
  std::atomic<bool> thread_done_{false};  ///< the serving thread has stopped
  std::atomic<double> finished_at_{0.0};  ///< wall s
  bool hung_up_ = false;
  bool silent_ = false;
  bool clock_running_ = false;
  double clock_origin_ = 0.0;
  std::string line_buffer_;
  std::uint64_t stream_count_ = 0;
  bool streaming_ = false;
  double rate_hz_;
  std::uint64_t next_sample_ = 0;
  std::uint16_t seq_ = 0;
  mutable std::mutex stats_mutex_;
  VirtualStats stats_;
  std::string thread_error_;
};

struct VirtualBallbarOptions {
  BallbarMachineModel truth;  ///< the machine measured (its pivot is the actual pivot)
  double noise_um = 0.5;
  std::uint64_t seed = 1;
  double rate_hz = 1000.0;  ///< default sample rate (the host may send RATE)
  double speed = 1.0;       ///< virtual seconds per wall-clock second (>1: faster than real)
  int baud = 115200;
  FaultInjection faults;
};

/// A ballbar transducer on a machine running the test program: every sample is the exact
/// length (ballbar/model.hpp) at the commanded pose of that instant plus Gaussian noise.
class VirtualBallbar final : public VirtualInstrument {
 public:
  VirtualBallbar(ProgramTimeline program, const VirtualBallbarOptions& options);
  ~VirtualBallbar() override { halt(); }

 private:
  std::string identity() const override { return "rotacal-virtual-ballbar 1.0"; }
  bool zero() override;
  double stream_end() const override { return program_.duration(); }
  Bytes sample_frame(double t, std::uint16_t seq) override;
  double exact_length(double t) const;  ///< noise-free reading of the program at t, mm
  ProgramTimeline program_;
  VirtualBallbarOptions options_;
  struct Noise;
  std::shared_ptr<Noise> noise_;
  double zero_mm_ = 0.0;  ///< displacement subtracted after ZERO
};

struct VirtualCircularBallbarOptions {
  /// The machine's linear-axis errors, centring error, bar length error, and the noise: AR(1)
  /// with correlation noise_rho between successive streamed readings and marginal sigma
  /// noise_um, seeded (circular/simulate.hpp).
  CircularSimulationOptions sim;
  double rate_hz = 250.0;  ///< default sample rate (the host may send RATE)
  double speed = 1.0;      ///< virtual seconds per wall-clock second
  int baud = 115200;
  FaultInjection faults;
};

/// The same ballbar transducer on a machine running an ISO 230-4 circular program
/// (circular/timeline.hpp): every sample is circular_exact_reading at that instant plus the
/// AR(1) noise. Throws InvalidArgument for the options simulate_circular refuses.
class VirtualCircularBallbar final : public VirtualInstrument {
 public:
  VirtualCircularBallbar(CircularTimeline program, const VirtualCircularBallbarOptions& options);
  ~VirtualCircularBallbar() override { halt(); }

 private:
  std::string identity() const override { return "rotacal-virtual-ballbar 1.0"; }
  bool zero() override;
  double stream_end() const override { return program_.duration(); }
  Bytes sample_frame(double t, std::uint16_t seq) override;
  CircularTimeline program_;
  CircularBar bar_;
  struct Noise;
  std::shared_ptr<Noise> noise_;
  double zero_mm_ = 0.0;  ///< displacement subtracted after ZERO
};

struct VirtualRtestOptions {
  MachineModel truth =
      MachineModel::nominal(MachineType::BC_trt);  ///< the machine the probes measure
  RtestSimOptions sim;  ///< pattern (poses, dwell), noise, probe zeros sigma, seed
  Eigen::Matrix3d probe_dirs = Eigen::Matrix3d::Identity();  ///< rows: probe directions
  ProbeMode mode = ProbeMode::keyence;
  double rate_hz = 100.0;  ///< stream mode
  double speed = 1.0;
  int baud = 115200;
  FaultInjection faults;
};

/// An R-test on a B/C table running the measurement pattern: pose k is held at rest in its
/// read window (pose_window.hpp: the middle 80 % of its dwell around the time the simulator
/// gives it); in between the table moves. A polled reading is the probes at the instant the
/// request arrives.
/// Polled modes start the program at the first request, stream mode at START.
class VirtualRtest final : public VirtualInstrument {
 public:
  explicit VirtualRtest(const VirtualRtestOptions& options);
  ~VirtualRtest() override { halt(); }
  /// The commanded session the instrument runs (rows: set-up, time, B, C, X, Y, Z), and the
  /// probe zeros it was given, per set-up (table frame, mm).
  const RtestSession& program() const { return program_; }
  const std::vector<Eigen::Vector3d>& probe_zeros() const { return zeros_; }

 private:
  void serve_once() override;
  /// Polled modes answer requests; stream mode the stream protocol's commands.
  void answer(const std::string& line) override;
  std::string identity() const override { return "rotacal-virtual-rtest 1.0"; }
  double stream_end() const override;
  Bytes sample_frame(double t, std::uint16_t seq) override;
  /// Probe readings (mm) at virtual time t, and whether the table is at rest.
  Eigen::Vector3d readings_at(double t, bool* at_rest);
  VirtualRtestOptions options_;
  RtestSession program_;
  std::vector<Eigen::Vector3d> zeros_;
  std::vector<Eigen::Vector3d> exact_;  ///< noise-free readings per pose
  struct Noise;
  std::shared_ptr<Noise> noise_;
};

}  // namespace rotacal::hw
