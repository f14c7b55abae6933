#pragma once
/// A rigid body set down on a horizontal plane, as a shell lies on a table: the stable pose
/// it reaches by rolling downhill from a pose it is put down in.
///
/// A body resting on a plane touches it at its lowest points; the height of its centre of
/// mass c above the plane, with up the plane's normal u in the body's frame, is
/// h(u) = c·u − min_p p·u over the body's points p (the support function of c − body). A
/// pose is stable where h is at a local minimum over the unit sphere of u: every small
/// tilt raises the centre of mass (the centre lies over the convex hull's face, edge or
/// vertex the body stands on). `restingUp` finds the minimum nearest a guess by a pattern
/// search on the sphere, so "aperture up" becomes the pose a shell put down aperture up
/// rolls into. Deterministic: no randomness, a fixed order of trial directions.

#include <span>

#include <glm/mat3x3.hpp>

#include "core/mesh.h"
#include "core/types.h"

namespace sprig::organisms {

/// The centre of mass of the solid a closed mesh bounds (uniform density; divergence
/// theorem over its triangles); the mean of its vertices when the enclosed volume is zero
/// (an open or flat mesh). {0,0,0} for a mesh without vertices.
DVec3 volumeCentroid(const Mesh& mesh);

/// Height of centre above the plane under points when up (unit) points away from it:
/// centre·up − min over points of p·up.
double restingHeight(std::span<const Vec3> points, const DVec3& centre, const DVec3& up);

/// The up direction (unit, in the points' frame) of the stable resting pose nearest
/// upGuess: a local minimum of restingHeight over unit vectors, reached by a pattern search
/// (steps of 0.05 rad, so the search rolls as the body would and never jumps a ridge
/// between stable poses wider than that, halved down to 1e-6 rad; eight trial directions). upGuess
/// must not be zero; points must not be empty.
DVec3 restingUp(std::span<const Vec3> points, const DVec3& centre, const DVec3& upGuess);

/// The rotation that turns up (unit) to +y and the part of forward perpendicular to up to
/// +x (any perpendicular direction when forward is parallel to up): a body at rest, turned
/// so that forward lies along the image's horizontal when seen from +z.
glm::dmat3 uprightRotation(const DVec3& up, const DVec3& forward);

}  // namespace sprig::organisms
