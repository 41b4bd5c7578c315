#include "marsala/core/iterators.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace marsala {

std::vector<CellIndex> disc_offsets(double radius_cells) {
  std::vector<CellIndex> offsets;
  if (!(radius_cells >= 0.0)) return offsets;
  const double limit = radius_cells * radius_cells + tolerance::kBallCells2;
  const int reach = static_cast<int>(std::floor(radius_cells + 1e-9));
  for (int dr = -reach; dr <= reach; ++dr)
    for (int dc = -reach; dc <= reach; ++dc)
      if (static_cast<double>(dr * dr + dc * dc) <= limit) offsets.push_back({dr, dc});
  return offsets;
}

SubmapIterator::SubmapIterator(const GridGeometry& grid, CellIndex top_left, int rows, int cols)
    : row_begin_(std::max(top_left.row, 0)),
      row_end_(std::min(top_left.row + rows, grid.rows)),
      col_begin_(std::max(top_left.col, 0)),
      col_end_(std::min(top_left.col + cols, grid.cols)),
      current_{row_begin_, col_begin_},
      past_end_(row_begin_ >= row_end_ || col_begin_ >= col_end_) {}

SubmapIterator& SubmapIterator::operator++() {
  if (++current_.col >= col_end_) {
    current_.col = col_begin_;
    if (++current_.row >= row_end_) past_end_ = true;
  }
  return *this;
}

DiscIterator::DiscIterator(const GridGeometry& grid, CellIndex center, double radius_m)
    : grid_(grid), center_(center), offsets_(disc_offsets(radius_m / grid.cell_size_m)) {
  skip_off_grid();
}

DiscIterator& DiscIterator::operator++() {
  ++index_;
  skip_off_grid();
  return *this;
}

void DiscIterator::skip_off_grid() {
  for (; index_ < offsets_.size(); ++index_) {
    current_ = {center_.row + offsets_[index_].row, center_.col + offsets_[index_].col};
    if (grid_.contains(current_)) return;
  }
}

LineIterator::LineIterator(const GridGeometry& grid, CellIndex start, CellIndex end)
    : grid_(grid),
      current_(start),
      end_(end),
      d_row_(std::abs(end.row - start.row)),
      d_col_(std::abs(end.col - start.col)),
      step_row_(end.row >= start.row ? 1 : -1),
      step_col_(end.col >= start.col ? 1 : -1),
      error_(d_col_ - d_row_),
      past_end_(!grid.contains(start)) {}

LineIterator& LineIterator::operator++() {
  if (past_end_) return *this;
  if (current_ == end_) {
    past_end_ = true;
    return *this;
  }
  const int twice = 2 * error_;
  if (twice > -d_row_) {
    error_ -= d_row_;
    current_.col += step_col_;
  }
  if (twice < d_col_) {
    error_ += d_col_;
    current_.row += step_row_;
  }
  if (!grid_.contains(current_)) past_end_ = true;
  return *this;
}

}  // namespace marsala
