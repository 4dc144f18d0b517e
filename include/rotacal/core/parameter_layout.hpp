// SPDX-License-Identifier: BSD-3-Clause
#pragma once
/// \file
/// Named parameter blocks of a fit: the one place where a parameter vector's layout
/// (location errors, pivot, sphere, probe or sensor zeros per nest, effect parameters,
/// radius, ...) is written down. A problem appends its blocks once; every residual, design,
/// diagnosis and export then reads a block through its handle, never through a hand-written
/// offset such as `p + 8 + 3 * nests`.
///
/// A block is a contiguous run [offset, offset + size) of the vector. Its handle
/// (ParameterBlock) views that run in an Eigen vector or matrix (`of`, `columns`) or in a
/// raw `const T*` (`ptr`), so the same handle serves the doubles of a fit and the Jets of a
/// templated residual. Blocks made of equal items (3 probe-zero components per nest) hand
/// out one item with `item(k)`.
///
/// Light on purpose (Eigen/Core and core/error.hpp only): it is included by every problem.

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "rotacal/core/error.hpp"

namespace rotacal {

/// One block of a parameter vector: where it lies, and what its parameters are called.
struct ParameterBlock {
  std::string name;                ///< block name ("location_errors", "pivot", ...)
  Eigen::Index offset = 0;         ///< first index in the parameter vector
  Eigen::Index size = 0;           ///< number of parameters (0: the block is absent)
  Eigen::Index item_size = 1;      ///< parameters per item (3 for zeros per nest)
  std::vector<std::string> names;  ///< parameter names, `size` of them
  std::vector<std::string> units;  ///< their units ("mm", "rad", "1", ...), `size` of them

  bool empty() const { return size == 0; }
  /// One past the block's last index.
  Eigen::Index end() const { return offset + size; }
  /// Number of items (size / item_size).
  Eigen::Index items() const { return item_size > 0 ? size / item_size : 0; }
  /// Whether vector index j lies in this block.
  bool contains(Eigen::Index j) const { return j >= offset && j < end(); }

  /// The block's first element in a raw parameter array (doubles or Jets): nullptr when the
  /// block is empty, so that a model without effects passes no effect parameters.
  template <typename T>
  const T* ptr(const T* p) const {
    return size > 0 ? p + offset : nullptr;
  }
  template <typename T>
  T* ptr(T* p) const {
    return size > 0 ? p + offset : nullptr;
  }

  /// The block's segment of a parameter vector (read or write).
  template <typename Derived>
  auto of(Eigen::MatrixBase<Derived>& x) const {
    return x.segment(offset, size);
  }
  template <typename Derived>
  auto of(const Eigen::MatrixBase<Derived>& x) const {
    return x.segment(offset, size);
  }
  /// The same as a fixed-size segment (N must be the block's size).
  template <int N, typename Derived>
  auto of(const Eigen::MatrixBase<Derived>& x) const {
    check_size(N);
    return x.template segment<N>(offset);
  }
  template <int N, typename Derived>
  auto of(Eigen::MatrixBase<Derived>& x) const {
    check_size(N);
    return x.template segment<N>(offset);
  }

  /// The block's columns of a Jacobian (rows: residuals, columns: this vector's parameters).
  template <typename Derived>
  auto columns(Eigen::MatrixBase<Derived>& J) const {
    return J.middleCols(offset, size);
  }
  template <typename Derived>
  auto columns(const Eigen::MatrixBase<Derived>& J) const {
    return J.middleCols(offset, size);
  }

  /// Item k (0-based) of a block of equal items, itself a block (name "<name>[k]"). Throws
  /// InvalidArgument when k is out of range.
  ParameterBlock item(Eigen::Index k) const {
    if (k < 0 || k >= items())
      throw InvalidArgument("parameter block " + name + ": item " + std::to_string(k) + " of " +
                            std::to_string(items()));
    ParameterBlock b;
    b.name = name + "[" + std::to_string(k) + "]";
    b.offset = offset + k * item_size;
    b.size = item_size;
    b.item_size = item_size;
    const auto first = static_cast<std::size_t>(k * item_size);
    b.names.assign(
        names.begin() + static_cast<std::ptrdiff_t>(first),
        names.begin() + static_cast<std::ptrdiff_t>(first + static_cast<std::size_t>(item_size)));
    b.units.assign(
        units.begin() + static_cast<std::ptrdiff_t>(first),
        units.begin() + static_cast<std::ptrdiff_t>(first + static_cast<std::size_t>(item_size)));
    return b;
  }
  /// Parameters [first, first + count) of this block (first counted from the block's start) as
  /// a block of its own called `part_name`, e.g. one effect's parameters within the effects.
  /// Throws InvalidArgument when they are not inside the block.
  ParameterBlock part(Eigen::Index first, Eigen::Index count, const std::string& part_name) const {
    if (first < 0 || count < 0 || first + count > size)
      throw InvalidArgument("parameter block " + name + ": parameters " + std::to_string(first) +
                            ".." + std::to_string(first + count) + " of " + std::to_string(size));
    ParameterBlock b;
    b.name = part_name;
    b.offset = offset + first;
    b.size = count;
    const auto f = names.begin() + static_cast<std::ptrdiff_t>(first);
    b.names.assign(f, f + static_cast<std::ptrdiff_t>(count));
    const auto u = units.begin() + static_cast<std::ptrdiff_t>(first);
    b.units.assign(u, u + static_cast<std::ptrdiff_t>(count));
    return b;
  }
  /// Offset of item k without building the block (hot loops).
  Eigen::Index item_offset(Eigen::Index k) const { return offset + k * item_size; }

