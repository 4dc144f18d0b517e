// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// The residual noise as measured data have it: correlated in time (servo loops and sensor
/// filters at 100 Hz - 1 kHz, thermal wander). One autoregressive model per stream of
/// readings (a group, i.e. a ballbar test or an R-test nest, split into channels when several
/// readings share a time stamp, as an R-test's dx, dy, dz do), its order chosen from the data;
/// the whitener that makes the residuals independent with unit variance (generalised least
/// squares); and generators of coloured noise for tests and benches.
///
/// Per stream x_0..x_{n-1} (time order, mean removed):
///   x_t = phi_1 x_{t-1} + ... + phi_p x_{t-p} + e_t,  e_t ~ N(0, s_e^2)
/// estimated by Burg's method (stable for correlations near 1, where Yule-Walker is biased),
/// with p = argmin over 0..max_order of BIC(p) = n ln v_p + p ln n (v_p: Burg's prediction
/// error variance of order p). White noise comes out p = 0.
/// Integrated autocorrelation time (samples): tau = sum_k rho_k = s_e^2 / (s_x^2 (1 - sum phi)^2)
/// (the long-run variance over the marginal one: AR(1) gives (1 + rho)/(1 - rho)); effective
/// number of independent samples n_eff = n / tau.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "rotacal/core/whitener.hpp"

namespace rotacal {

struct NoiseModelOptions {
  int max_order = 8;        ///< largest AR order tried (limited further to n/4 per stream)
  int min_stream_size = 8;  ///< shorter streams are taken as white (too short for an AR fit)
  /// Smallest order BIC may choose (at most the stream's own limit, n/4): a bound on the lag-1
  /// coefficient needs its estimate even where BIC would call the stream white.
  int min_order = 0;
  /// AR coefficients shared by all streams (Burg's sums taken over every stream: the same
  /// sensor at the same rate in every test), each stream keeping its own variance, rows and
  /// sample interval. Per-stream Burg estimates of a few hundred readings are biased towards
  /// less correlation (by about (1 + 3 rho)/n), which makes tests against them too lenient.
  bool pooled = false;
  /// With `pooled`: pool only if every stream is correlated on its own; if some are white, the
  /// correlation is structure in some groups (an effect), not the sensor's, and each stream
  /// keeps its own model.
  bool pool_only_if_all_coloured = false;
  /// With `pooled`: one set of coefficients per session, the part of a stream's group before
  /// its first ':' (a diagnosis of several sessions names its groups "session:group",
  /// diagnose/multi_session.hpp): each instrument keeps its own noise model.
  bool pool_by_session = false;
  /// The R-test joint fit: when the residuals are correlated, estimate AR(1) + a random walk
  /// per stream by REML over what the fit leaves (estimate_noise_model_reml in
  /// core/noise_handling.hpp: probe zeros that wander between poses), instead of Burg's AR(p)
  /// on the residuals scaled by the bootstrap bias factor. The ballbar fit does not read it.
  bool reml_random_walk = true;
  /// Streams longer than this (readings) fall back to Burg + bias factor: each of REML's ~240
  /// likelihood evaluations takes a QR of the whitened Jacobian (readings x free parameters).
  int reml_max_stream_size = 2000;
};

/// The AR model of one stream.
struct NoiseStream {
  std::string group;
  int channel = 0;                   ///< index among the group's readings that share a time
  std::vector<Eigen::Index> rows;    ///< its readings' indices, in time order
  std::vector<double> ar;            ///< phi_1..phi_p (empty: white)
  std::vector<double> reflection;    ///< Burg's reflection coefficients k_1..k_p
  double innovation_sigma_um = 0.0;  ///< s_e
  double marginal_sigma_um = 0.0;    ///< s_x
  double correlation_samples = 1.0;  ///< integrated autocorrelation time tau, in samples
  double sample_interval_s = 0.0;    ///< median time between successive readings
  double correlation_time_s = 0.0;   ///< tau * sample interval
  double effective_samples = 0.0;    ///< n / tau (at most n)
  /// 1 sigma of a random-walk step per reading, um (0: none). The stream's covariance is then
  /// the AR part's plus q^2 min(i, j) (i, j: positions in the stream): a level that wanders
  /// from reading to reading, as R-test probe zeros do between poses. The constant part of
  /// the walk is the stream's mean, which the fits take as a nuisance (a probe zero).
  double random_walk_step_um = 0.0;
  int order() const { return static_cast<int>(ar.size()); }
};

/// The noise model of a whole set of residuals.
struct NoiseModel {
  std::vector<NoiseStream> streams;
  std::size_t n = 0;                 ///< readings covered
  double sigma_um = 0.0;             ///< pooled marginal sigma (RMS over streams, by size)
  double innovation_sigma_um = 0.0;  ///< pooled innovation sigma
  double correlation_samples = 1.0;  ///< largest over the streams
  double correlation_time_s = 0.0;   ///< largest over the streams
  double effective_samples = 0.0;    ///< sum over the streams
  int max_order = 0;                 ///< largest AR order of any stream
  double random_walk_step_um = 0.0;  ///< largest random-walk step of any stream (0: none)
  bool white() const { return max_order == 0 && random_walk_step_um == 0.0; }
  /// e.g. "AR(1), rho 0.95, sigma 0.50 um, correlation time 0.39 s, 46 effective samples of 1800".
  std::string summary() const;
};

/// Estimate the noise model of `residuals_mm` (one per reading) grouped by `groups`, with each
/// group's readings put in order by `times` (s). Throws InvalidArgument if the sizes differ,
/// a residual or time is not finite, or max_order < 0.
NoiseModel estimate_noise_model(const std::vector<std::string>& groups,
                                const std::vector<double>& times,
                                const Eigen::VectorXd& residuals_mm,
                                const NoiseModelOptions& options = {});

/// What estimate_noise_model needs of a session besides its residuals: its streams (group,
/// channel) in time order and their sample intervals. Built once where many residual vectors of
/// one session are modelled (the diagnosis models what each candidate leaves): splitting the
/// readings into streams compares labels and sorts times, which costs as much as the AR fit.
struct NoiseStreamLayout {
  std::vector<std::vector<Eigen::Index>> rows;  ///< per stream, its rows in time order
  std::vector<std::string> group;               ///< per stream
  std::vector<int> channel;                     ///< per stream
  std::vector<double> sample_interval_s;        ///< per stream: median of its time steps
  std::size_t n = 0;                            ///< readings in the session

