// Basic numeric types shared by every module: SI units everywhere outside the LBM kernels.
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

namespace ff {
using Real = double;
using Vec3 = Eigen::Matrix<Real, 3, 1>;
using Mat3 = Eigen::Matrix<Real, 3, 3>;
using Quat = Eigen::Quaternion<Real>;
using Index = std::int32_t;  // particle / bond / cell index (2^31 is ample per rank)
inline constexpr Real kPi = 3.14159265358979323846;
}  // namespace ff
