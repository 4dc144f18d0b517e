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
extern template Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>&
Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>::compute<Eigen::MatrixXd>(const Eigen::EigenBase<Eigen::MatrixXd>&,
                                                                         int);
