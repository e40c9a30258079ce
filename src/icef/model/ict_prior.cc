#include "icef/model/ict_prior.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <sstream>
#include <utility>

#include "icef/face/ict_fit.h"
#include "icef/model/lazy_grid.h"

namespace icef {

namespace {

// The landmarks FitIctHeadFromWorld aligns: the nose (27-35) and the eye corners, which expressions
// move least (the lids, brows, lips and jaw line move with them).
constexpr int kRigidLandmarks[] = {27, 28, 29, 30, 31, 32, 33, 34, 35, 36, 39, 42, 45};

// Cells of the mouth volume's 2D grid along its longer side.
constexpr int kGridCells = 32;

// cm: the mean gap between the inner lips (iBUG 61-67, 62-66, 63-65) above which the mouth is open
// (the neutral's is 0.1 cm; jawOpen = 1 parts them by 3.6 cm).
constexpr float kOpenLipGap = 0.3f;
constexpr int kInnerLipPairs[3][2] = {{61, 67}, {62, 66}, {63, 65}};
// cm: the air between parted lips is looked for within this of the inner lips' box (Cavity's kAir),
// and it is air when the warp carries it more than kAirDepth behind the surface at rest.
constexpr float kLipsReach = 1.5f;
constexpr float kAirDepth = 0.1f;

// ARKit weights are 0..1: negative and non-finite ones act as 0 (as in FacePrior).
float Sanitized(float w) { return std::isfinite(w) && w > 0.f ? w : 0.f; }

bool SameRow(const float* beta, const std::vector<float>& key) {
  for (size_t e = 0; e < key.size(); ++e)
    if (Sanitized(beta[e]) != key[e]) return false;
  return true;
}

Vec3f Interpolated(const std::vector<Vec3f>& values, const std::array<uint32_t, 3>& t, const Vec3f& b) {
  const Vec3f v = b[0] * values[t[0]] + b[1] * values[t[1]] + b[2] * values[t[2]];
  const float norm = v.norm();
  return norm > 0.f ? Vec3f(v / norm) : Vec3f::Zero();
}

// Twice the signed area of (p[a], p[b], (x, y)) projected along z, for a < b; for a > b the negated
// value for (b, a): both triangles that share an edge see bit-identical values of it.
float EdgeValue(const std::vector<Vec3f>& p, uint32_t a, uint32_t b, float x, float y) {
  if (a > b) return -EdgeValue(p, b, a, x, y);
  const Vec3f& pa = p[a];
  const Vec3f& pb = p[b];
  return (pb.x() - pa.x()) * (y - pa.y()) - (pb.y() - pa.y()) * (x - pa.x());
}

}  // namespace

// The closed surface of the mouth volume as indices: the bag (the warp's triangles with a
// mouth_socket vertex and the rest on mouth_socket or face: the socket and the lip triangles that join
// it), and a fan from an apex (the rim's mean, index vertices.size()) over each rim edge.
struct IctPrior::MouthSurface {
  std::vector<uint32_t> vertices;                     // model vertex of each local index
  std::vector<uint32_t> rim;                          // local indices of the rim's vertices
  std::vector<std::array<uint32_t, 3>> triangles;     // local indices; the apex is vertices.size()
  std::array<std::array<uint32_t, 2>, 3> inner_lips;  // model vertices of the inner lips' pairs
  int socket = -1, tongue = -1, teeth = -1;           // part indices of mouth_socket, gums_tongue, teeth
  std::vector<uint32_t> teeth_vertices;               // model vertices of the teeth

