#pragma once
/// Text over a rendered picture: the labels of a scene (TextLabel, cpfg's `@L`), drawn as
/// cpfg's window draws them (platformQt.cpp, DrawString; glcanvas.cpp, renderText): each
/// label's baseline starts at the pixel where its position projects, the text runs to the
/// right, screen-aligned and unshaded, over everything (the depth test is off), clipped at
/// the image's edges; a label behind the camera is not drawn.

#include <vector>

#include "core/image.h"
#include "render/camera.h"
#include "render/geometry.h"

namespace sprig::render {

/// Draws labels over image as camera sees them (image.width x image.height). Same bytes at
/// any thread count. Throws InputError (`sprig: error: ...`) naming a label's font file when
/// it does not exist, std::runtime_error when the text cannot be rasterized. Cost: the
/// glyphs' pixels.
void drawLabels(Image& image, const std::vector<TextLabel>& labels, const Camera& camera);

}  // namespace sprig::render
