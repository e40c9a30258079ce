// The volumetric prior warp of ICT-FaceKit (IctModel): P(x, beta) moves a point x observed on or
// near the subject's head at expression beta to its canonical point, where it would be on the same
// head (same identity) at rest (beta = 0). A NeRF's deformation prior (DeformationPrior) is
// P(x, beta) - x.
//
// Frames and units: x and P(x) are in the model's head frame, in centimetres (+y up, the face looks
// down +z; ict_model.h). The head frame is the rigid frame of the head, so far from the surface
// the warp is the identity.
//
// The warp, for the posed mesh M = mesh(identity, beta) and the neutral N = mesh(identity, 0):
//   - p = the closest point of x on M (exact: a KD-tree over points on M's triangles prunes, and the
//     exact point-triangle distance decides), on triangle t with barycentric coordinates b;
//     d = |x - p|;
//   - mapped = p' + R(p) (x - p), with p' the point b of triangle t on N and R(p) a rotation that
//     varies continuously over the surface: each triangle's rotation from M to N (its face normal
//     onto N's, and in its plane the rotation part of its affine map), averaged at the vertices
//     (area-weighted quaternions) and blended over a triangle by b. Where M moves rigidly near p,
//     mapped is that rigid motion of x; where p lies inside t, x - p = s d n_M (s = +-1) and mapped
//     is p' + s d R(p) n_M, the same barycentric point and signed distance along (nearly) N's normal;
//   - P(x) = x + w(d) (mapped - x): w = 1 for d <= inner_radius, a smoothstep down to 0 at
//     outer_radius, 0 beyond (the rigid head frame).
// On the surface (d = 0) P is exact: a vertex of M maps to the same vertex of N. P is continuous
// wherever the closest point is: it jumps only across the medial axis (between the lips, between two
// shells such as the teeth and the lips; near a concave crease by d times the change of R there).
//
// The surface: the parts of the model that a camera sees and that expressions move or that bound
// what they move: face, head_neck, mouth_socket, gums_tongue, teeth, the eye sockets (one connected
// surface with the face) and the eyeballs (sclera, iris; they do not move with expressions, so the
// points on them stay put while a lid closes over them). Left out: lacrimal fluid, eye blend and
// eye occlusion meshes (thin transparent overlays of the eyes) and the eyelashes (hair cards a few
// millimetres from the lids: their closest points would pull the lids' surroundings along cards).
//
// Blinks (the lid slide): ICT's eyeBlink deltas are made on the mean face and do not close every
// identity's lids (an identity with a larger or more prominent eye keeps part of its eyeball
// uncovered; so may one fitted to a real subject). So the posed mesh M leaves eyeBlink_L/_R out, and
// a blink is a slide of the space over each eyeball before the closest-point warp, measured on the
// identity's own eye. Per eye: the eyeball's sphere (centre and median radius of the sclera) and its
// rest opening, by column u = q.x / radius (q = x - centre, in IctEye::kColumns columns): the lowest and
// highest elevation theta = atan2(q.y, q.z) of the sphere's points seen from the front past the skin
// (any surface part other than the eyeballs) within 3 cm in front (+z). That opening is grown by a
// margin m = min(0.15 rad, its height) above and below (a real subject's eye, which the fitted
// identity's lids only approximate, reaches past it): upper += m, lower -= m. At blink weight c
// (clamped to 0..1) the upper lid's margin comes down to edge = upper - c (upper - lower), and a
// point over the eyeball at elevation theta in [edge, pi/2] is rotated about the x axis through the
// centre to
//   upper + (theta - edge) (pi/2 - upper) / (pi/2 - edge),
// where the open lid is (the span the closing lid covers, mapped onto the open lid's), in full
// within [-0.3, 0.4] cm of the sphere, fading out by -0.6 and 0.9 cm. At c = 1 the opening is
// covered from top to bottom, whatever the identity. The slide is continuous except at the closing
// margin (theta = edge), as the lid is.
//
// Cost: IctWarp holds the neutral for one identity (IctWarp::Create measures its eyes once, ~50 ms on
// the host below); IctWarp::Pose(beta) builds the posed mesh, the
// vertex rotations and a KD-tree over ~117k surface points once per expression (a training step with
// K distinct expressions builds K). Measured (IctWarp.Timing, 2-core AMD EPYC host): Pose 28 ms;
// Offsets for 100k points 4.4 us/point on one thread uniform in the head's box, 6.4 us/point 0.5 cm
// over the face, halved on two threads.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "icef/core/parallel.h"
#include "icef/core/status.h"
#include "icef/face/ict_model.h"
#include "icef/math/types.h"

namespace icef::face {

struct IctWarpOptions {
  float inner_radius = 1.f;  // cm: points at most this far from the posed surface follow it fully
  float outer_radius = 3.f;  // cm: points this far or farther do not move; smoothstep in between
  // cm: spacing of the KD-tree's points on the posed surface (a triangle gets the centroids of an
  // m x m subdivision, m = ceil(its size / spacing)). Speed only: closest points are exact for any.
  float tree_point_spacing = 0.25f;

  // How much a point this far (cm) from the posed surface follows it: 1 up to inner_radius, a
  // smoothstep down to 0 at outer_radius, 0 beyond.
  float Weight(float distance) const;