  static Result<MouthSurface> Build(const face::IctWarp& warp);
};

Result<IctPrior::MouthSurface> IctPrior::MouthSurface::Build(const face::IctWarp& warp) {
  const face::IctModel& model = warp.model();
  const int socket = model.PartIndex("mouth_socket"), face = model.PartIndex("face");
  MouthSurface surface;
  surface.socket = socket;
  surface.tongue = model.PartIndex("gums_tongue");
  surface.teeth = model.PartIndex("teeth");
  if (socket < 0 || face < 0 || surface.tongue < 0 || surface.teeth < 0)
    return Status::Error(model.path().string() +
                         ": the face model has no mouth_socket, gums_tongue, teeth or face part");
  for (uint32_t v = 0; v < model.part_labels().size(); ++v)
    if (model.part_labels()[v] == surface.teeth) surface.teeth_vertices.push_back(v);
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 2; ++j) {
      const int32_t v = model.landmark_vertices()[kInnerLipPairs[k][j]];
      if (v < 0)
        return Status::Error(model.path().string() + ": the face model has no landmark " +
                             std::to_string(kInnerLipPairs[k][j]) + " (inner lips)");
      surface.inner_lips[k][j] = static_cast<uint32_t>(v);
    }
  }
  const std::vector<uint8_t>& labels = model.part_labels();
  std::map<uint32_t, uint32_t> local;                  // model vertex -> local index
  std::map<std::pair<uint32_t, uint32_t>, int> edges;  // undirected edge -> triangle count
  for (const auto& t : warp.triangles()) {
    const auto on = [&](int part) {
      return labels[t[0]] == part || labels[t[1]] == part || labels[t[2]] == part;
    };
    const auto off = [&](uint32_t v) { return labels[v] != socket && labels[v] != face; };
    if (!on(socket) || off(t[0]) || off(t[1]) || off(t[2])) continue;
    std::array<uint32_t, 3> l;
    for (int k = 0; k < 3; ++k) {
      const auto [it, added] = local.emplace(t[k], static_cast<uint32_t>(surface.vertices.size()));
      if (added) surface.vertices.push_back(t[k]);
      l[k] = it->second;
    }
    surface.triangles.push_back(l);
    for (int k = 0; k < 3; ++k) ++edges[std::minmax(l[k], l[(k + 1) % 3])];
  }
  const auto apex = static_cast<uint32_t>(surface.vertices.size());
  std::map<uint32_t, int> rim_degree;
  const size_t bag = surface.triangles.size();
  for (size_t i = 0; i < bag; ++i) {
    const std::array<uint32_t, 3> t = surface.triangles[i];
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t[k], b = t[(k + 1) % 3];
      if (edges[std::minmax(a, b)] != 1) continue;
      surface.triangles.push_back({b, a, apex});  // the rim edge, reversed: the cap closes the bag
      ++rim_degree[a], ++rim_degree[b];
    }
  }
  for (const auto& [v, degree] : rim_degree) {
    // A closed surface (mod 2): the rim is made of loops, every edge then bounds an even count.
    if (degree % 2 != 0)
      return Status::Error(model.path().string() + ": the mouth socket's rim is not a closed loop");
    surface.rim.push_back(v);
  }
  if (surface.rim.empty() || bag < 100)
    return Status::Error(model.path().string() + ": the mouth socket is not an open bag");
  return surface;
}

namespace {

// The inside of the mouth surface on one mesh: the parity of the crossings of a +z ray, with
// triangles found through a 2D grid. Edge values are bit-identical for the two triangles that share
// an edge, and a ray through an edge goes to the triangle on the edge's positive side, so the
// count is exact for every ray that misses the vertices.
class MouthVolume {
 public:
  MouthVolume(const IctPrior::MouthSurface& surface, const std::vector<Vec3f>& mesh);
  bool Inside(const Vec3f& x) const;

 private:
  void BuildGrid();
  bool Crosses(uint32_t triangle, const Vec3f& x) const;

