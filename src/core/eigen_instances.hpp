// SPDX-License-Identifier: BSD-3-Clause
// Eigen decompositions compiled once for the library (eigen_instances.cpp) instead of in every
// file that uses them. Included into every library file through the precompiled header
// (cmake/RotacalPrecompile.cmake), so no source includes it by name.
//
// Compiler CPU at -O3 of a file that only builds one decomposition of a MatrixXd, without and
// with these declarations: JacobiSVD 7.5 -> 1.1 s (11 library files use it),
// SelfAdjointEigenSolver from a MatrixXd 6.3 -> 1.0 s, ColPivHouseholderQR 5.3 -> 4.1 s (its
// solve() is a member template, compiled where it is called). An explicit instantiation covers
// a class's members but not its member templates: SelfAdjointEigenSolver's compute() is one and
// is named for the MatrixXd argument; a solver built from an expression (A * B) still compiles it
// in that file, as do LDLT and LLT, whose work lies in member templates.
#pragma once

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>

extern template class Eigen::JacobiSVD<Eigen::MatrixXd>;
extern template class Eigen::ColPivHouseholderQR<Eigen::MatrixXd>;
extern template class Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>;
extern template Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>& Eigen::SelfAdjointEigenSolver<
    Eigen::MatrixXd>::compute<Eigen::MatrixXd>(const Eigen::EigenBase<Eigen::MatrixXd>&, int);

// The dense product and triangular-solve kernels of double matrices (GEMM's block-panel kernel
// and packing, GEMV, triangular products and solves), compiled once in eigen_instances.cpp
// instead of in every library batch and test file that multiplies a MatrixXd: up to 19 of the
// sanitizer build's 103 object files held a copy of each (nm), and in test_diagnose_scoring they
// were a quarter of the optimiser's time (-ftime-trace). Only members Eigen defines out of line
// (EIGEN_DONT_INLINE) are covered, so nothing that was inlined stops being inlined: the code that
// runs is the same. The template arguments are those of SSE2 (x86-64's baseline, the only vector
// unit these builds enable); with AVX the kernels take other arguments and both sides leave the
// list out. A mode is Eigen's bits: 1 Lower, 2 Upper, 4 UnitDiag; an order 0 ColMajor, 1 RowMajor.
#if defined(EIGEN_VECTORIZE_SSE2) && !defined(EIGEN_VECTORIZE_AVX)
#define ROTACAL_EIGEN_KERNELS(EXTERN)                                                         \
  EXTERN template struct Eigen::internal::gebp_kernel<                                        \
      double, double, Eigen::Index,                                                           \
      Eigen::internal::blas_data_mapper<double, Eigen::Index, 0, 0, 1>, 4, 4, false, false>;  \
  ROTACAL_EIGEN_PACK_LHS(EXTERN, (const_blas_data_mapper<double, Eigen::Index, 0>), 0, false) \
  ROTACAL_EIGEN_PACK_LHS(EXTERN, (const_blas_data_mapper<double, Eigen::Index, 1>), 1, false) \
  ROTACAL_EIGEN_PACK_LHS(EXTERN, (blas_data_mapper<double, Eigen::Index, 0, 0, 1>), 0, true)  \
  ROTACAL_EIGEN_PACK_RHS(EXTERN, (const_blas_data_mapper<double, Eigen::Index, 0>), 0, false) \
  ROTACAL_EIGEN_PACK_RHS(EXTERN, (const_blas_data_mapper<double, Eigen::Index, 1>), 1, false) \
  ROTACAL_EIGEN_PACK_RHS(EXTERN, (const_blas_data_mapper<double, Eigen::Index, 1>), 1, true)  \
  ROTACAL_EIGEN_PACK_RHS(EXTERN, (blas_data_mapper<double, Eigen::Index, 0, 0, 1>), 0, true)  \
  ROTACAL_EIGEN_GEMV(EXTERN, 1, 0, 0)                                                         \
  ROTACAL_EIGEN_GEMV(EXTERN, 0, 1, 0)                                                         \
  ROTACAL_EIGEN_GEMV(EXTERN, 0, 0, 0)                                                         \
  ROTACAL_EIGEN_GEMV(EXTERN, 1, 1, 1)                                                         \
  EXTERN template struct Eigen::internal::triangular_matrix_vector_product<                   \
      Eigen::Index, 6, double, false, double, false, 1, 0>;                                   \
  ROTACAL_EIGEN_TRMM(EXTERN, 6, 1)                                                            \
  ROTACAL_EIGEN_TRMM(EXTERN, 5, 0)                                                            \
  ROTACAL_EIGEN_TRMM(EXTERN, 2, 1)                                                            \
  ROTACAL_EIGEN_TRMM(EXTERN, 1, 0)                                                            \
  ROTACAL_EIGEN_TRSM(EXTERN, 1, 5, 0)                                                         \
  ROTACAL_EIGEN_TRSM(EXTERN, 2, 2, 1)                                                         \
  ROTACAL_EIGEN_TRSM(EXTERN, 1, 6, 1)                                                         \
  ROTACAL_EIGEN_TRSM(EXTERN, 1, 2, 0)                                                         \
  ROTACAL_EIGEN_TRSM(EXTERN, 1, 1, 0)

