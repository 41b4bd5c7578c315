#include "marsala/world_server/rules/occupancy_cache.hpp"

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <string>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/iterators.hpp"
#include "marsala/core/navigability_processor.hpp"

namespace marsala::world_server {
namespace {

constexpr int kMaxInt = std::numeric_limits<int>::max();

}  // namespace

const OccupancyCache::Box OccupancyCache::kNoChange{kMaxInt, kMaxInt, -1, -1};

OccupancyCache::OccupancyCache(const Heightmap& terrain, CellRect area, NavigabilityParams params)
    : area_(area), params_(params) {
  const NavigabilityProcessor processor(params);  // throws for invalid parameters
  if (area.empty() || !terrain.contains(area.first) ||
      !terrain.contains({area.first.row + area.rows - 1, area.first.col + area.cols - 1}))
    throw InvalidArgument(fmt::format("OccupancyCache: area of {} x {} cells at {} is empty or leaves the {} x {} grid",
                                      area.rows, area.cols, area.first, terrain.rows(), terrain.cols()));
  for (const CellIndex& o : disc_offsets(params.delta_m / (2.0 * terrain.cell_size_m())))
    reach_ = std::max({reach_, std::abs(o.row), std::abs(o.col)});
  block_rows_ = (area.rows + kBlockCells - 1) / kBlockCells;
  block_cols_ = (area.cols + kBlockCells - 1) / kBlockCells;
  changed_.assign(static_cast<std::size_t>(block_rows_) * block_cols_, kNoChange);
  mask_ = processor.occupiable(terrain.window(area.first, area.rows, area.cols));
}

void OccupancyCache::mark_changed(CellIndex cell) {
  if (!area_.contains(cell)) return;
  const int r = cell.row - area_.first.row, c = cell.col - area_.first.col;
  Box& box = changed_[static_cast<std::size_t>(r / kBlockCells) * block_cols_ + c / kBlockCells];
  box = {std::min(box.row0, r), std::min(box.col0, c), std::max(box.row1, r), std::max(box.col1, c)};
  has_changes_ = true;
}

std::vector<CellIndex> OccupancyCache::pending_changes() const {
  std::vector<CellIndex> cells;
  for (const Box& b : changed_) {
    if (b.row0 > b.row1) continue;
    cells.push_back({area_.first.row + b.row0, area_.first.col + b.col0});
    cells.push_back({area_.first.row + b.row1, area_.first.col + b.col1});
  }
  return cells;
}

void OccupancyCache::recompute(const Heightmap& terrain, const CellRect& t) {
  // The window holds every cell of T's balls that the area holds (see the header).
  const int r0 = std::max(0, t.first.row - reach_), c0 = std::max(0, t.first.col - reach_);
  const int r1 = std::min(area_.rows, t.first.row + t.rows + reach_);
  const int c1 = std::min(area_.cols, t.first.col + t.cols + reach_);
  const Heightmap window = terrain.window({area_.first.row + r0, area_.first.col + c0}, r1 - r0, c1 - c0);
  const CellMask part = NavigabilityProcessor(params_).occupiable(window);
  mask_.block(t.first.row, t.first.col, t.rows, t.cols) =
      part.block(t.first.row - r0, t.first.col - c0, t.rows, t.cols);
}

long long OccupancyCache::update(const Heightmap& terrain) {
  if (!has_changes_) return 0;
  if (!terrain.contains({area_.first.row + area_.rows - 1, area_.first.col + area_.cols - 1}))
    throw InvalidArgument(fmt::format("OccupancyCache::update: the {} x {} grid does not hold the cached area",
                                      terrain.rows(), terrain.cols()));
  // The cells within reach of each block's changes; overlapping boxes are merged (their hull), so no cell is
  // recomputed twice within one merged box.
  std::vector<Box> boxes;
  for (const Box& b : changed_)
    if (b.row0 <= b.row1)
      boxes.push_back({std::max(0, b.row0 - reach_), std::max(0, b.col0 - reach_),
                       std::min(area_.rows - 1, b.row1 + reach_), std::min(area_.cols - 1, b.col1 + reach_)});
  const auto overlap = [](const Box& a, const Box& b) {
    return a.row0 <= b.row1 && b.row0 <= a.row1 && a.col0 <= b.col1 && b.col0 <= a.col1;
  };
  for (bool merged = true; merged;) {
    merged = false;
    for (std::size_t i = 0; i < boxes.size(); ++i)
      for (std::size_t j = i + 1; j < boxes.size();) {
        if (!overlap(boxes[i], boxes[j])) {
          ++j;
          continue;
        }
        boxes[i] = {std::min(boxes[i].row0, boxes[j].row0), std::min(boxes[i].col0, boxes[j].col0),
                    std::max(boxes[i].row1, boxes[j].row1), std::max(boxes[i].col1, boxes[j].col1)};
        boxes[j] = boxes.back();
        boxes.pop_back();
        merged = true;
      }
  }
  long long recomputed = 0;
  for (const Box& b : boxes) {
    const CellRect t{{b.row0, b.col0}, b.row1 - b.row0 + 1, b.col1 - b.col0 + 1};
    recompute(terrain, t);
    recomputed += t.size();
  }
  std::fill(changed_.begin(), changed_.end(), kNoChange);
  has_changes_ = false;
  return recomputed;
}

}  // namespace marsala::world_server
