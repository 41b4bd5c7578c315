#pragma once
// fmt formatters for the vocabulary types, so every message spells a cell, a position or a body the same way:
//   CellIndex           "(row, col)"                      e.g. "(3, 7)"
//   Position            "(x, y) m"                        e.g. "(1.5, -0.25) m"
//   Rect                "[x0, x1] x [y0, y1] m"           e.g. "[0, 4.5] x [-1, 1] m"
//   CellRect            "rows R, cols C from (row, col)"  e.g. "rows 10, cols 20 from (3, 7)"
//   NavigabilityParams  "kappa K, delta D m, eps E m"     e.g. "kappa 0.3, delta 1 m, eps 0.05 m"
// Doubles print as fmt's "{}": the shortest text that reads back to the same double, so a message never hides the
// bit that decided a tie.

#include <fmt/format.h>

#include "marsala/core/types.hpp"

template <>
struct fmt::formatter<marsala::CellIndex> : fmt::formatter<fmt::string_view> {
  template <typename FormatContext>
  auto format(marsala::CellIndex c, FormatContext& ctx) const {
    return fmt::format_to(ctx.out(), "({}, {})", c.row, c.col);
  }
};

template <>
struct fmt::formatter<marsala::Position> : fmt::formatter<fmt::string_view> {
  template <typename FormatContext>
  auto format(marsala::Position p, FormatContext& ctx) const {
    return fmt::format_to(ctx.out(), "({}, {}) m", p.x, p.y);
  }
};

template <>
struct fmt::formatter<marsala::NavigabilityParams> : fmt::formatter<fmt::string_view> {
  template <typename FormatContext>
  auto format(const marsala::NavigabilityParams& p, FormatContext& ctx) const {
    return fmt::format_to(ctx.out(), "kappa {}, delta {} m, eps {} m", p.kappa, p.delta_m, p.eps_m);
  }
};

template <>
struct fmt::formatter<marsala::Rect> : fmt::formatter<fmt::string_view> {
  template <typename FormatContext>
  auto format(const marsala::Rect& r, FormatContext& ctx) const {
    return fmt::format_to(ctx.out(), "[{}, {}] x [{}, {}] m", r.x0, r.x1, r.y0, r.y1);
  }
};

template <>
struct fmt::formatter<marsala::CellRect> : fmt::formatter<fmt::string_view> {
  template <typename FormatContext>
  auto format(const marsala::CellRect& r, FormatContext& ctx) const {
    return fmt::format_to(ctx.out(), "rows {}, cols {} from ({}, {})", r.rows, r.cols, r.first.row, r.first.col);
  }
};
