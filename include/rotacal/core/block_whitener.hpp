// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// A block-diagonal ResidualWhitener: the residuals of a stacked fit (core/joint_fit.hpp) lie
/// in consecutive row ranges, one per independent data set (one per session of a
/// multi-instrument fit), and each range is whitened by its own noise model. Each block is a
/// ResidualWhitener over its own rows (null: none) followed by a constant factor, so a white
/// block is factor = 1 / sigma and a coloured one an ArWhitener with factor 1 / bias scale
/// (core/fit_with_noise.hpp), which inflates that block's share of the covariance by the scale.

#include <memory>
#include <vector>

#include "rotacal/core/whitener.hpp"

namespace rotacal {

class BlockDiagonalWhitener : public ResidualWhitener {
 public:
  struct Block {
    Eigen::Index rows = 0;                             ///< residuals of this block
    std::shared_ptr<const ResidualWhitener> whitener;  ///< null: identity
    double factor = 1.0;                               ///< applied after the whitener
  };
  /// Blocks in row order. Throws InvalidArgument for a whitener whose size is not its block's
  /// rows, or a factor that is not finite and positive.
  explicit BlockDiagonalWhitener(std::vector<Block> blocks);
  void apply(Eigen::Ref<Eigen::MatrixXd> columns) const override;
  Eigen::Index size() const override { return n_; }

 private:
  std::vector<Block> blocks_;
  Eigen::Index n_ = 0;
};

}  // namespace rotacal
