// Basic numeric types shared by every part of backbone.
//
// Everything numerical is an Eigen dense vector or matrix of doubles; the aliases keep the
// signatures short and make the layout choice explicit in one place.
//
//   backbone::core::Vector x(3);
//   backbone::core::Matrix J = backbone::core::Matrix::Zero(2, 3);
#pragma once

#include <Eigen/Dense>

namespace backbone::core {

using Vector = Eigen::VectorXd;
using Matrix = Eigen::MatrixXd;

}  // namespace backbone::core
