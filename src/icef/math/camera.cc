#include "icef/math/camera.h"

#include <cmath>
#include <sstream>

namespace icef {

Intrinsics Intrinsics::FromCameraAngle(int width, int height, double camera_angle_x,
                                       std::optional<double> camera_angle_y) {
  Intrinsics k;
  k.width = width;
  k.height = height;
  k.fl_x = 0.5 * width / std::tan(0.5 * camera_angle_x);
  k.fl_y = camera_angle_y ? 0.5 * height / std::tan(0.5 * *camera_angle_y) : k.fl_x;
  k.cx = 0.5 * width;
  k.cy = 0.5 * height;
  return k;
}

Status Intrinsics::Validate() const {
  if (width <= 0 || height <= 0) return Status::Error("image size must be positive");
  if (!(std::isfinite(fl_x) && fl_x != 0)) return Status::Error("fl_x must be a nonzero finite number");
  if (!(std::isfinite(fl_y) && fl_y != 0)) return Status::Error("fl_y must be a nonzero finite number");
  if (!std::isfinite(cx) || !std::isfinite(cy)) return Status::Error("cx/cy must be finite");
  return Status::Ok();
}

std::string Intrinsics::ToString() const {
  std::ostringstream os;
  os << "Intrinsics(w=" << width << ", h=" << height << ", fl_x=" << fl_x << ", fl_y=" << fl_y
     << ", cx=" << cx << ", cy=" << cy << ")";
  return os.str();
}

Status ValidateRigid(const Mat4d& m, double tolerance) {
  if (!m.allFinite()) return Status::Error("contains a non-finite value");
  if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > tolerance)
    return Status::Error("last row must be [0, 0, 0, 1]");
  const Mat3d r = m.block<3, 3>(0, 0);
  const double ortho = (r.transpose() * r - Mat3d::Identity()).cwiseAbs().maxCoeff();
  if (ortho > tolerance) {
    std::ostringstream os;
    os << "rotation is not orthonormal (max |R^T R - I| = " << ortho << "): not a rigid transform";
    return Status::Error(os.str());
  }
  if (r.determinant() < 0) return Status::Error("rotation has determinant -1 (a reflection)");
  return Status::Ok();
}

Camera::Camera(const Intrinsics& intrinsics, const Mat4d& world_from_cam)
    : intrinsics_(intrinsics), world_from_cam_(world_from_cam) {
  cam_from_world_rotation_ = world_from_cam_.block<3, 3>(0, 0).transpose();
}

Camera Camera::Upright(const Intrinsics& intrinsics, const Mat4d& world_from_cam) {
  if (!(intrinsics.fl_y < 0)) return Camera(intrinsics, world_from_cam);
  Intrinsics k = intrinsics;
  k.fl_x = -k.fl_x;
  k.fl_y = -k.fl_y;
  Mat4d m = world_from_cam;
  // Camera X and Y axes in the world frame; 0 - x rather than -x, so that no -0 reaches a file.
  m.block<3, 2>(0, 0) = Eigen::Matrix<double, 3, 2>::Zero() - m.block<3, 2>(0, 0);
  return Camera(k, m);
}

Mat4d Camera::cam_from_world() const {
  Mat4d m = Mat4d::Identity();
  m.block<3, 3>(0, 0) = cam_from_world_rotation_;
  m.block<3, 1>(0, 3) = -cam_from_world_rotation_ * Center();
  return m;
}

Ray Camera::RayThrough(double u, double v) const {
  const Vec3d d_cam((u - intrinsics_.cx) / intrinsics_.fl_x, -(v - intrinsics_.cy) / intrinsics_.fl_y, -1.0);
  const Vec3d d_world = (world_from_cam_.block<3, 3>(0, 0) * d_cam).normalized();
  return Ray{Center().cast<float>(), d_world.cast<float>()};
}

std::optional<Camera::Projection> Camera::Project(const Vec3d& p) const {
  const Vec3d q = cam_from_world_rotation_ * (p - Center());
  const double depth = -q.z();
  if (depth <= 1e-12) return std::nullopt;
  const double u = intrinsics_.cx + intrinsics_.fl_x * q.x() / depth;
  const double v = intrinsics_.cy - intrinsics_.fl_y * q.y() / depth;
  return Projection{Vec2d(u, v), depth};
}

Camera Camera::LookAt(const Intrinsics& intrinsics, const Vec3d& eye, const Vec3d& target, const Vec3d& up) {
  const Vec3d back = (eye - target).normalized();  // camera +Z points away from the target
  Vec3d right = up.cross(back);
  if (right.norm() < 1e-9) right = Vec3d::UnitX().cross(back);
  right.normalize();
  const Vec3d cam_up = back.cross(right);
  Mat4d m = Mat4d::Identity();
  m.block<3, 1>(0, 0) = right;
  m.block<3, 1>(0, 1) = cam_up;
  m.block<3, 1>(0, 2) = back;
  m.block<3, 1>(0, 3) = eye;
  return Camera(intrinsics, m);
}

std::string Camera::ToString() const {
  return "Camera(" + intrinsics_.ToString() + ", world_from_cam=" + icef::ToString(world_from_cam_) + ")";
}

}  // namespace icef