  const IctPrior::MouthSurface* surface_;
  std::vector<Vec3f> points_;        // the surface's vertices on the mesh, then the apex
  std::vector<int8_t> orientation_;  // per triangle: the sign of its projected area
  Vec3f lo_, hi_;                    // bounding box
  float cell_ = 1;                   // cm
  int nx_ = 1, ny_ = 1;
  std::vector<uint32_t> cell_start_;  // [nx * ny + 1] into cell_triangles_
  std::vector<uint32_t> cell_triangles_;
};

MouthVolume::MouthVolume(const IctPrior::MouthSurface& surface, const std::vector<Vec3f>& mesh)
    : surface_(&surface) {
  for (uint32_t v : surface.vertices) points_.push_back(mesh[v]);
  Vec3f apex = Vec3f::Zero();
  for (uint32_t v : surface.rim) apex += points_[v];
  points_.push_back(apex / static_cast<float>(surface.rim.size()));
  lo_ = hi_ = points_[0];
  for (const Vec3f& p : points_) lo_ = lo_.cwiseMin(p), hi_ = hi_.cwiseMax(p);
  for (const auto& t : surface.triangles) {
    const float area = EdgeValue(points_, t[0], t[1], points_[t[2]].x(), points_[t[2]].y());
    orientation_.push_back(static_cast<int8_t>(area > 0.f ? 1 : area < 0.f ? -1 : 0));
  }
  BuildGrid();
}

void MouthVolume::BuildGrid() {
  cell_ = std::max(hi_.x() - lo_.x(), hi_.y() - lo_.y()) / kGridCells + 1e-6f;
  nx_ = std::max(1, static_cast<int>(std::ceil((hi_.x() - lo_.x()) / cell_)));
  ny_ = std::max(1, static_cast<int>(std::ceil((hi_.y() - lo_.y()) / cell_)));
  const auto cell = [&](float v, float lo, int count) {
    return std::clamp(static_cast<int>((v - lo) / cell_), 0, count - 1);
  };
  std::vector<std::vector<uint32_t>> cells(static_cast<size_t>(nx_) * ny_);
  for (uint32_t i = 0; i < surface_->triangles.size(); ++i) {
    if (orientation_[i] == 0) continue;  // no area seen along z: no ray crosses it
    Vec3f a = points_[surface_->triangles[i][0]], b = a;
    for (uint32_t v : surface_->triangles[i]) a = a.cwiseMin(points_[v]), b = b.cwiseMax(points_[v]);
    for (int y = cell(a.y(), lo_.y(), ny_); y <= cell(b.y(), lo_.y(), ny_); ++y)
      for (int x = cell(a.x(), lo_.x(), nx_); x <= cell(b.x(), lo_.x(), nx_); ++x)
        cells[static_cast<size_t>(y) * nx_ + x].push_back(i);
  }
  cell_start_.assign(1, 0);
  for (const auto& c : cells) {
    cell_triangles_.insert(cell_triangles_.end(), c.begin(), c.end());
    cell_start_.push_back(static_cast<uint32_t>(cell_triangles_.size()));
  }
}

bool MouthVolume::Crosses(uint32_t triangle, const Vec3f& x) const {
  const std::array<uint32_t, 3>& t = surface_->triangles[triangle];
  const int s = orientation_[triangle];
  float w[3];  // w[k]: the edge opposite corner k, traversed in the triangle's order
  for (int k = 0; k < 3; ++k) {
    const uint32_t a = t[(k + 1) % 3], b = t[(k + 2) % 3];
    w[k] = EdgeValue(points_, a, b, x.x(), x.y());
    // The interior lies on the side s of the traversed edge; on the edge itself, the triangle takes
    // the point when its interior is on the positive side of the edge from the lower index.
    const float v = s * w[k];
    if (v < 0.f || (v == 0.f && (a < b ? s : -s) < 0)) return false;
  }
  const float sum = w[0] + w[1] + w[2];
  const float z = (w[0] * points_[t[0]].z() + w[1] * points_[t[1]].z() + w[2] * points_[t[2]].z()) / sum;
  return z > x.z();
}

bool MouthVolume::Inside(const Vec3f& x) const {
  if (!(x.array() >= lo_.array()).all() || !(x.array() <= hi_.array()).all()) return false;
  const int cx = std::min(static_cast<int>((x.x() - lo_.x()) / cell_), nx_ - 1);
  const int cy = std::min(static_cast<int>((x.y() - lo_.y()) / cell_), ny_ - 1);
  const size_t c = static_cast<size_t>(cy) * nx_ + cx;
  bool inside = false;
  for (uint32_t i = cell_start_[c]; i < cell_start_[c + 1]; ++i)
    if (Crosses(cell_triangles_[i], x)) inside = !inside;
  return inside;
}

}  // namespace

// The grid's channels: offset (cm), observed normal, canonical normal; head frame.
constexpr int kGridChannels = 9;