  Status Validate() const;
  std::string ToString() const;
};

// The closest point of a query on the warp's surface (posed mesh).
struct IctWarpClosest {
  int32_t triangle = -1;       // index into IctWarp::triangles(); -1: nothing within outer_radius
  Vec3f barycentric{0, 0, 0};  // of the closest point on that triangle (sums to 1)
  float distance = 0;          // cm, |x - closest point|; meaningful when triangle >= 0

  std::string ToString() const;
};

// One eye of the lid slide (above), for one identity, head frame, cm.
struct IctEye {
  static constexpr int kColumns = 32;  // columns of the rest opening across the eyeball
  int blink = -1;                      // expression index of its eyeBlink (-1: the model has none)
  Vec3f centre{0, 0, 0};
  float radius = 0;
  // Rest opening of column k (u = -1 + (k + 0.5) 2 / kColumns): the lowest and the highest uncovered
  // elevation (rad); equal (no opening) where no direction of the column is uncovered.
  std::array<float, kColumns> lower{}, upper{};

  // The opening at column u (-1..1), interpolated between column centres: {lower, upper}.
  std::pair<float, float> Opening(float u) const;
  // x slid from a lid closed to weight `blink` (0..1) back to the open lid's place; x elsewhere.
  Vec3f Slide(const Vec3f& x, float blink) const;
};

class PosedIctWarp;

// The warp for one identity; Pose() specialises it to one expression. Holds a pointer to the
// model: the model must outlive the warp and every PosedIctWarp made from it.
class IctWarp {
 public:
  // identity: <= model.num_identities() coefficients (missing ones 0). Fails on invalid options or
  // a model without the parts named above.
  static Result<IctWarp> Create(const IctModel& model, std::span<const float> identity,
                                const IctWarpOptions& options = {});

  // expression: <= model.num_expressions() finite weights (missing ones 0). Builds the posed mesh
  // and its KD-tree. The result points to this warp: keep the warp alive and in place (not moved)
  // while the result is used.
  PosedIctWarp Pose(std::span<const float> expression) const;

  const IctModel& model() const { return *model_; }
  const IctWarpOptions& options() const { return options_; }
  // The neutral of this identity (beta = 0): [num_vertices], head frame, cm.
  const std::vector<Vec3f>& neutral() const { return neutral_; }
  // The warp's surface: the model's triangles (vertex indices) whose three vertices lie on the parts
  // named above, in model order.
  const std::vector<std::array<uint32_t, 3>>& triangles() const { return triangles_; }
  // The lid slide's eyes: the subject's left (+x, eyeBlink_L) and right.
  const std::array<IctEye, 2>& eyes() const { return eyes_; }
  // Area-weighted vertex normals of that surface on `mesh` (a mesh of the model: the neutral or a
  // posed one), normalised: [mesh.size()], 0 at vertices off the surface.
  std::vector<Vec3f> VertexNormals(const std::vector<Vec3f>& mesh) const;
  std::string ToString() const;

 private:
  friend class PosedIctWarp;
  IctWarp() = default;

  const IctModel* model_ = nullptr;
  IctWarpOptions options_;
  std::vector<Vec3f> neutral_;
  std::vector<std::array<uint32_t, 3>> triangles_;
  std::array<IctEye, 2> eyes_;
};

// The warp at one expression: the posed mesh, its KD-tree, and the batched warp.
class PosedIctWarp {
 public:
  PosedIctWarp(PosedIctWarp&&) noexcept;
  PosedIctWarp& operator=(PosedIctWarp&&) noexcept;
  ~PosedIctWarp();

  // positions [n, 3] head frame cm (observed, at this expression) -> offsets [n, 3] cm: P(x) - x
  // (the lid slide, then the closest-point warp).
  // Parallel over points; each output depends on its point alone (the same for any thread count).
  void Offsets(const Executor& executor, int64_t n, const float* positions, float* offsets) const;
  // P(x) - x of one point.
  Vec3f Offset(const Vec3f& x) const;
  // The lid slide of x at this expression's blinks: x where neither eye blinks or x is off the
  // eyeballs. Offset(x) = LidSlide(x) - x + OffsetAt(LidSlide(x), Closest(LidSlide(x))).
  Vec3f LidSlide(const Vec3f& x) const;
  // The closest point of x on the posed surface (without the blinks), when within outer_radius.
  IctWarpClosest Closest(const Vec3f& x) const;
  // The closest-point warp's part of P(x) - x given x's closest point (Closest(x)), without the lid
  // slide; the whole of it where LidSlide(x) = x.
  Vec3f OffsetAt(const Vec3f& x, const IctWarpClosest& closest) const;

  const IctWarp& warp() const { return *warp_; }
  const std::vector<float>& expression() const { return expression_; }
  // The posed mesh M (every expression but the blinks): [num_vertices], head frame, cm.
  const std::vector<Vec3f>& posed() const { return posed_; }
  // Rotation from M to N at each vertex of the surface: [num_vertices] quaternions (x, y, z, w),
  // w >= 0; the identity off the surface.
  const std::vector<Vec4f>& vertex_rotations() const { return vertex_rotations_; }
  std::string ToString() const;

  struct Tree;  // the KD-tree (ict_warp.cc)

 private:
  friend class IctWarp;
  PosedIctWarp(const IctWarp& warp, std::span<const float> expression);

  const IctWarp* warp_;
  std::vector<float> expression_;
  std::vector<Vec3f> posed_;
  std::vector<Vec4f> vertex_rotations_;
  std::array<float, 2> blink_{};  // the eyes' blink weights, 0..1
  float max_cover_ = 0;
  std::unique_ptr<Tree> tree_;
};

}  // namespace icef::face
