// Eigen decompositions compiled once for the library (eigen_instances.cpp) instead of in every
// file that uses them. Included into every library file through the precompiled header
// (cmake/RotacalPrecompile.cmake), so no source includes it by name.
//
// JacobiSVD<MatrixXd>: its compute() and the QR preconditioner behind it took 6-7 s of compiler
// CPU at -O3 in each of the 11 files that use it; with this declaration a file that uses it
// compiles in about 1 s (README, "Build time"). Only class templates whose heavy members are
// not themselves templates gain from this: SelfAdjointEigenSolver's and LDLT's compute() are
// member templates, which an explicit instantiation declaration does not cover.
#pragma once

#include <Eigen/SVD>

extern template class Eigen::JacobiSVD<Eigen::MatrixXd>;