#define ROTACAL_EIGEN_UNPAREN(...) __VA_ARGS__
// Packing of GEMM's left operand from a mapper of the given storage order (panel mode last).
#define ROTACAL_EIGEN_PACK_LHS(EXTERN, MAPPER, ORDER, PANEL)                     \
  EXTERN template struct Eigen::internal::gemm_pack_lhs<                         \
      double, Eigen::Index, Eigen::internal::ROTACAL_EIGEN_UNPAREN MAPPER, 4, 2, \
      Eigen::internal::Packet2d, ORDER, false, PANEL>;
// Packing of GEMM's right operand.
#define ROTACAL_EIGEN_PACK_RHS(EXTERN, MAPPER, ORDER, PANEL)                                \
  EXTERN template struct Eigen::internal::gemm_pack_rhs<                                    \
      double, Eigen::Index, Eigen::internal::ROTACAL_EIGEN_UNPAREN MAPPER, 4, ORDER, false, \
      PANEL>;
// Matrix times vector: the matrix's storage order, the vector mapper's, the kernel's version.
#define ROTACAL_EIGEN_GEMV(EXTERN, LHS_ORDER, RHS_ORDER, VERSION)                                 \
  EXTERN template struct Eigen::internal::general_matrix_vector_product<                          \
      Eigen::Index, double,                                                                       \
      Eigen::internal::const_blas_data_mapper<double, Eigen::Index, LHS_ORDER>, LHS_ORDER, false, \
      double, Eigen::internal::const_blas_data_mapper<double, Eigen::Index, RHS_ORDER>, false,    \
      VERSION>;
// Triangular (mode) times general matrix, the triangle on the left, of the given storage order.
#define ROTACAL_EIGEN_TRMM(EXTERN, MODE, LHS_ORDER)                         \
  EXTERN template struct Eigen::internal::product_triangular_matrix_matrix< \
      double, Eigen::Index, MODE, true, LHS_ORDER, false, 0, false, 0, 1, 0>;
// Triangular solve with many right-hand sides: side, mode, the triangle's storage order.
#define ROTACAL_EIGEN_TRSM(EXTERN, SIDE, MODE, TRI_ORDER)                                     \
  EXTERN template struct Eigen::internal::triangular_solve_matrix<double, Eigen::Index, SIDE, \
                                                                  MODE, false, TRI_ORDER, 0, 1>;

// Eigen names the packet type in these arguments too; GCC notes that its alignment attribute does
// not take part in the type.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wignored-attributes"
ROTACAL_EIGEN_KERNELS(extern)
#pragma GCC diagnostic pop
#endif
