// Small fixed-size vector/matrix aliases (Eigen). Float is the storage type of fields and
// renderers; double is used for cameras, geometry set-up and gradient checks.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

namespace icef {

using Vec2f = Eigen::Vector2f;
using Vec3f = Eigen::Vector3f;
using Vec4f = Eigen::Vector4f;
using Vec2d = Eigen::Vector2d;
using Vec3d = Eigen::Vector3d;
using Vec4d = Eigen::Vector4d;
using Vec2i = Eigen::Vector2i;
using Vec3i = Eigen::Vector3i;
using Mat3f = Eigen::Matrix3f;
using Mat3d = Eigen::Matrix3d;
using Mat4d = Eigen::Matrix4d;
using Mat4f = Eigen::Matrix4f;
using VecXf = Eigen::VectorXf;
using VecXd = Eigen::VectorXd;

// "[x, y, z]" with 6 significant digits.
std::string ToString(const Eigen::MatrixXd& m);

}  // namespace icef
