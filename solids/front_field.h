#pragma once
/// Distance fields grown by a moving front (Cutler et al. §2.4, Fig. 3; Sethian, "Level Set
/// Methods and Fast Marching Methods", 2nd ed., 1999, ch. 8).
///
/// A front starts at a field's zero set and moves along its normal with speed v(x) > 0; the
/// new field value is the arrival time T, the solution of the eikonal equation |∇T|·v = 1
/// (negative inside, positive outside). Layers are ranges of T, so a layer is v times as
/// thick where the speed is v: the paper's interface velocity. With v = 1 the front
/// re-measures Euclidean distance from the zero set, which is what `from_volume_surface`
/// needs of a combination of fields that is not itself a distance.
///
/// OpenVDB 10 has fast sweeping for unit speed only, so this is a fast-marching solver of
/// Sprig's own: first-order upwind differences on a lattice at the caller's cell, nodes
/// accepted in order of T from a binary heap (ties by node index, so the result is the
/// same at any thread count). Nodes next to the zero set start at d/|∇d|/v.
///
/// Speeds come from a procedure of the point (SpeedFn, evaluated at every lattice node) or
/// are painted on the surface: evaluated only at the nodes next to the zero set, carried
/// along the surface normals by a unit-speed march that extends them (Adalsteinsson and
/// Sethian, "The fast construction of extension velocities in level set methods", JCP 148,
/// 1999), and then the front runs at them, so a painted value sets the thickness of the
/// layers above that part of the surface. Where a fast region borders a slow one the
/// fast front spills sideways into the slow side, as the eikonal equation says it must.

#include <functional>
#include <vector>

#include "solids/distance_field.h"

namespace sprig::solids {

/// Speeds at points (one per point, written into out). Must be thread-safe.
using SpeedFn = std::function<void(const std::vector<Vec3>& points, std::vector<float>& out)>;

/// The same speed v everywhere.
SpeedFn uniformSpeed(float v);

/// Speeds below this are raised to it (a front that stops would never fill the layers).
constexpr float kMinSpeed = 0.01f;

/// child with every value divided by the constant speed v > 0 (exact: T = d / v).
FieldPtr constantSpeedField(FieldPtr child, double speed);

/// The arrival time of a front leaving child's zero set with speed(x) at every point;
/// maxSpeed bounds the speed (the field reaches maxSpeed·T world units at most).
/// painted = true: speed is asked only next to the zero set and extended from there.
FieldPtr frontField(FieldPtr child, SpeedFn speed, double maxSpeed, bool painted);

/// Arrival times on a lattice (x fastest): d are the starting field's values at the nodes,
/// speed the speeds (all nodes; painted: valid only at nodes next to the zero set, the rest
/// is overwritten by the extension; speeds below kMinSpeed are raised to it, non-finite
/// ones taken as 1), h the lattice step. Values beyond limit (in T) are
/// left at ±limit. Exposed for tests.
std::vector<float> marchFront(const std::vector<float>& d, std::vector<float>& speed, const std::array<int, 3>& dims,
                              double h, double limit, bool painted);

}  // namespace sprig::solids
