#include "icef/model/lazy_grid.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "icef/core/status.h"

namespace icef {

namespace {

constexpr int kNodes = LazyGrid::kBrickCells + 1;  // corners per brick side
constexpr int kBrickCellCount = LazyGrid::kBrickCells * LazyGrid::kBrickCells * LazyGrid::kBrickCells;

int NodeIndex(int i, int j, int k) { return (k * kNodes + j) * kNodes + i; }
int CellIndex(int i, int j, int k) { return (k * LazyGrid::kBrickCells + j) * LazyGrid::kBrickCells + i; }

// Trilinear interpolation of `channels` values at the corners of cell (i, j, k) of a brick, at local
// coordinates u in [0, 1]^3.
void Interpolate(const float* nodes, int channels, int i, int j, int k, const Vec3f& u, float* out) {
  const float wx[2] = {1.f - u.x(), u.x()}, wy[2] = {1.f - u.y(), u.y()}, wz[2] = {1.f - u.z(), u.z()};
  for (int c = 0; c < channels; ++c) out[c] = 0.f;
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        const float w = wx[dx] * wy[dy] * wz[dz];
        const float* v = nodes + static_cast<size_t>(NodeIndex(i + dx, j + dy, k + dz)) * channels;
        for (int c = 0; c < channels; ++c) out[c] += w * v[c];
      }
}

}  // namespace

struct LazyGrid::Brick {
  std::vector<float> nodes;           // [kNodes^3, channels]; empty: all 0 (a brick far from anchors)
  std::vector<uint8_t> interpolated;  // [kBrickCells^3]: the cell passes the three tests
};

LazyGrid::LazyGrid(const Vec3f& lo, const Vec3f& hi, Options options, Function f)
    : lo_(lo), options_(std::move(options)), f_(std::move(f)) {
  ICEF_CHECK((lo.array() < hi.array()).all() && lo.allFinite() && hi.allFinite(), "LazyGrid: empty box");
  ICEF_CHECK(std::isfinite(options_.cell) && options_.cell > 0.f, "LazyGrid: cell must be > 0");
  ICEF_CHECK(!options_.tolerance.empty(), "LazyGrid: no channels");
  for (float t : options_.tolerance) ICEF_CHECK(std::isfinite(t) && t >= 0.f, "LazyGrid: bad tolerance");
  ICEF_CHECK(options_.smooth_beyond >= 0.f, "LazyGrid: smooth_beyond must be >= 0");
  int64_t count = 1;
  for (int a = 0; a < 3; ++a) {
    cells_[a] = std::max(1, static_cast<int>(std::ceil((hi[a] - lo[a]) / options_.cell)));
    bricks_[a] = (cells_[a] + kBrickCells - 1) / kBrickCells;
    cells_[a] = bricks_[a] * kBrickCells;
    count *= bricks_[a];
  }
  bricks_built_ = std::make_unique<std::atomic<const Brick*>[]>(static_cast<size_t>(count));
  for (int64_t b = 0; b < count; ++b) bricks_built_[b].store(nullptr, std::memory_order_relaxed);
}

LazyGrid::~LazyGrid() {
  const int64_t count = static_cast<int64_t>(bricks_[0]) * bricks_[1] * bricks_[2];
  for (int64_t b = 0; b < count; ++b) delete bricks_built_[b].load(std::memory_order_relaxed);
}