 private:
  void check_size(int n) const {
    if (n != size)
      throw InvalidArgument("parameter block " + name + " has " + std::to_string(size) +
                            " parameters, not " + std::to_string(n));
  }
};

/// The blocks of a parameter vector, in vector order.
class ParameterLayout {
 public:
  /// Append block `name` of size names.size(), each parameter with its unit (units: one per
  /// name, or a single unit for all). `item_size` (> 0, dividing the size) groups the block in
  /// equal items. Returns a copy of the new block's handle (it stays valid: the layout only
  /// grows at its end). Throws InvalidArgument for a repeated block
  /// name, a units list of another length, or an item size that does not divide the size.
  ParameterBlock add(const std::string& name, std::vector<std::string> names,
                     std::vector<std::string> units, Eigen::Index item_size = 1) {
    for (const ParameterBlock& b : blocks_)
      if (b.name == name) throw InvalidArgument("parameter layout: block " + name + " added twice");
    const Eigen::Index n = static_cast<Eigen::Index>(names.size());
    if (units.size() == 1 && n != 1) units.assign(names.size(), units.front());
    if (static_cast<Eigen::Index>(units.size()) != n)
      throw InvalidArgument("parameter layout: block " + name + " has " + std::to_string(n) +
                            " names but " + std::to_string(units.size()) + " units");
    if (item_size <= 0 || n % item_size != 0)
      throw InvalidArgument("parameter layout: block " + name + " of " + std::to_string(n) +
                            " parameters cannot hold items of " + std::to_string(item_size));
    ParameterBlock b;
    b.name = name;
    b.offset = size_;
    b.size = n;
    b.item_size = item_size;
    b.names = std::move(names);
    b.units = std::move(units);
    size_ += n;
    blocks_.push_back(std::move(b));
    return blocks_.back();
  }
  /// A block of `size` parameters named "<name>[k]", all in `unit`.
  ParameterBlock add(const std::string& name, Eigen::Index size, const std::string& unit) {
    if (size < 0) throw InvalidArgument("parameter layout: block " + name + " of negative size");
    std::vector<std::string> names;
    for (Eigen::Index k = 0; k < size; ++k) names.push_back(name + "[" + std::to_string(k) + "]");
    return add(name, std::move(names),
               std::vector<std::string>(static_cast<std::size_t>(size), unit));
  }

  /// Total number of parameters.
  Eigen::Index size() const { return size_; }
  const std::vector<ParameterBlock>& blocks() const { return blocks_; }
  bool has(const std::string& name) const {
    for (const ParameterBlock& b : blocks_)
      if (b.name == name) return true;
    return false;
  }
  /// The block called `name`; throws InvalidArgument naming it when there is none.
  const ParameterBlock& block(const std::string& name) const {
    for (const ParameterBlock& b : blocks_)
      if (b.name == name) return b;
    throw InvalidArgument("parameter layout: no block named " + name);
  }
  /// The block holding vector index j; throws InvalidArgument when j is outside the vector.
  const ParameterBlock& block_of(Eigen::Index j) const {
    for (const ParameterBlock& b : blocks_)
      if (b.contains(j)) return b;
    throw InvalidArgument("parameter layout: index " + std::to_string(j) + " outside the " +
                          std::to_string(size_) + " parameters");
  }
  /// Every parameter's name, in vector order.
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const ParameterBlock& b : blocks_) out.insert(out.end(), b.names.begin(), b.names.end());
    return out;
  }
  /// Every parameter's unit, in vector order.
  std::vector<std::string> units() const {
    std::vector<std::string> out;
    for (const ParameterBlock& b : blocks_) out.insert(out.end(), b.units.begin(), b.units.end());
    return out;
  }

 private:
  std::vector<ParameterBlock> blocks_;
  Eigen::Index size_ = 0;
};

}  // namespace rotacal
