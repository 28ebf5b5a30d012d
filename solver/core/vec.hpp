// Small fixed-size vectors and the dimension-generic index type.
//
// Everything that is written once for 2D and 3D takes `int D` and uses Vec<D> for
// physical or lattice coordinates and Index<D> for grid indices.
#pragma once

#include <Eigen/Core>
#include <array>

namespace caplab {

template <int D>
using Vec = Eigen::Matrix<double, D, 1>;

template <int D>
using Index = std::array<int, D>;

}  // namespace caplab
