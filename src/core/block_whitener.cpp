// SPDX-License-Identifier: BSD-3-Clause
// Block-diagonal whitening of stacked residuals (core/block_whitener.hpp).
#include "rotacal/core/block_whitener.hpp"

#include <cmath>
#include <string>

#include "rotacal/core/error.hpp"

namespace rotacal {

BlockDiagonalWhitener::BlockDiagonalWhitener(std::vector<Block> blocks)
    : blocks_(std::move(blocks)) {
  for (std::size_t k = 0; k < blocks_.size(); ++k) {
    const Block& b = blocks_[k];
    if (b.whitener && b.whitener->size() != b.rows)
      throw InvalidArgument("block whitener: block " + std::to_string(k) + " has " +
                            std::to_string(b.rows) + " rows but its whitener was built for " +
                            std::to_string(b.whitener->size()));
    if (!std::isfinite(b.factor) || b.factor <= 0.0)
      throw InvalidArgument("block whitener: block " + std::to_string(k) + " has factor " +
                            std::to_string(b.factor) + " (must be finite and positive)");
    n_ += b.rows;
  }
}

void BlockDiagonalWhitener::apply(Eigen::Ref<Eigen::MatrixXd> columns) const {
  ROTACAL_ASSERT(columns.rows() == n_);
  Eigen::Index row = 0;
  for (const Block& b : blocks_) {
    auto rows = columns.middleRows(row, b.rows);
    if (b.whitener) b.whitener->apply(rows);
    rows *= b.factor;
    row += b.rows;
  }
}

}  // namespace rotacal