LazyGrid::Brick* LazyGrid::Build(int bx, int by, int bz) const {
  const int channels = this->channels();
  auto brick = std::make_unique<Brick>();
  brick->nodes.resize(static_cast<size_t>(kNodes * kNodes * kNodes) * channels);
  brick->interpolated.assign(kBrickCellCount, 0);
  std::vector<Vec3f> anchors(kNodes * kNodes * kNodes);
  std::vector<uint8_t> anchored(anchors.size());
  std::vector<float> to_anchor(anchors.size(), INFINITY);  // a node's distance to its anchor
  const Vec3f origin = lo_ + options_.cell * Vec3f(bx * kBrickCells, by * kBrickCells, bz * kBrickCells);
  for (int k = 0; k < kNodes; ++k)
    for (int j = 0; j < kNodes; ++j)
      for (int i = 0; i < kNodes; ++i) {
        const int n = NodeIndex(i, j, k);
        const Vec3f node = origin + options_.cell * Vec3f(i, j, k);
        anchored[n] = f_(node, brick->nodes.data() + n * channels, &anchors[n]) ? 1 : 0;
        if (anchored[n]) to_anchor[n] = (node - anchors[n]).norm();
      }
  const float spread = options_.max_anchor_spread * options_.cell;
  const float diagonal = std::sqrt(3.f) * options_.cell;
  std::vector<float> exact(channels), interpolated(channels);
  Vec3f anchor;
  for (int k = 0; k < kBrickCells; ++k)
    for (int j = 0; j < kBrickCells; ++j)
      for (int i = 0; i < kBrickCells; ++i) {
        int count = 0;
        Vec3f a_lo = Vec3f::Constant(INFINITY), a_hi = Vec3f::Constant(-INFINITY);
        float nearest = INFINITY;  // the corners' smallest distance to their anchors
        for (int d = 0; d < 8; ++d) {
          const int n = NodeIndex(i + (d & 1), j + ((d >> 1) & 1), k + (d >> 2));
          if (!anchored[n]) continue;
          ++count;
          a_lo = a_lo.cwiseMin(anchors[n]);
          a_hi = a_hi.cwiseMax(anchors[n]);
          nearest = std::min(nearest, to_anchor[n]);
        }
        if (std::isfinite(options_.smooth_beyond) && nearest - diagonal >= options_.smooth_beyond) {
          brick->interpolated[CellIndex(i, j, k)] = 1;  // far from every anchor: smooth by definition
          continue;
        }
        if (count != 0 && count != 8 && !options_.mixed_anchors) continue;
        if (count > 1 && (a_hi - a_lo).norm() > spread) continue;
        f_(origin + options_.cell * Vec3f(i + 0.5f, j + 0.5f, k + 0.5f), exact.data(), &anchor);
        Interpolate(brick->nodes.data(), channels, i, j, k, Vec3f::Constant(0.5f), interpolated.data());
        bool close = true;
        for (int c = 0; c < channels && close; ++c)
          close = std::abs(interpolated[c] - exact[c]) <= options_.tolerance[c];
        brick->interpolated[CellIndex(i, j, k)] = close ? 1 : 0;
      }
  // Nothing anchored, every value 0 and every cell interpolated: keep no nodes.
  const bool empty =
      std::all_of(anchored.begin(), anchored.end(), [](uint8_t a) { return a == 0; }) &&
      std::all_of(brick->nodes.begin(), brick->nodes.end(), [](float v) { return v == 0.f; }) &&
      std::all_of(brick->interpolated.begin(), brick->interpolated.end(), [](uint8_t c) { return c == 1; });
  if (empty) brick->nodes = {};
  return brick.release();
}

const LazyGrid::Brick& LazyGrid::BrickAt(int bx, int by, int bz) const {
  const int64_t index = (static_cast<int64_t>(bz) * bricks_[1] + by) * bricks_[0] + bx;
  std::atomic<const Brick*>& slot = bricks_built_[index];
  const Brick* brick = slot.load(std::memory_order_acquire);
  if (brick != nullptr) return *brick;
  const std::lock_guard<std::mutex> lock(locks_[index % kLocks]);
  brick = slot.load(std::memory_order_acquire);
  if (brick == nullptr) {
    brick = Build(bx, by, bz);
    slot.store(brick, std::memory_order_release);
  }
  return *brick;
}

bool LazyGrid::At(const Vec3f& x, float* values) const {
  const Vec3f g = (x - lo_) / options_.cell;
  int cell[3];
  for (int a = 0; a < 3; ++a) {
    if (!(g[a] >= 0.f && g[a] < static_cast<float>(cells_[a]))) {  // outside, or not finite
      if (options_.zero_outside && x.allFinite()) {
        std::fill_n(values, channels(), 0.f);
        return true;
      }
      Vec3f anchor;
      f_(x, values, &anchor);
      return false;
    }
    cell[a] = std::min(static_cast<int>(g[a]), cells_[a] - 1);
  }
  const Brick& brick = BrickAt(cell[0] / kBrickCells, cell[1] / kBrickCells, cell[2] / kBrickCells);
  const int i = cell[0] % kBrickCells, j = cell[1] % kBrickCells, k = cell[2] % kBrickCells;
  if (!brick.interpolated[CellIndex(i, j, k)]) {
    Vec3f anchor;
    f_(x, values, &anchor);
    return false;
  }
  if (brick.nodes.empty()) {
    std::fill_n(values, channels(), 0.f);
    return true;
  }
  const Vec3f u(g[0] - static_cast<float>(cell[0]), g[1] - static_cast<float>(cell[1]),
                g[2] - static_cast<float>(cell[2]));
  Interpolate(brick.nodes.data(), channels(), i, j, k, u, values);
  return true;
}

LazyGrid::Counts LazyGrid::counts() const {
  Counts counts;
  const int64_t count = static_cast<int64_t>(bricks_[0]) * bricks_[1] * bricks_[2];
  for (int64_t b = 0; b < count; ++b) {
    const Brick* brick = bricks_built_[b].load(std::memory_order_acquire);
    if (brick == nullptr) continue;
    ++counts.bricks;
    counts.cells += kBrickCellCount;
    counts.interpolated += std::count(brick->interpolated.begin(), brick->interpolated.end(), 1);
  }
  return counts;
}

std::string LazyGrid::ToString() const {
  const Counts c = counts();
  std::ostringstream os;
  os << "LazyGrid(cells=" << cells_[0] << "x" << cells_[1] << "x" << cells_[2] << " of " << options_.cell
     << ", channels=" << channels() << ", bricks built=" << c.bricks
     << ", interpolated cells=" << c.interpolated << "/" << c.cells << ")";
  return os.str();
}

}  // namespace icef