  /// Throws InvalidArgument if the sizes differ or a time is not finite.
  NoiseStreamLayout(const std::vector<std::string>& groups, const std::vector<double>& times);
  /// The streams of every group but `group`, over the same readings (models fitted to the other
  /// groups' residuals alone, as the layout of the session without that group would give).
  NoiseStreamLayout except_group(const std::string& group) const;

 private:
  NoiseStreamLayout() = default;
};

/// estimate_noise_model on a layout built once. Throws InvalidArgument if `residuals_mm` does not
/// hold layout.n values, one is not finite, or max_order < 0.
NoiseModel estimate_noise_model(const NoiseStreamLayout& layout,
                                const Eigen::VectorXd& residuals_mm,
                                const NoiseModelOptions& options = {});

/// `model` with the lag-1 coefficient of every AR(1) stream corrected for the bias that removing
/// the stream's mean puts into it (Kendall 1954; Burg's estimate has it too): with n readings,
/// E[rho_hat] = rho - (1 + 3 rho) / n, so rho_hat + (1 + 3 rho_hat) / n (at most 0.995). It
/// matters near rho = 1, where the long-run variance (1 + rho) / (1 - rho) turns a small bias
/// into a large one: 250 readings at rho 0.95 give 0.933 on average, a long-run variance 26 %
/// too small, and tests of slow signatures against it too lenient. The innovation sigma, the
/// correlation time and the effective samples follow; other streams (white, AR(p >= 2), with a
/// random walk: REML's, which accounts for the mean itself) are returned as they are.
NoiseModel with_mean_bias_corrected(const NoiseModel& model);

/// `model` with stream s taken as AR(1) with lag-1 coefficient phi[s] (|phi| < 1; its marginal
/// sigma kept, its innovation sigma, correlation time and effective samples following), e.g. a
/// coefficient at the bound of its confidence interval. Throws InvalidArgument if phi does not
/// hold one value per stream or a stream has a random walk.
NoiseModel with_lag1(const NoiseModel& model, const std::vector<double>& phi);

/// Autocovariance gamma_0..gamma_{n-1} (mm^2) of a stream's AR part, from its marginal
/// variance and reflection coefficients (gamma_m = k_m v_{m-1} + sum_j phi_{m-1,j} gamma_{m-j}
/// up to the order, then the AR recursion).
std::vector<double> ar_autocovariance(const NoiseStream& stream, std::size_t n);

/// The covariance (mm^2) of one stream's readings in its time order: AR autocovariance plus
/// the random walk's q^2 min(i, j).
Eigen::MatrixXd stream_covariance(const NoiseStream& stream);

/// Whitening of one AR(1) + random-walk stream in O(n): the innovations of the two-state
/// Kalman filter (a_t = rho a_{t-1} + e_t started stationary with variance `marginal_var`;
/// w_t = w_{t-1} + eta_t, Var eta = `step_var`, w_0 = 0; reading a_t + w_t, no further noise),
/// each divided by its sd. The innovations are the readings minus their prediction from the
/// earlier ones, so this is the inverse Cholesky factor of stream_covariance's matrix
/// sigma^2 rho^|i-j| + q^2 min(i, j), without forming it.
class ArWalkFilter {
 public:
  ArWalkFilter(std::size_t n, double marginal_var, double rho, double step_var);
  /// Replace rows `rows[0..n-1]` (the stream's readings in time order) of every column by
  /// their whitened values.
  void apply(const std::vector<Eigen::Index>& rows, Eigen::Ref<Eigen::MatrixXd> columns) const;
  double log_det() const { return log_det_; }  ///< ln |V| = sum_t ln F_t
  std::size_t size() const { return inv_sd_.size(); }

