#pragma once
/// Interface velocity of a solid's distance field (Cutler et al. §2.4, Fig. 3), as written in
/// a species file, turned into a field wrapper (solids/front_field.h):
///
///   velocity: 2                                      # constant: every layer twice as thick
///   velocity: "1 + 2*turbulence"                     # a procedure of the point (x, y, z, noise, turbulence)
///   velocity: {expression: "1 + 0.5*sin(900*(x+y))", noise: {scale: 0.2, octaves: 4, seed: 1}, max: 1.5}
///   velocity: {painted: {low: 1, high: 3}}           # surface_mesh only: the mesh's vertex colours
///   velocity: {painted: {low: 1, high: 3, image: {file: ring.png, axis: [0, 1, 0]}}}  # or an image map
///
/// In an expression `noise` is Perlin noise in [-1, 1] at the point divided by the noise
/// scale and `turbulence` the turbulence (sum of |noise| over the octaves) in [0, 1] there
/// (textures/noise.h); the rest is the grammar's expression language (docs/GRAMMAR.md),
/// never compiled code. `max` bounds the speed (the default grid's margin and the front's
/// band); by default it is measured on a 32³ lattice over the field's box, and a value
/// that is not positive and finite there is an error at the expression. A painted speed is
/// low + (high − low)·luminance of the mesh's vertex colours, averaged over the vertices
/// within about 1/24 of the mesh's size of each point of the surface (the nearest vertex
/// where none is that near), carried outward along the normals. With `image`, the paint is
/// the luminance of an image map laid on the plane perpendicular to `axis` as extrude_2d
/// lays its image (solids/extrude_field.h: columns along u, rows along v, the top row at
/// the −v edge), `size` [u, v] and `center` [u, v] defaulting to the mesh's extent on that
/// plane; read bilinearly, clamped at the image's edges, and projected along the axis
/// onto the surface (a decal, as a painter's top view).

#include <functional>
#include <optional>

#include "core/diagnostics.h"
#include "core/polymesh.h"
#include "model/yaml_reader.h"
#include "solids/distance_field.h"

namespace sprig {

/// Wraps a field in its velocity.
using VelocityWrap = std::function<solids::FieldPtr(solids::FieldPtr)>;

/// Reads the `velocity` value at node. mesh: the surface mesh (painted velocity needs its
/// colours or its extent), or nullptr where painting is not possible. redistance: the child
/// is not a distance (from_volume_surface), so even a constant speed runs the front.
/// policy: where an image map may come from (nullptr: none may). Returns nullopt with
/// errors added to diags.
std::optional<VelocityWrap> readVelocity(const YNode& node, DiagnosticList& diags, const PolyMesh* mesh, bool redistance,
                                         const PathPolicy* policy = nullptr);

/// The identity velocity of from_volume_surface: a unit-speed front that measures
/// distance from the zero set again.
solids::FieldPtr redistanced(solids::FieldPtr child);

}  // namespace sprig
