#include "icef/model/lazy_grid.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "icef/core/status.h"

namespace icef {

namespace {

constexpr int kBrickCellCount = LazyGrid::kBrickCells * LazyGrid::kBrickCells * LazyGrid::kBrickCells;

// Index of corner (i, j, k) of a block of n^3 cells ((n + 1)^3 corners), and of its cell (i, j, k).
int NodeIndex(int n, int i, int j, int k) { return (k * (n + 1) + j) * (n + 1) + i; }
int CellIndex(int n, int i, int j, int k) { return (k * n + j) * n + i; }

// Trilinear interpolation of channels [first, first + count) of the `channels` values at the corners
// of cell (i, j, k) of a block of n^3 cells, at local coordinates u in [0, 1]^3.
void Interpolate(const float* nodes, int n, int channels, int first, int count, int i, int j, int k,
                 const Vec3f& u, float* out) {
  const float wx[2] = {1.f - u.x(), u.x()}, wy[2] = {1.f - u.y(), u.y()}, wz[2] = {1.f - u.z(), u.z()};
  for (int c = 0; c < count; ++c) out[c] = 0.f;
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        const float w = wx[dx] * wy[dy] * wz[dz];
        const float* v = nodes + static_cast<size_t>(NodeIndex(n, i + dx, j + dy, k + dz)) * channels + first;
        for (int c = 0; c < count; ++c) out[c] += w * v[c];
      }
}

}  // namespace

// f sampled over a block of n^3 cells: a brick (n = kBrickCells, cells of options.cell) or a refined
// cell (n = options.refine).
struct LazyGrid::Block {
  std::vector<float> nodes;           // [(n + 1)^3, channels]; empty: all 0 (a block far from anchors)
  std::vector<uint8_t> interpolated;  // [n^3]: bit g set: the cell passes the tests for channel group g
};

struct LazyGrid::Brick : LazyGrid::Block {
  // [kBrickCells^3] the refined blocks of the cells that failed (nullptr until asked for); null
  // when no cell failed or options.refine < 2.
  std::unique_ptr<std::atomic<const Block*>[]> refined;
  ~Brick() {
    if (refined != nullptr)
      for (int c = 0; c < kBrickCellCount; ++c) delete refined[c].load(std::memory_order_relaxed);
  }
};

