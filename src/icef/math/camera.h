// Pinhole cameras in the NeRF/OpenGL convention: the camera looks down its -Z axis, +Y is up and
// +X is right. Pixel (i, j) (column i, row j, row 0 at the top) has its centre at image
// coordinates (i + 0.5, j + 0.5). `world_from_cam` is the dataset's `transform_matrix`
// (camera-to-world) and is always a rigid transform (rotation with determinant +1).
//
// Focal lengths are signed, as in NerFace: the camera-frame direction through image coordinates
// (u, v) is ((u - cx) / fl_x, -(v - cy) / fl_y, -1) whatever the signs, so a negative focal length
// flips that image axis. Two negative focal lengths are an ordinary camera turned 180 degrees about
// its viewing axis (Camera::Upright makes them positive); exactly one negative focal length is a
// mirrored camera, which no rigid pose with positive focal lengths can express, so it is kept in
// the intrinsics rather than as a reflection in `world_from_cam`. RayThrough and Project are exact
// inverses for either sign.
#pragma once

#include <optional>
#include <string>

#include "icef/core/status.h"
#include "icef/math/ray.h"
#include "icef/math/types.h"

namespace icef {

struct Intrinsics {
  int width = 0;
  int height = 0;
  double fl_x = 0;  // focal length in pixels; nonzero, negative flips the image's x axis (see above)
  double fl_y = 0;  // likewise for the y axis
  double cx = 0;    // principal point in image coordinates (pixels)
  double cy = 0;

  // instant-ngp / NeRF style: fl_x = 0.5 * width / tan(0.5 * camera_angle_x); principal point at
  // the image centre; fl_y = fl_x unless camera_angle_y is given.
  static Intrinsics FromCameraAngle(int width, int height, double camera_angle_x,
                                    std::optional<double> camera_angle_y = std::nullopt);
  Status Validate() const;
  std::string ToString() const;
};

// Checks that m is a finite rigid transform: last row (0,0,0,1), rotation orthonormal with
// determinant +1 within `tolerance`. The error message says what is wrong.
Status ValidateRigid(const Mat4d& m, double tolerance = 1e-3);

class Camera {
 public:
  Camera() = default;
  Camera(const Intrinsics& intrinsics, const Mat4d& world_from_cam);

  // The camera that casts the same rays as (intrinsics, world_from_cam) with fl_y > 0: when fl_y
  // is negative, both focal lengths change sign and the frame turns 180 degrees about its viewing
  // axis (world_from_cam * diag(-1, -1, 1, 1)); the principal point stays. Every ray and
  // projection is unchanged (bit for bit: only signs flip), and camera +Y is image-up again. What
  // remains negative afterwards is fl_x alone, exactly when the camera is mirrored.
  static Camera Upright(const Intrinsics& intrinsics, const Mat4d& world_from_cam);

  const Intrinsics& intrinsics() const { return intrinsics_; }
  const Mat4d& world_from_cam() const { return world_from_cam_; }
  Mat4d cam_from_world() const;
  Vec3d Center() const { return world_from_cam_.block<3, 1>(0, 3); }
  int width() const { return intrinsics_.width; }
  int height() const { return intrinsics_.height; }

  // The world-frame ray through image coordinates (u, v) (pixel centres at +0.5).
  Ray RayThrough(double u, double v) const;
  // The ray through the centre of pixel (column i, row j).
  Ray PixelRay(int i, int j) const { return RayThrough(i + 0.5, j + 0.5); }
  // Image coordinates (u, v) of a world point and its depth along the viewing axis (> 0 in front
  // of the camera); nullopt for points at or behind the camera plane.
  struct Projection {
    Vec2d uv;
    double depth;
  };
  std::optional<Projection> Project(const Vec3d& world_point) const;

  // A camera at `eye` looking at `target` with the given world up vector.
  static Camera LookAt(const Intrinsics& intrinsics, const Vec3d& eye, const Vec3d& target,
                       const Vec3d& up = Vec3d::UnitY());

  std::string ToString() const;

 private:
  Intrinsics intrinsics_;
  Mat4d world_from_cam_ = Mat4d::Identity();
  Mat3d cam_from_world_rotation_ = Mat3d::Identity();
};

}  // namespace icef
