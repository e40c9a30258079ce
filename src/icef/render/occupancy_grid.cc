#include "icef/render/occupancy_grid.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "icef/core/rng.h"

namespace icef {

Status OccupancyGridOptions::Validate() const {
  if (resolution < 1 || resolution > 1024) return Status::Error("occupancy.resolution must be in [1, 1024]");
  if (!(decay >= 0.f && decay <= 1.f)) return Status::Error("occupancy.decay must be in [0, 1]");
  if (!(threshold >= 0.f) || !std::isfinite(threshold))
    return Status::Error("occupancy.threshold must be >= 0");
  if (dilation < 0 || dilation > 16) return Status::Error("occupancy.dilation must be in [0, 16]");
  if (query_batch < 1) return Status::Error("occupancy.query_batch must be >= 1");
  if (!(update_fraction > 0.f && update_fraction <= 1.f))
    return Status::Error("occupancy.update_fraction must be in (0, 1]");
  return Status::Ok();
}

std::string OccupancyGridOptions::ToString() const {
  std::ostringstream os;
  os << "OccupancyGridOptions(resolution=" << resolution << ", decay=" << decay << ", threshold=" << threshold
     << ", dilation=" << dilation << ", query_batch=" << query_batch
     << ", update_fraction=" << update_fraction << ")";
  return os.str();
}

OccupancyGrid::OccupancyGrid(const Aabb& aabb, const OccupancyGridOptions& options)
    : aabb_(aabb), options_(options) {
  const Status status = options.Validate();
  ICEF_CHECK(status.ok(), status.ToString());
  ICEF_CHECK(aabb.IsValid(), "invalid aabb " + aabb.ToString());
  inv_cell_size_ = Vec3f::Constant(float(options_.resolution)).cwiseQuotient(aabb_.Extent());
  density_.assign(num_cells(), 0.f);
  bits_.assign(num_cells(), 0);
  Fill(true);
}

void OccupancyGrid::Fill(bool occupied) {
  std::fill(density_.begin(), density_.end(), occupied ? std::max(2.f * options_.threshold, 1e-6f) : 0.f);
  std::fill(bits_.begin(), bits_.end(), occupied ? 1 : 0);
  if (occupied && !allowed_.empty())
    for (int64_t c = 0; c < num_cells(); ++c) bits_[c] = allowed_[c];
}

Status OccupancyGrid::SetAllowed(std::vector<uint8_t> allowed) {
  if (!allowed.empty() && int64_t(allowed.size()) != num_cells())
    return Status::Error("occupancy grid: expected " + std::to_string(num_cells()) + " allowed flags, got " +
                         std::to_string(allowed.size()));
  allowed_ = std::move(allowed);
  queried_ = allowed_;
  if (!queried_.empty()) Dilate(&queried_);
  RecomputeBits();
  return Status::Ok();
}

int64_t OccupancyGrid::NumOccupied() const {
  int64_t n = 0;
  for (uint8_t b : bits_) n += b;
  return n;
}

void OccupancyGrid::Update(const DensityQuery& query, uint64_t seed, int64_t step) {
  const int r = options_.resolution;
  const int64_t cells = num_cells();
  const Vec3f cell_size = aabb_.Extent() / float(r);
  for (float& d : density_) d *= options_.decay;
  // The cells to re-query this step, in index order.
  std::vector<int64_t> selected;
  selected.reserve(options_.update_fraction >= 1.f ? cells
                                                   : int64_t(cells * options_.update_fraction * 1.1f) + 16);
  for (int64_t c = 0; c < cells; ++c) {
    if (!queried_.empty() && !queried_[c]) continue;
    if (options_.update_fraction >= 1.f ||
        Rng(seed, StreamId("occupancy_subset"), uint64_t(step), uint64_t(c)).Uniform() <
            options_.update_fraction)
      selected.push_back(c);
  }
  const int64_t batch =
      std::max<int64_t>(1, std::min<int64_t>(options_.query_batch, int64_t(selected.size())));
  std::vector<float> positions(batch * 3);
  std::vector<float> sigma(batch);
  for (int64_t begin = 0; begin < int64_t(selected.size()); begin += batch) {
    const int64_t n = std::min<int64_t>(batch, int64_t(selected.size()) - begin);
    for (int64_t i = 0; i < n; ++i) {
      const int64_t c = selected[begin + i];
      const int idx[3] = {int(c % r), int((c / r) % r), int(c / (int64_t(r) * r))};
      Rng rng(seed, StreamId("occupancy"), uint64_t(step), uint64_t(c));
      for (int a = 0; a < 3; ++a)
        positions[3 * i + a] = aabb_.min[a] + (float(idx[a]) + rng.Uniform()) * cell_size[a];
    }
    query(positions.data(), n, sigma.data());
    for (int64_t i = 0; i < n; ++i) {
      const float s = std::isfinite(sigma[i]) ? std::max(sigma[i], 0.f) : 0.f;
      float& d = density_[selected[begin + i]];
      d = std::max(d, s);
    }
  }
  RecomputeBits();
}

void OccupancyGrid::Dilate(std::vector<uint8_t>* bits) const {
  const int r = options_.resolution;
  const int k = options_.dilation;
  // Separable max filter, axis by axis.
  std::vector<uint8_t>& a = *bits;
  std::vector<uint8_t> b(num_cells());
  for (int axis = 0; axis < 3 && k > 0; ++axis) {
    for (int z = 0; z < r; ++z)
      for (int y = 0; y < r; ++y)
        for (int x = 0; x < r; ++x) {
          const int coord[3] = {x, y, z};
          uint8_t v = 0;
          for (int o = -k; o <= k && !v; ++o) {
            const int q = coord[axis] + o;
            if (q < 0 || q >= r) continue;
            int cc[3] = {x, y, z};
            cc[axis] = q;
            v = a[CellIndex(cc[0], cc[1], cc[2])];
          }
          b[CellIndex(x, y, z)] = v;
        }
    a.swap(b);
  }
}

void OccupancyGrid::RecomputeBits() {
  std::vector<uint8_t> a(num_cells());
  for (int64_t c = 0; c < num_cells(); ++c) a[c] = density_[c] > options_.threshold ? 1 : 0;
  Dilate(&a);
  if (!allowed_.empty())
    for (int64_t c = 0; c < num_cells(); ++c) a[c] &= allowed_[c];
  bits_.swap(a);
}

OccupancyGrid OccupancyGrid::WithQueriedCells(const DensityQuery& query, int stride) const {
  ICEF_CHECK(stride >= 1, "stride must be >= 1");
  const int r = options_.resolution;
  const int rb = (r + stride - 1) / stride;  // blocks per axis
  const int64_t blocks = int64_t(rb) * rb * rb;
  const Vec3f cell_size = aabb_.Extent() / float(r);
  std::vector<float> sigma(blocks);
  const int64_t batch = std::max<int64_t>(1, std::min<int64_t>(options_.query_batch, blocks));
  std::vector<float> positions(3 * batch);
  for (int64_t begin = 0; begin < blocks; begin += batch) {
    const int64_t n = std::min(batch, blocks - begin);
    for (int64_t i = 0; i < n; ++i) {
      const int64_t c = begin + i;
      const int64_t idx[3] = {c % rb, (c / rb) % rb, c / (int64_t(rb) * rb)};
      for (int a = 0; a < 3; ++a) {
        const float lo = float(idx[a] * stride), hi = float(std::min<int64_t>((idx[a] + 1) * stride, r));
        positions[3 * i + a] = aabb_.min[a] + 0.5f * (lo + hi) * cell_size[a];
      }
    }
    query(positions.data(), n, sigma.data() + begin);
  }
  const int64_t cells = num_cells();
  std::vector<uint8_t> hit(cells), allowed(cells);
  for (int z = 0; z < r; ++z)
    for (int y = 0; y < r; ++y)
      for (int x = 0; x < r; ++x) {
        const float v = sigma[(int64_t(z / stride) * rb + y / stride) * rb + x / stride];
        hit[CellIndex(x, y, z)] = std::isfinite(v) && v > options_.threshold ? 1 : 0;
        allowed[CellIndex(x, y, z)] = v >= 0.f ? 1 : 0;
      }
  Dilate(&hit);
  OccupancyGrid out = *this;
  out.allowed_.clear();
  out.queried_.clear();
  for (int64_t c = 0; c < cells; ++c) out.bits_[c] = bits_[c] | (hit[c] & allowed[c]);
  return out;
}

Status OccupancyGrid::SetDensities(std::vector<float> densities) {
  if (int64_t(densities.size()) != num_cells()) {
    return Status::Error("occupancy grid: expected " + std::to_string(num_cells()) + " densities, got " +
                         std::to_string(densities.size()));
  }
  density_ = std::move(densities);
  RecomputeBits();
  return Status::Ok();
}

std::string OccupancyGrid::ToString() const {
  std::ostringstream os;
  os << "OccupancyGrid(" << options_.ToString() << ", aabb=" << aabb_.ToString()
     << ", occupied=" << OccupiedFraction() << ")";
  return os.str();
}

}  // namespace icef
