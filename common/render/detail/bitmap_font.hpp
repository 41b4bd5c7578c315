#pragma once
// A built-in 5 x 7 pixel font (plus one descender row) for legend labels: printable ASCII.

#include <array>
#include <cstdint>

namespace marsala::render::detail {

/// Glyph size in font pixels: 5 wide, 7 above the baseline, 1 descender row below it.
inline constexpr int kGlyphWidth = 5;
inline constexpr int kGlyphHeight = 8;
/// Horizontal advance per character [font pixels] (glyph plus one pixel of spacing).
inline constexpr int kGlyphAdvance = 6;

/// Rows of a glyph, top first; bit 4 is the leftmost pixel. Unknown characters map to '?'.
std::array<std::uint8_t, kGlyphHeight> glyph_rows(char c);

}  // namespace marsala::render::detail