struct IctPrior::Expression {
  Expression(const face::IctWarp& warp, const MouthSurface& surface,
             const std::vector<Vec3f>* neutral_normals, std::span<const float> beta,
             const IctPriorOptions& options)
      : posed(warp.Pose(beta)),
        mouth(surface, posed.posed()),
        normals(warp.VertexNormals(posed.posed())),
        canonical_normals(neutral_normals != nullptr ? *neutral_normals : normals) {
    float gap = 0;
    for (const auto& [upper, lower] : surface.inner_lips)
      gap += (posed.posed()[upper] - posed.posed()[lower]).norm();
    open = gap / 3.f > kOpenLipGap;
    for (uint32_t v : surface.teeth_vertices)
      teeth_lo = teeth_lo.cwiseMin(posed.posed()[v]), teeth_hi = teeth_hi.cwiseMax(posed.posed()[v]);
    for (const auto& pair : surface.inner_lips)
      for (uint32_t v : pair)
        lips_lo = lips_lo.cwiseMin(posed.posed()[v]), lips_hi = lips_hi.cwiseMax(posed.posed()[v]);
    lips_lo -= Vec3f::Constant(kLipsReach), lips_hi += Vec3f::Constant(kLipsReach);
    if (options.grid_cell <= 0.f) return;
    // The box: the posed surface and outer_radius around it (beyond, nothing moves and no normal).
    Vec3f lo = Vec3f::Constant(INFINITY), hi = Vec3f::Constant(-INFINITY);
    for (const auto& t : warp.triangles())
      for (uint32_t v : t) lo = lo.cwiseMin(posed.posed()[v]), hi = hi.cwiseMax(posed.posed()[v]);
    const Vec3f margin = Vec3f::Constant(warp.options().outer_radius + options.grid_cell);
    LazyGrid::Options grid_options;
    grid_options.cell = options.grid_cell;
    grid_options.tolerance.assign(kGridChannels, options.normal_tolerance);
    grid_options.mixed_anchors = true;  // every channel fades to 0 at outer_radius (Exact)
    grid_options.zero_outside = true;   // the box holds every point within outer_radius of the surface
    std::fill_n(grid_options.tolerance.begin(), 3, options.offset_tolerance);
    grid_options.smooth_beyond = options.smooth_beyond;
    grid_options.refine = options.grid_refine;
    // Group 0 the offset, 1 both normals: Offsets asks for the offset alone.
    grid_options.group = {0, 0, 0, 1, 1, 1, 1, 1, 1};
    grid = std::make_unique<LazyGrid>(
        lo - margin, hi + margin, std::move(grid_options),
        [this](const Vec3f& x, float* values, Vec3f* anchor) { return Exact(x, values, anchor); });
  }

  // values[kGridChannels] at x (head frame); the anchor is x's closest surface point, if any. The
  // normals are scaled by the warp's weight (IctWarpOptions::Weight), so that every channel fades to
  // 0 at outer_radius, as the offset does (Sample's caller normalises them).
  bool Exact(const Vec3f& x, float* values, Vec3f* anchor) const {
    // The lid slide, then the closest-point warp at the slid point (as PosedIctWarp::Offset).
    const Vec3f slid = posed.LidSlide(x);
    const face::IctWarpClosest closest = posed.Closest(slid);
    Eigen::Map<Vec3f> offset(values), observed(values + 3), canonical(values + 6);
    offset = (slid - x) + posed.OffsetAt(slid, closest);
    if (closest.triangle < 0) {
      observed.setZero(), canonical.setZero();
      return false;
    }
    const std::array<uint32_t, 3>& t = posed.warp().triangles()[closest.triangle];
    const Vec3f& b = closest.barycentric;
    const float weight = posed.warp().options().Weight(closest.distance);
    observed = weight * Interpolated(normals, t, b);
    canonical = weight * Interpolated(canonical_normals, t, b);
    *anchor = SurfacePoint(closest);
    return true;
  }

  // The point of the posed surface at a closest point (closest.triangle >= 0), head frame.
  Vec3f SurfacePoint(const face::IctWarpClosest& closest) const {
    const std::array<uint32_t, 3>& t = posed.warp().triangles()[closest.triangle];
    const Vec3f& b = closest.barycentric;
    const std::vector<Vec3f>& mesh = posed.posed();
    return b[0] * mesh[t[0]] + b[1] * mesh[t[1]] + b[2] * mesh[t[2]];
  }
  // Which side of the posed surface x lies on, and how far along its normal there: the interpolated
  // vertex normal at x's closest point (closest.triangle >= 0) dotted with x minus that point.
  float Side(const face::IctWarpClosest& closest, const Vec3f& x) const {
    const std::array<uint32_t, 3>& t = posed.warp().triangles()[closest.triangle];
    return Interpolated(normals, t, closest.barycentric).dot(x - SurfacePoint(closest));
  }

  // Channels [first, first + count) of the offset and normals at x (head frame) into values[count]:
  // the grid's where there is one.
  void Sample(const Vec3f& x, int first, int count, float* values) const {
    if (grid != nullptr) {
      grid->At(x, first, count, values);
      return;
    }
    float all[kGridChannels];
    Vec3f anchor;
    Exact(x, all, &anchor);
    std::copy_n(all + first, count, values);
  }

