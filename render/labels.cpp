#include "render/labels.h"

#include <cmath>

namespace sprig::render {

void drawLabels(Image& image, const std::vector<TextLabel>& labels, const Camera& camera) {
  for (const TextLabel& l : labels) {
    Vec2 film;
    if (l.text.empty() || !camera.project(l.position, image.width, image.height, film)) continue;
    if (!std::isfinite(film.x) || !std::isfinite(film.y) || std::fabs(film.x) > 1e6f || std::fabs(film.y) > 1e6f) continue;
    drawText(image, static_cast<int>(std::floor(film.x)), static_cast<int>(std::floor(film.y)), l.text, l.color, l.fontFile,
             l.sizePixels);
  }
}

}  // namespace sprig::render