 private:
  double rho_;
  std::vector<double> gain_a_, gain_w_, inv_sd_;
  double log_det_ = 0.0;
};

/// Per stream (rows in time order) of a matrix J with rows j_t: S = sum_t j_t j_t^T,
/// U = sum_{t>=1} j_t j_{t-1}^T, and the first and last rows' outer products F and L. Under
/// AR(1) with coefficient phi, start-up scale a and innovation scale b (ArWhitener), the
/// whitened Gram matrix of the stream is a^2 F + b^2 ((1 + phi^2) S - F - phi^2 L - phi (U + U^T)).
struct StreamLagProducts {
  std::vector<std::vector<Eigen::Index>> rows;
  std::vector<Eigen::MatrixXd> S, U, first, last;
  Eigen::MatrixXd rest;  ///< sum of j_t j_t^T over rows in no stream (the whitener leaves them)
  StreamLagProducts(const Eigen::MatrixXd& J, std::vector<std::vector<Eigen::Index>> stream_rows);
};

/// Prewhitening by the AR filter of each stream, with its exact start-up rows (the first p
/// readings are predicted from the orders 0..p-1 of Burg's recursion, so W is the inverse
/// Cholesky factor of the model's covariance), scaled to unit variance. A stream with a random
/// walk is whitened by ArWalkFilter when its AR order is 0 or 1, else by the inverse Cholesky
/// factor of its dense covariance (stream_covariance; O(n^3) once). Columns hold values in
/// units of `residual_unit_mm` (1: mm; pass sigma if the fit's residuals are already divided
/// by a sigma).
class ArWhitener : public ResidualWhitener {
 public:
  explicit ArWhitener(const NoiseModel& model, double residual_unit_mm = 1.0);
  void apply(Eigen::Ref<Eigen::MatrixXd> columns) const override;
  Eigen::Index size() const override { return static_cast<Eigen::Index>(n_); }

  /// Whether every stream is a plain AR filter of order 0 or 1 (no random walk): the models
  /// for which gram() and apply_inverse_covariance() hold.
  bool ar1_only() const;
  /// Replace each column c by W^T W c (the inverse covariance times c), so that the GLS inner
  /// product x^T V^-1 y is a plain one, x^T (W^T W y). Requires ar1_only().
  void apply_inverse_covariance(Eigen::Ref<Eigen::MatrixXd> columns) const;
  /// J^T W^T W J from lag products of J taken once (StreamLagProducts), in O(streams p^2):
  /// a search that scores many candidates, each with its own AR(1) model of the same streams,
  /// pays the n p^2 of the Gram matrix once. Requires ar1_only() and the same streams (rows)
  /// as the lag products; throws InvalidArgument otherwise.
  Eigen::MatrixXd gram(const StreamLagProducts& lags) const;

 private:
  struct Stream {
    std::vector<Eigen::Index> rows;
    std::vector<std::vector<double>> phi;  ///< phi[m]: coefficients of order m = 0..p
    std::vector<double> inv_sd;            ///< 1 / sqrt(v_m) in column units
    Eigen::MatrixXd chol;  ///< random walk, AR order >= 2: lower Cholesky factor, column units
    std::vector<ArWalkFilter> walk;  ///< random walk, AR order 0 or 1 (one filter or none)
  };
  std::vector<Stream> streams_;
  std::size_t n_ = 0;
};

/// Coloured noise for tests and benches, added per stream (group, channel) in time order, all
/// seeded. Sizes in mm.
namespace noise_gen {

/// Stationary AR(1) with correlation rho per sample and marginal sigma.
Eigen::VectorXd ar1(const std::vector<std::string>& groups, const std::vector<double>& times,
                    double rho, double sigma_mm, std::uint64_t seed);
/// 1/f-like noise: equal-variance AR(1) processes with correlation times 1, 10, 100, 1000
/// samples summed (a flat spectrum per decade of frequency over three decades), scaled to
/// marginal sigma.
Eigen::VectorXd pink(const std::vector<std::string>& groups, const std::vector<double>& times,
                     double sigma_mm, std::uint64_t seed);
/// Slow thermal wander common to all readings: a sum of three sines with random phases and
/// periods between period_s and 3 period_s, RMS amplitude_mm over a long record.
Eigen::VectorXd thermal_wander(const std::vector<double>& times, double amplitude_mm,
                               double period_s, std::uint64_t seed);
/// R-test probe zeros wandering between poses: a random walk per stream that steps by
/// N(0, step_mm) from one reading time to the next.
Eigen::VectorXd probe_zero_wander(const std::vector<std::string>& groups,
                                  const std::vector<double>& times, double step_mm,
                                  std::uint64_t seed);

}  // namespace noise_gen

/// The streams of readings (group, channel) in time order, as the noise model splits them.
std::vector<std::vector<Eigen::Index>> noise_streams(
    const std::vector<std::string>& groups, const std::vector<double>& times,
    std::vector<std::string>* stream_group = nullptr, std::vector<int>* stream_channel = nullptr);

}  // namespace rotacal
