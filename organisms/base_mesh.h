#pragma once
/// Built-in control meshes for organisms: a cube-sphere, torus, cylinder, plane and a
/// surface of revolution. Every mesh is made of quads (caps of cylinders and revolutions
/// are one polygon each), counter-clockwise seen from outside, with shared vertices, so the
/// closed ones are closed manifolds and Catmull-Clark keeps them closed.

#include <functional>

#include "organisms/subdivision.h"

namespace sprig::organisms {

/// A cube whose faces are n x n quads, its vertices pushed onto the sphere of radius r
/// about the origin: 6 n^2 quads, 6 n^2 + 2 vertices, closed; valence-3 vertices at the
/// cube's corners only.
ControlMesh cubeSphere(float radius, int n);

/// A torus about the y axis: `around` quads along the major circle by `across` along the
/// tube. Closed, every vertex regular.
ControlMesh torus(float majorRadius, float minorRadius, int around, int across);

/// A cylinder about the y axis from y = 0 to y = height: `around` x `rings` quads, plus a
/// polygon cap at each end when caps (closed), else open at both ends.
ControlMesh cylinder(float radius, float height, int around, int rings, bool caps);

/// A square in the xz plane centred at the origin, normal +y: n x n quads, open.
ControlMesh plane(float size, int n);

/// The surface swept by the profile radius(t) about the y axis, t from t0 to t1 along y
/// (y = t): `around` x `rings` quads, with a polygon cap at an end whose radius is not 0
/// (a radius of 0 there closes the end at one pole vertex). Throws std::invalid_argument
/// when a radius is negative or not finite.
ControlMesh revolution(const std::function<double(double)>& radius, double t0, double t1, int around, int rings);

}  // namespace sprig::organisms