LazyGrid::LazyGrid(const Vec3f& lo, const Vec3f& hi, Options options, Function f)
    : lo_(lo), options_(std::move(options)), f_(std::move(f)) {
  ICEF_CHECK((lo.array() < hi.array()).all() && lo.allFinite() && hi.allFinite(), "LazyGrid: empty box");
  ICEF_CHECK(std::isfinite(options_.cell) && options_.cell > 0.f, "LazyGrid: cell must be > 0");
  ICEF_CHECK(!options_.tolerance.empty() && options_.tolerance.size() <= kMaxChannels,
             "LazyGrid: 1 to kMaxChannels channels");
  for (float t : options_.tolerance) ICEF_CHECK(std::isfinite(t) && t >= 0.f, "LazyGrid: bad tolerance");
  ICEF_CHECK(options_.smooth_beyond >= 0.f, "LazyGrid: smooth_beyond must be >= 0");
  ICEF_CHECK(options_.refine >= 0 && options_.refine <= kMaxRefine,
             "LazyGrid: refine must be in [0, kMaxRefine]");
  ICEF_CHECK(options_.group.empty() || options_.group.size() == options_.tolerance.size(),
             "LazyGrid: one group per channel");
  for (int g : options_.group) ICEF_CHECK(g >= 0 && g < 8, "LazyGrid: groups are 0 to 7");
  for (int c = 0; c < channels(); ++c) all_groups_ |= GroupBit(c);
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

void LazyGrid::Sample(const Vec3f& origin, float h, int n, Block* block) const {
  const int channels = this->channels();
  const int nodes = (n + 1) * (n + 1) * (n + 1);
  block->nodes.resize(static_cast<size_t>(nodes) * channels);
  block->interpolated.assign(static_cast<size_t>(n) * n * n, 0);
  std::vector<Vec3f> anchors(nodes);
  std::vector<uint8_t> anchored(nodes);
  std::vector<float> to_anchor(nodes, INFINITY);  // a node's distance to its anchor
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        const int v = NodeIndex(n, i, j, k);
        const Vec3f node = origin + h * Vec3f(i, j, k);
        anchored[v] = f_(node, block->nodes.data() + v * channels, &anchors[v]) ? 1 : 0;
        if (anchored[v]) to_anchor[v] = (node - anchors[v]).norm();
      }
  const float spread = options_.max_anchor_spread * h;
  const float diagonal = std::sqrt(3.f) * h;
  float exact[kMaxChannels], interpolated[kMaxChannels];
  Vec3f anchor;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        int count = 0;
        Vec3f a_lo = Vec3f::Constant(INFINITY), a_hi = Vec3f::Constant(-INFINITY);
        float nearest = INFINITY;  // the corners' smallest distance to their anchors
        for (int d = 0; d < 8; ++d) {
          const int v = NodeIndex(n, i + (d & 1), j + ((d >> 1) & 1), k + (d >> 2));
          if (!anchored[v]) continue;
          ++count;
          a_lo = a_lo.cwiseMin(anchors[v]);
          a_hi = a_hi.cwiseMax(anchors[v]);
          nearest = std::min(nearest, to_anchor[v]);
        }
        uint8_t& passes = block->interpolated[CellIndex(n, i, j, k)];  // 0: fails for every group
        if (n == kBrickCells && std::isfinite(options_.smooth_beyond) &&
            nearest - diagonal >= options_.smooth_beyond) {
          passes = all_groups_;  // far from every anchor: smooth by definition
          continue;
        }
        if (count != 0 && count != 8 && !options_.mixed_anchors) continue;
        if (count > 1 && (a_hi - a_lo).norm() > spread) continue;
        f_(origin + h * Vec3f(i + 0.5f, j + 0.5f, k + 0.5f), exact, &anchor);
        Interpolate(block->nodes.data(), n, channels, 0, channels, i, j, k, Vec3f::Constant(0.5f),
                    interpolated);
        passes = all_groups_;
        for (int c = 0; c < channels; ++c)
          if (!(std::abs(interpolated[c] - exact[c]) <= options_.tolerance[c])) passes &= ~GroupBit(c);
      }
  // Nothing anchored, every value 0 and every cell interpolated: keep no nodes.
  const bool empty =
      std::all_of(anchored.begin(), anchored.end(), [](uint8_t a) { return a == 0; }) &&
      std::all_of(block->nodes.begin(), block->nodes.end(), [](float v) { return v == 0.f; }) &&
      std::all_of(block->interpolated.begin(), block->interpolated.end(),
                  [&](uint8_t c) { return c == all_groups_; });
  if (empty) block->nodes = {};
}

LazyGrid::Brick* LazyGrid::Build(int bx, int by, int bz) const {
  auto brick = std::make_unique<Brick>();
  const Vec3f origin = lo_ + options_.cell * Vec3f(bx * kBrickCells, by * kBrickCells, bz * kBrickCells);
  Sample(origin, options_.cell, kBrickCells, brick.get());
  const bool failed = std::any_of(brick->interpolated.begin(), brick->interpolated.end(),
                                  [&](uint8_t c) { return c != all_groups_; });
  if (options_.refine >= 2 && failed) {
    brick->refined = std::make_unique<std::atomic<const Block*>[]>(kBrickCellCount);
    for (int c = 0; c < kBrickCellCount; ++c) brick->refined[c].store(nullptr, std::memory_order_relaxed);
  }
  return brick.release();
}