  face::PosedIctWarp posed;
  MouthVolume mouth;
  std::vector<Vec3f> normals;                   // of the posed warp surface: [num_vertices], head frame
  const std::vector<Vec3f>& canonical_normals;  // of the neutral (beta = 0)
  bool open = false;                            // the inner lips are parted (kOpenLipGap)
  Vec3f teeth_lo = Vec3f::Constant(INFINITY);   // the posed teeth's bounding box, head frame
  Vec3f teeth_hi = Vec3f::Constant(-INFINITY);
  Vec3f lips_lo = Vec3f::Constant(INFINITY);  // the inner lips' box grown by kLipsReach
  Vec3f lips_hi = Vec3f::Constant(-INFINITY);
  std::unique_ptr<LazyGrid> grid;  // nullptr: grid_cell = 0
};

Status IctPriorOptions::Validate() const {
  ICEF_RETURN_IF_ERROR(warp.Validate());
  if (!std::isfinite(grid_cell) || grid_cell < 0.f)
    return Status::Error("grid_cell must be a finite number >= 0 (cm), got " + std::to_string(grid_cell));
  if (!std::isfinite(offset_tolerance) || offset_tolerance < 0.f || !std::isfinite(normal_tolerance) ||
      normal_tolerance < 0.f)
    return Status::Error("offset_tolerance and normal_tolerance must be finite numbers >= 0");
  if (grid_refine < 0 || grid_refine > LazyGrid::kMaxRefine)
    return Status::Error("grid_refine must be in [0, " + std::to_string(LazyGrid::kMaxRefine) + "], got " +
                         std::to_string(grid_refine));
  if (!(smooth_beyond >= 0.f))
    return Status::Error("smooth_beyond must be >= 0 (cm; infinity: never), got " +
                         std::to_string(smooth_beyond));
  return Status::Ok();
}

std::string IctPriorOptions::ToString() const {
  std::ostringstream os;
  os << "IctPriorOptions(" << warp.ToString() << ", grid_cell=" << grid_cell
     << ", offset_tolerance=" << offset_tolerance << ", normal_tolerance=" << normal_tolerance
     << ", smooth_beyond=" << smooth_beyond << ", grid_refine=" << grid_refine << ")";
  return os.str();
}

IctPrior::~IctPrior() = default;

Result<std::unique_ptr<IctPrior>> IctPrior::Create(std::shared_ptr<const face::IctModel> model,
                                                   std::span<const float> identity,
                                                   const face::Similarity& head_from_world,
                                                   const IctPriorOptions& options) {
  if (model == nullptr) return Status::Error("IctPrior: no face model");
  const face::Similarity& s = head_from_world;
  const bool finite = std::isfinite(s.scale) && s.rotation.allFinite() && s.translation.allFinite();
  if (!finite || !(s.scale > 0) || !(s.rotation.transpose() * s.rotation).isApprox(Mat3d::Identity(), 1e-6) ||
      !(s.rotation.determinant() > 0))
    return Status::Error("IctPrior: head_from_world is not a similarity (finite scale > 0, a rotation): " +
                         s.ToString());
  ICEF_RETURN_IF_ERROR(options.Validate().WithContext("IctPrior"));
  Result<face::IctWarp> warp = face::IctWarp::Create(*model, identity, options.warp);
  if (!warp.ok()) return warp.status().WithContext("IctPrior");
  std::unique_ptr<IctPrior> prior(new IctPrior());
  prior->warp_ = std::make_unique<const face::IctWarp>(std::move(warp).value());
  Result<MouthSurface> surface = MouthSurface::Build(*prior->warp_);
  if (!surface.ok()) return surface.status().WithContext("IctPrior");
  prior->mouth_surface_ = std::make_unique<const MouthSurface>(std::move(surface).value());
  prior->options_ = options;
  prior->neutral_normals_ = prior->warp_->VertexNormals(prior->warp_->neutral());
  prior->model_ = std::move(model);
  prior->identity_.assign(identity.begin(), identity.end());
  prior->head_from_world_ = s;
  prior->head_from_world_linear_ = (s.scale * s.rotation).cast<float>();
  prior->world_from_head_linear_ = (s.rotation.transpose() / s.scale).cast<float>();
  prior->world_from_head_rotation_ = s.rotation.transpose().cast<float>();
  prior->translation_ = s.translation.cast<float>();
  prior->rest_ = prior->Pose(std::vector<float>(prior->expression_dims(), 0.f));
  return prior;
}

std::shared_ptr<const IctPrior::Expression> IctPrior::Pose(const std::vector<float>& key) const {
  return std::make_shared<const Expression>(*warp_, *mouth_surface_, &neutral_normals_, key, options_);
}

