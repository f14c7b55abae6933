#pragma once
/// Sprig's own animated GIF encoder (GIF89a): per-frame palettes by median cut over the
/// frame's distinct colours, Floyd-Steinberg dithering, LZW.
///
/// Why not OpenImageIO's writer: its embedded gif.h builds each palette by median cut over
/// *pixels*, so a colour's share of the 255 entries follows its pixel count. A sprout a few
/// pixels high against a large sky (the first frame of a growth animation) got no entry of
/// its own and was drawn in sky colours and near-black (docs/GALLERY.md, "GIF colours").
/// Here every distinct colour counts once when a box is split, so a small group of
/// distinct colours keeps entries near it however few pixels it covers; each entry is
/// still the pixel-weighted mean of its box.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace sprig {

/// A frame's palette as 3·n RGB bytes, n <= maxColours (1..256): the frame's own colours
/// (sorted) when it has at most maxColours, else the pixel-weighted means of maxColours
/// median-cut boxes. rgb holds width·height RGB triples. Cost: O(pixels + maxColours ·
/// distinct colours · log).
std::vector<uint8_t> gifPalette(const std::vector<uint8_t>& rgb, int maxColours = 256);

/// Palette indices of rgb (width x height RGB triples) under palette (gifPalette's), with
/// Floyd-Steinberg error diffusion; a frame whose colours are all in the palette maps
/// exactly. Cost: O(pixels · 256).
std::vector<uint8_t> gifDither(const std::vector<uint8_t>& rgb, int width, int height, const std::vector<uint8_t>& palette);

/// The bytes of an animated GIF89a that loops forever: frameCount frames of width x height
/// RGB triples (frameRgb(i)), each shown delayCs centiseconds, each a full-canvas image with
/// its own local palette of up to 255 colours; after the first frame, index 255 is
/// transparent and marks pixels whose colour is unchanged on the canvas. Deterministic:
/// the same frames give the same bytes.
std::string encodeGif(int width, int height, int delayCs, size_t frameCount,
                      const std::function<std::vector<uint8_t>(size_t)>& frameRgb);

}  // namespace sprig
