// The one instantiation of the Eigen decompositions declared extern in eigen_instances.hpp.
#include "eigen_instances.hpp"

template class Eigen::JacobiSVD<Eigen::MatrixXd>;
