#pragma once

#include <cstdint>
#include <vector>

namespace autograv::gl::detail {

/// The readout's bitmap font: 5x7-pixel capitals, digits and punctuation, drawn for this project.
/// Glyphs sit in an atlas of kAtlasColumns columns of kCellWidth x kCellHeight texels; the glyph's
/// top-left pixel is the cell's top-left texel, and the last column and row of a cell stay empty.
inline constexpr int kGlyphWidth = 5;
inline constexpr int kGlyphHeight = 7;
inline constexpr int kCellWidth = 6;
inline constexpr int kCellHeight = 8;
inline constexpr int kAtlasColumns = 16;

/// Cell of `c` in the atlas; lower case maps to upper case and unknown characters to '?'.
int glyphIndex(char c) noexcept;
/// Number of glyphs in the atlas.
int glyphCount() noexcept;
/// True when pixel (x, y) of glyph `index` is lit; (0, 0) is the top-left pixel.
bool glyphPixel(int index, int x, int y) noexcept;

/// The atlas as one byte per texel (0 or 255), rows from the top.
struct FontAtlas {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> texels;
};
FontAtlas buildFontAtlas();

}  // namespace autograv::gl::detail