IctPrior::Batch IctPrior::Prepare(const Executor& executor, int64_t n, const float* betas) const {
  const int dims = expression_dims();
  Batch batch;
  const float* last = nullptr;
  for (int64_t i = 0; i < n; ++i) {
    const float* beta = betas + i * dims;
    if (last != nullptr && std::equal(beta, beta + dims, last)) continue;  // a run of one row
    last = beta;
    if (std::any_of(batch.keys.begin(), batch.keys.end(), [&](const auto& k) { return SameRow(beta, k); }))
      continue;
    batch.keys.emplace_back(dims);
    std::transform(beta, beta + dims, batch.keys.back().begin(), Sanitized);
  }
  batch.expressions.resize(batch.keys.size());
  std::vector<size_t> missing;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    for (size_t k = 0; k < batch.keys.size(); ++k) {
      const std::vector<float>& key = batch.keys[k];
      if (std::all_of(key.begin(), key.end(), [](float w) { return w == 0.f; })) {
        batch.expressions[k] = rest_;
        continue;
      }
      const auto hit =
          std::find_if(cache_.begin(), cache_.end(), [&](const auto& e) { return e.key == key; });
      if (hit == cache_.end()) {
        missing.push_back(k);
        continue;
      }
      hit->last_used = ++clock_;
      batch.expressions[k] = hit->expression;
    }
  }
  // Posing is single-threaded and independent per expression: the missing ones side by side.
  ParallelForChunks(executor, static_cast<int64_t>(missing.size()), 1, [&](int64_t begin, int64_t end) {
    for (int64_t j = begin; j < end; ++j) batch.expressions[missing[j]] = Pose(batch.keys[missing[j]]);
  });
  const std::lock_guard<std::mutex> lock(mutex_);
  for (size_t k : missing) {
    const auto hit =
        std::find_if(cache_.begin(), cache_.end(), [&](const auto& e) { return e.key == batch.keys[k]; });
    if (hit != cache_.end()) continue;  // another call posed it meanwhile (the same result)
    cache_.push_back({batch.keys[k], batch.expressions[k], ++clock_});
  }
  while (cache_.size() > static_cast<size_t>(kCacheCapacity)) {
    const auto oldest = std::min_element(
        cache_.begin(), cache_.end(), [](const auto& a, const auto& b) { return a.last_used < b.last_used; });
    cache_.erase(oldest);
  }
  return batch;
}

template <class Fn>
void IctPrior::ForEachSample(const Executor& executor, int64_t n, const float* positions, const float* betas,
                             Fn&& fn) const {
  if (n <= 0) return;
  const Batch batch = Prepare(executor, n, betas);
  const int dims = expression_dims();
  ParallelForChunks(executor, n, BalancedChunk(n, 64, 4096), [&](int64_t begin, int64_t end) {
    const float* row = nullptr;
    const Expression* expression = nullptr;
    for (int64_t i = begin; i < end; ++i) {
      const float* beta = betas + i * dims;
      if (row == nullptr || !std::equal(beta, beta + dims, row)) {
        row = beta;
        size_t k = 0;
        while (k < batch.keys.size() && !SameRow(beta, batch.keys[k])) ++k;
        ICEF_CHECK(k < batch.keys.size(), "an expression row the batch did not see");
        expression = batch.expressions[k].get();
      }
      const Vec3f x = head_from_world_linear_ * Eigen::Map<const Vec3f>(positions + 3 * i) + translation_;
      fn(i, *expression, x);
    }
  });
}

void IctPrior::Offsets(const Executor& executor, int64_t n, const float* positions, const float* betas,
                       float* offsets) const {
  ForEachSample(executor, n, positions, betas, [&](int64_t i, const Expression& e, const Vec3f& x) {
    float values[3];
    e.Sample(x, 0, 3, values);
    Eigen::Map<Vec3f>(offsets + 3 * i) = world_from_head_linear_ * Eigen::Map<const Vec3f>(values);
  });
}

