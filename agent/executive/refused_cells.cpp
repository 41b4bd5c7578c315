#include "marsala/agent/executive/refused_cells.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "marsala/core/error.hpp"
#include "marsala/core/format.hpp"
#include "marsala/core/iterators.hpp"

namespace marsala::agent::executive {

std::optional<CellIndex> cell_named(const std::string& reason) {
  // The world's reasons name cells as "cell (r, c)" (docs/runtime.md#validation).
  const std::size_t at = reason.find("cell (");
  if (at == std::string::npos) return std::nullopt;
  int row = 0, col = 0;
  if (std::sscanf(reason.c_str() + at, "cell (%d, %d)", &row, &col) != 2) return std::nullopt;
  return CellIndex{row, col};
}

namespace {

// The drop a reason names at `at` (": cell (r, c) at h m lies too far below cell (r, c) at h m", or the same after
// "; " for the drops that follow the first), its heights finite; nullopt otherwise.
std::optional<DropRefusal> drop_at(const std::string& reason, std::size_t at) {
  DropRefusal out;
  if (std::sscanf(reason.c_str() + at + 1, " cell (%d, %d) at %lf m lies too far below cell (%d, %d) at %lf m",
                  &out.low.row, &out.low.col, &out.low_m, &out.high.row, &out.high.col, &out.high_m) != 6 ||
      !std::isfinite(out.low_m) || !std::isfinite(out.high_m))
    return std::nullopt;
  return out;
}

}  // namespace

std::optional<DropRefusal> drop_named(const std::string& reason) {
  const std::size_t at = reason.find(": cell (");
  if (at == std::string::npos) return std::nullopt;
  return drop_at(reason, at);
}

std::vector<DropRefusal> drops_named(const std::string& reason) {
  std::vector<DropRefusal> out;
  for (std::size_t at = reason.find(": cell ("); at != std::string::npos; at = reason.find("; cell (", at + 1)) {
    const auto drop = drop_at(reason, at);
    if (!drop) break;
    out.push_back(*drop);
  }
  return out;
}

std::optional<BoundRefusal> bound_named(const std::string& reason) {
  const std::size_t at = reason.find("would leave cell (");
  if (at == std::string::npos || reason.find("above the deposit bound") == std::string::npos) return std::nullopt;
  BoundRefusal out;
  if (std::sscanf(reason.c_str() + at, "would leave cell (%d, %d) at %lf m", &out.cell.row, &out.cell.col,
                  &out.height_m) != 3 ||
      !std::isfinite(out.height_m))
    return std::nullopt;
  return out;
}

std::optional<Position> pile_under_robot_named(const std::string& reason) {
  if (reason.rfind("deposit at (", 0) != 0 || reason.find(", under agent ") == std::string::npos) return std::nullopt;
  Position at;
  if (std::sscanf(reason.c_str(), "deposit at (%lf, %lf) m raises cell (", &at.x, &at.y) != 2 ||
      !std::isfinite(at.x) || !std::isfinite(at.y))
    return std::nullopt;
  return at;
}

bool refused_for_terrain(const std::string& reason) { return reason.find("not occupiable") != std::string::npos; }

RefusedCells::RefusedCells(double ball_radius_cells, double change_m, std::uint64_t hold_steps)
    : change_m_(change_m), hold_steps_(hold_steps) {
  if (!(ball_radius_cells >= 0.0) || !std::isfinite(ball_radius_cells) || !(change_m > 0.0) ||
      !std::isfinite(change_m) || hold_steps == 0)
    throw InvalidArgument(fmt::format("refused cells: ball radius {} cells, change {} m or hold {} steps out of range",
                                      ball_radius_cells, change_m, hold_steps));
  offsets_ = disc_offsets(ball_radius_cells);
}

std::vector<double> RefusedCells::ball(CellIndex cell, const Heightmap& heights, const CellMask& known) const {
  std::vector<double> out;
  out.reserve(offsets_.size());
  for (const CellIndex o : offsets_) {
    const CellIndex p{cell.row + o.row, cell.col + o.col};
    const bool on = heights.contains(p) && known(p.row, p.col) != 0;
    out.push_back(on ? heights(p) : std::numeric_limits<double>::quiet_NaN());
  }
  return out;
}

bool RefusedCells::changed(const std::vector<double>& before, const std::vector<double>& now, double change_m) {
  for (std::size_t i = 0; i < before.size(); ++i) {
    if (std::isnan(before[i]) != std::isnan(now[i])) return true;
    if (!std::isnan(before[i]) && std::abs(now[i] - before[i]) > change_m) return true;
  }
  return false;
}

void RefusedCells::refuse_terrain(CellIndex cell, const Heightmap& heights, const CellMask& known,
                                  std::optional<CellIndex> drop_low) {
  ++refusals_;
  const int earlier = terrain_refusals_[cell]++;
  Entry e{0, ball(cell, heights, known), std::ldexp(change_m_, std::min(earlier, 20)), std::nullopt, 0.0};
  if (drop_low && heights.contains(*drop_low)) {
    e.drop_low = drop_low;
    e.drop_low_m = heights(*drop_low);
  }
  cells_[cell] = std::move(e);
}

void RefusedCells::refuse_for_now(CellIndex cell, std::uint64_t step) {
  ++refusals_;
  Entry& e = cells_[cell];
  if (e.ball.empty()) e.until_step = std::max(e.until_step, step + hold_steps_);  // a terrain refusal stays one
}

void RefusedCells::update(const Heightmap& heights, const CellMask& known, std::uint64_t step) {
  for (auto it = cells_.begin(); it != cells_.end();) {
    const Entry& e = it->second;
    const bool over = e.ball.empty() ? e.until_step <= step
                                     : changed(e.ball, ball(it->first, heights, known), e.change_m) ||
                                           (e.drop_low && heights(*e.drop_low) > e.drop_low_m);
    it = over ? cells_.erase(it) : std::next(it);
  }
}

std::vector<CellIndex> RefusedCells::cells() const {
  std::vector<CellIndex> out;
  out.reserve(cells_.size());
  for (const auto& [cell, entry] : cells_) out.push_back(cell);
  return out;
}

}  // namespace marsala::agent::executive