const LazyGrid::Brick& LazyGrid::BrickAt(int64_t index, int bx, int by, int bz) const {
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

const LazyGrid::Block& LazyGrid::RefinedAt(const Brick& brick, int64_t brick_index, int cell_index,
                                           const int cell[3]) const {
  std::atomic<const Block*>& slot = brick.refined[cell_index];
  const Block* block = slot.load(std::memory_order_acquire);
  if (block != nullptr) return *block;
  const std::lock_guard<std::mutex> lock(locks_[(brick_index * kBrickCellCount + cell_index) % kLocks]);
  block = slot.load(std::memory_order_acquire);
  if (block == nullptr) {
    auto fine = std::make_unique<Block>();
    const Vec3f origin = lo_ + options_.cell * Vec3f(cell[0], cell[1], cell[2]);
    Sample(origin, options_.cell / static_cast<float>(options_.refine), options_.refine, fine.get());
    block = fine.release();
    slot.store(block, std::memory_order_release);
  }
  return *block;
}

bool LazyGrid::At(const Vec3f& x, float* values) const { return At(x, 0, channels(), values); }

bool LazyGrid::At(const Vec3f& x, int first, int count, float* values) const {
  ICEF_CHECK(first >= 0 && count >= 0 && first + count <= channels(), "LazyGrid::At: channels out of range");
  const auto exact = [&] {
    float all[kMaxChannels];
    Vec3f anchor;
    f_(x, all, &anchor);
    std::copy_n(all + first, count, values);
    return false;
  };
  const Vec3f g = (x - lo_) / options_.cell;
  int cell[3];
  for (int a = 0; a < 3; ++a) {
    if (!(g[a] >= 0.f && g[a] < static_cast<float>(cells_[a]))) {  // outside, or not finite
      if (options_.zero_outside && x.allFinite()) {
        std::fill_n(values, count, 0.f);
        return true;
      }
      return exact();
    }
    cell[a] = std::min(static_cast<int>(g[a]), cells_[a] - 1);
  }
  const int bx = cell[0] / kBrickCells, by = cell[1] / kBrickCells, bz = cell[2] / kBrickCells;
  const int64_t brick_index = (static_cast<int64_t>(bz) * bricks_[1] + by) * bricks_[0] + bx;
  const Brick& brick = BrickAt(brick_index, bx, by, bz);
  const int i = cell[0] % kBrickCells, j = cell[1] % kBrickCells, k = cell[2] % kBrickCells;
  const int cell_index = CellIndex(kBrickCells, i, j, k);
  const Vec3f u(g[0] - static_cast<float>(cell[0]), g[1] - static_cast<float>(cell[1]),
                g[2] - static_cast<float>(cell[2]));
  const Block* block = &brick;
  int n = kBrickCells, ci = i, cj = j, ck = k;
  Vec3f local = u;
  uint8_t needed = 0;  // the groups of the channels asked for
  for (int c = first; c < first + count; ++c) needed |= GroupBit(c);
  if ((brick.interpolated[cell_index] & needed) != needed) {
    if (brick.refined == nullptr) return exact();
    block = &RefinedAt(brick, brick_index, cell_index, cell);
    n = options_.refine;
    const Vec3f s = u * static_cast<float>(n);
    ci = std::clamp(static_cast<int>(s.x()), 0, n - 1);
    cj = std::clamp(static_cast<int>(s.y()), 0, n - 1);
    ck = std::clamp(static_cast<int>(s.z()), 0, n - 1);
    if ((block->interpolated[CellIndex(n, ci, cj, ck)] & needed) != needed) return exact();
    local = s - Vec3f(ci, cj, ck);
  }
  if (block->nodes.empty()) {
    std::fill_n(values, count, 0.f);
    return true;
  }
  Interpolate(block->nodes.data(), n, channels(), first, count, ci, cj, ck, local, values);
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
    counts.interpolated += std::count(brick->interpolated.begin(), brick->interpolated.end(), all_groups_);
    if (brick->refined == nullptr) continue;
    for (int c = 0; c < kBrickCellCount; ++c) {
      const Block* fine = brick->refined[c].load(std::memory_order_acquire);
      if (fine == nullptr) continue;
      ++counts.refined;
      counts.fine_cells += static_cast<int64_t>(fine->interpolated.size());
      counts.fine_interpolated +=
          std::count(fine->interpolated.begin(), fine->interpolated.end(), all_groups_);
    }
  }
  return counts;
}

std::string LazyGrid::ToString() const {
  const Counts c = counts();
  std::ostringstream os;
  os << "LazyGrid(cells=" << cells_[0] << "x" << cells_[1] << "x" << cells_[2] << " of " << options_.cell
     << ", channels=" << channels() << ", refine=" << options_.refine << ", bricks built=" << c.bricks
     << ", interpolated cells=" << c.interpolated << "/" << c.cells << ", refined cells=" << c.refined
     << " (interpolated " << c.fine_interpolated << "/" << c.fine_cells << "))";
  return os.str();
}

}  // namespace icef