void IctPrior::Cavity(const Executor& executor, int64_t n, const float* positions, const float* betas,
                      uint8_t* inside) const {
  const std::vector<uint8_t>& labels = model_->part_labels();
  ForEachSample(executor, n, positions, betas, [&](int64_t i, const Expression& e, const Vec3f& x) {
    inside[i] = kField;
    if (!e.open) return;
    const auto in_box = [&](const Vec3f& lo, const Vec3f& hi) {
      return (x.array() >= lo.array()).all() && (x.array() <= hi.array()).all();
    };
    const bool in_mouth = e.mouth.Inside(x), near_teeth = in_box(e.teeth_lo, e.teeth_hi),
               near_lips = in_box(e.lips_lo, e.lips_hi);
    if (!in_mouth && !near_teeth && !near_lips) return;
    const face::IctWarpClosest closest = e.posed.Closest(x);
    if (closest.triangle < 0) return;
    // The part of the closest point: that of the triangle's corner nearest to it.
    const std::array<uint32_t, 3>& t = warp_->triangles()[closest.triangle];
    const Vec3f& b = closest.barycentric;
    const int corner = b[0] >= b[1] && b[0] >= b[2] ? 0 : b[1] >= b[2] ? 1 : 2;
    const int part = labels[t[corner]];
    const float side = e.Side(closest, x);
    const bool interior =
        part == mouth_surface_->teeth || part == mouth_surface_->socket || part == mouth_surface_->tongue;
    // Inside a tooth: behind the teeth's surface (their normals point out).
    if (part == mouth_surface_->teeth && side < 0.f) {
      inside[i] = kTeeth;
      return;
    }
    // On the air side of the socket or the tongue (their normals point into the mouth): the cavity.
    if (in_mouth && (part == mouth_surface_->socket || part == mouth_surface_->tongue) && side > 0.f) {
      inside[i] = kMouthCavity;
      return;
    }
    // Air in the parted lips: x on the air side of its closest surface (its normal points to x), and
    // that surface is inside the mouth (teeth, gums, tongue, socket: x is in the opening, which the
    // unmoving upper teeth would carry into the closed lips at rest), or x's canonical point lies more
    // than kAirDepth behind the surface at rest.
    if (!near_lips || !(side > 0.f)) return;
    if (interior) {
      inside[i] = kAir;
      return;
    }
    const Vec3f canonical = x + e.posed.OffsetAt(x, closest);
    const face::IctWarpClosest rest = rest_->posed.Closest(canonical);
    if (rest.triangle >= 0 && rest_->Side(rest, canonical) < -kAirDepth) inside[i] = kAir;
  });
}

bool IctPrior::Normals(const Executor& executor, int64_t n, const float* positions, const float* betas,
                       float* observed, float* canonical) const {
  ForEachSample(executor, n, positions, betas, [&](int64_t i, const Expression& e, const Vec3f& x) {
    float values[6];  // observed, canonical
    e.Sample(x, 3, 6, values);
    // Unit normals where the warp's weight is above 1e-3 (within ~2.96 of the 3 cm outer radius),
    // else 0 (the channels are the normals times the weight; interpolated ones are renormalised).
    const auto unit = [](const float* v) {
      const Vec3f n = Eigen::Map<const Vec3f>(v);
      const float norm = n.norm();
      return norm > 1e-3f ? Vec3f(n / norm) : Vec3f::Zero();
    };
    Eigen::Map<Vec3f>(observed + 3 * i) = world_from_head_rotation_ * unit(values);
    Eigen::Map<Vec3f>(canonical + 3 * i) = world_from_head_rotation_ * unit(values + 3);
  });
  return true;
}

int IctPrior::expression_dims() const { return model_->num_expressions(); }

std::string IctPrior::ToString() const {
  int identities = 0;
  for (float c : identity_) identities += c != 0.f;
  std::lock_guard<std::mutex> lock(mutex_);
  std::ostringstream os;
  os << "IctPrior(model=" << model_->path().string() << ", identity=" << identities << " of "
     << model_->num_identities() << " coefficients non-zero, head_from_world=" << head_from_world_.ToString()
     << ", " << options_.ToString() << ", mouth_surface=" << mouth_surface_->triangles.size()
     << " triangles, cached=" << cache_.size() << "/" << kCacheCapacity << " expressions";
  LazyGrid::Counts grid;
  for (const CacheEntry& entry : cache_) {
    if (entry.expression->grid == nullptr) continue;
    const LazyGrid::Counts c = entry.expression->grid->counts();
    grid.bricks += c.bricks, grid.cells += c.cells, grid.interpolated += c.interpolated;
    grid.refined += c.refined, grid.fine_cells += c.fine_cells, grid.fine_interpolated += c.fine_interpolated;
  }
  if (grid.cells > 0)
    os << ", their grids: " << grid.bricks << " bricks, " << grid.interpolated << "/" << grid.cells
       << " cells interpolated, " << grid.refined << " refined (" << grid.fine_interpolated << "/"
       << grid.fine_cells << " fine cells interpolated)";
  os << ")";
  return os.str();
}

