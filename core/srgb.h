#pragma once
/// The sRGB transfer curve (IEC 61966-2-1), in float and in double precision.
///
/// Both overloads are the same formula; they exist because Sprig's files were made with
/// both precisions and must keep their bytes: rendered images, mesh colors and `#rrggbb`
/// species colors go through float, procedural and image textures (and texture maps)
/// through double. Pass the precision you mean explicitly (a float argument picks the
/// float overload), because the two can differ in the last bit.

namespace sprig {

/// sRGB-encoded value of a linear value, the input clamped to [0, 1] first (std::clamp:
/// -0 stays -0 and NaN stays NaN). 1 encodes as 0.99999994f, the float formula's value.
float linearToSrgb(float linear);
/// sRGB-encoded value of a linear value clamped to [0, 1] (double formula).
double linearToSrgb(double linear);

/// Linear value of an sRGB-encoded value in [0, 1]; no clamping.
float srgbToLinear(float encoded);
/// Linear value of an sRGB-encoded value in [0, 1]; no clamping (double formula).
double srgbToLinear(double encoded);

}  // namespace sprig
