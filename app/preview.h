#pragma once
/// Skeleton previews through render/: one image, or a strip of growth stages sharing one camera.

#include <string>
#include <vector>

#include "app/species.h"
#include "core/image.h"
#include "lsystem/skeleton.h"

namespace sprig {

/// Renders skeleton with the species' render settings, the camera framed on frameBox
/// (pass the final stage's bounds so every stage of a sequence shares one camera).
/// Cost: about width*height*samples*3 rays.
Image renderSkeletonImage(const lsystem::Skeleton& skeleton, const SpeciesRender& look, const DBox3& frameBox,
                                  int width, int height, const std::string& label);

/// Renders each skeleton into a cellWidth x height cell, left to right, all framed on
/// frameBox, and returns the strip (cellWidth * count wide).
Image renderGrowthStrip(const std::vector<const lsystem::Skeleton*>& stages, const SpeciesRender& look,
                                const DBox3& frameBox, int cellWidth, int height, const std::string& label);

/// The box of a skeleton as the camera should frame it (a unit box around the origin when empty).
DBox3 framingBox(const lsystem::Skeleton& skeleton);

}  // namespace sprig