Result<face::Similarity> FitIctHeadFromWorld(const face::IctModel& model, std::span<const float> identity,
                                             const std::vector<std::vector<Vec3f>>& landmarks_3d_world) {
  if (landmarks_3d_world.empty()) return Status::Error("FitIctHeadFromWorld: no frames with landmarks");
  if (identity.size() > static_cast<size_t>(model.num_identities()))
    return Status::Error("FitIctHeadFromWorld: " + std::to_string(identity.size()) +
                         " identity coefficients for a model with " + std::to_string(model.num_identities()));
  const std::vector<Vec3f> target = model.Landmarks(model.Mesh(identity, {}));
  std::vector<Vec3d> world, head;
  for (size_t f = 0; f < landmarks_3d_world.size(); ++f) {
    const std::vector<Vec3f>& frame = landmarks_3d_world[f];
    if (frame.size() != static_cast<size_t>(face::IctModel::kNumLandmarks))
      return Status::Error("FitIctHeadFromWorld: frame " + std::to_string(f) + " has " +
                           std::to_string(frame.size()) + " landmarks, not 68");
    for (int k : kRigidLandmarks) {
      if (!frame[k].allFinite() || !target[k].allFinite()) continue;
      world.push_back(frame[k].cast<double>());
      head.push_back(target[k].cast<double>());
    }
  }
  const auto m = static_cast<Eigen::Index>(world.size());
  Eigen::Matrix3Xd src(3, m), dst(3, m);
  for (Eigen::Index j = 0; j < m; ++j) src.col(j) = world[j], dst.col(j) = head[j];
  // Points spread in 3D (not all on a line): the second singular value of the centred points.
  const Eigen::Matrix3Xd centred = src.colwise() - src.rowwise().mean();
  const Vec3d spread = Eigen::JacobiSVD<Eigen::Matrix3Xd>(centred).singularValues();
  if (m < 3 || !(spread[1] > 1e-9 * spread[0]))
    return Status::Error("FitIctHeadFromWorld: too few usable landmarks (" + std::to_string(m) +
                         " finite nose and eye-corner points, on a line or fewer than 3)");
  const Mat4d t = Eigen::umeyama(src, dst, true);
  face::Similarity s;
  s.scale = std::cbrt(t.topLeftCorner<3, 3>().determinant());
  s.rotation = t.topLeftCorner<3, 3>() / s.scale;
  s.translation = t.topRightCorner<3, 1>();
  if (!std::isfinite(s.scale) || !(s.scale > 0) || !s.rotation.allFinite() || !s.translation.allFinite())
    return Status::Error("FitIctHeadFromWorld: the alignment failed (" + s.ToString() + ")");
  return s;
}

bool IsIctExpressionSpace(const face::IctModel& model, const std::vector<std::string>& expression_names) {
  return expression_names == model.expression_names();
}

Result<IctFaceFit> FitIctToDataset(const face::IctModel& model, const Dataset& dataset) {
  const std::string origin = dataset.root.string();
  if (!IsIctExpressionSpace(model, dataset.expression_names))
    return Status::Error(origin + ": the ICT-FaceKit prior needs the model's " +
                         std::to_string(model.num_expressions()) +
                         " expressions (expression_names as `icef track --face-model ict` writes them)");
  std::vector<face::IctObservation> observations;
  std::vector<std::vector<Vec3f>> landmarks_3d;
  for (const Frame& f : dataset.train) {
    if (!f.landmarks_2d || !f.landmarks_3d) continue;
    observations.push_back(face::IctObservation{f.camera.intrinsics(), *f.landmarks_2d, {}});
    landmarks_3d.push_back(*f.landmarks_3d);
  }
  if (observations.empty())
    return Status::Error(origin +
                         ": the ICT-FaceKit fit needs landmarks_2d and landmarks_3d on the training frames "
                         "(`icef track --face-model ict` writes both)");
  Result<face::IctFit> fit = face::FitIctToLandmarks(model, observations, face::IctFitOptions::ForPhotos());
  if (!fit.ok()) return fit.status().WithContext(origin + ": ICT-FaceKit fit");
  IctFaceFit out;
  out.identity = fit->identity;
  out.rms_iod = fit->rms_iod;
  Result<face::Similarity> sim = FitIctHeadFromWorld(model, out.identity, landmarks_3d);
  if (!sim.ok()) return sim.status().WithContext(origin);
  out.head_from_world = *sim;
  return out;
}

}  // namespace icef
