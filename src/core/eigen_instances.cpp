// SPDX-License-Identifier: BSD-3-Clause
// The one instantiation of the Eigen decompositions declared extern in eigen_instances.hpp.
#include "eigen_instances.hpp"

template class Eigen::JacobiSVD<Eigen::MatrixXd>;
template class Eigen::ColPivHouseholderQR<Eigen::MatrixXd>;
template class Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>;
template Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>& Eigen::SelfAdjointEigenSolver<
    Eigen::MatrixXd>::compute<Eigen::MatrixXd>(const Eigen::EigenBase<Eigen::MatrixXd>&, int);
#ifdef ROTACAL_EIGEN_KERNELS
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wignored-attributes"
ROTACAL_EIGEN_KERNELS()
#pragma GCC diagnostic pop
#endif
