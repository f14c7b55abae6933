#pragma once
/// Particle tools on a layered solid's visible surface (Cutler et al., "A procedural approach
/// to authoring solid models", §3.2 and §5.3: the paper's DIRT, WASH, ERODE and LICHEN).
///
/// A particle system is an initialization, a motion and an action:
/// - initialization: vertical fall. A particle starts at a uniformly random point of the
///   horizontal footprint of the surface's bounding box and falls straight down (along
///   −up) onto the first visible face it meets; one that meets none is lost.
/// - motion: the paper's CLINGING. At the face under the particle with outward normal n, if
///   n·g > cos(falling angle) (g = −up: the face looks down steeply enough) the particle
///   drips: it falls straight down from there onto the next face below, or is lost.
///   Otherwise it moves along the surface by one step in the direction of gravity projected
///   onto the face's plane, then back onto the surface (the nearest point of the visible
///   faces). On a face within 1° of level, or where a step moves it by less than a tenth of
///   a step (a crease it cannot leave), it comes to rest and its life ends there.
/// - action, at the landing point and after every step: wash blends the face colour of the
///   vertices within `radius` back toward their material's colour (the paper's
///   REMOVE_DIRT, with `strength`·(1 − d/radius) per step); lichen blends them toward the
///   lichen colour by `strength`·(1 − d/radius)·(n·up) on faces with n·up ≥ cos(top_angle)
///   (top-facing); erode removes a sphere of `radius` of material where the particle's life
///   ends (all spheres at once, by solids::cutByField, as polish subtracts).
/// Only vertices of visible faces of the affected materials change colour; erode removes
/// only tetrahedra of affected materials.
///
/// Particle i draws its random numbers from a generator seeded with (seed, i); paths are
/// computed in parallel (they depend on the geometry alone) in batches, and actions applied
/// in particle order, so the result is the same bytes at any thread count.
/// Units: metres, seconds; a particle moves at `speed` along the surface, in steps of
/// `step`, for `life` seconds (life·speed/step steps at most).

#include <cstdint>
#include <vector>

#include "solids/material.h"
#include "solids/solid.h"

namespace sprig::solids {

/// Options of dirt: an even layer of colour on the visible surface.
struct DirtOptions {
  Vec3 color{0.5f};              ///< linear RGB (the paper's { 0.5 0.5 0.5 })
  double amount = 1.0;           ///< blend weight in [0, 1]
  std::vector<uint16_t> affects; ///< material ids; empty = every material
};

/// Which particle tool.
enum class ParticleTool { Wash, Erode, Lichen };

/// Options of wash, erode and lichen (defaults: particleDefaults).
struct ParticleOptions {
  ParticleTool tool = ParticleTool::Wash;
  int particles = 10000;          ///< the paper's num_particles
  double life = 1.0;              ///< seconds (the paper's particle_life)
  double speed = 1.0;             ///< m/s along the surface
  double step = 0;                ///< m; 0 = half the radius
  double fallingAngleDeg = 60;    ///< CLINGING's falling angle, degrees from straight down
  double radius = 0.1;            ///< m: action radius (wash, lichen) or eroded sphere (erode)
  double strength = 0.01;         ///< blend weight per step at the particle (wash, lichen)
  /// wash: rivulets. Each step turns sideways (never uphill, at most 45°) toward cleaner
  /// surface by attraction·radius·|lateral gradient of the tint amount|; 0 = the paper's
  /// CLINGING. Tints change between batches of 4,096 particles, so later particles follow
  /// the tracks earlier ones washed.
  double attraction = 0;
  /// wash: meandering. Each step also turns sideways (never uphill, at most 45° with
  /// attraction together) by meander·(the part across the fall line of a seeded vector noise
  /// of position at scale meanderScale): one smooth field for every drop, so drops that
  /// pass one place turn alike and their tracks wander, merge and part irregularly, as rain
  /// on a rough stone does (the statue's primitives are smooth); 0 = off.
  double meander = 0;
  double meanderScale = 0.1;      ///< m: the wavelength of the meander noise is about this
  Vec3 color{0.0f};               ///< lichen colour, linear RGB
  double topAngleDeg = 60;        ///< lichen: faces within this angle of straight up grow it
  std::vector<uint16_t> affects;  ///< material ids; empty = every material
  uint64_t seed = 0;
  DVec3 up{0, 1, 0};              ///< gravity is −up; also the ground for erode's loose pieces
};

/// The defaults of a tool: wash 10,000 particles (the paper's WASH default; its gargoyle
/// script used 200,000), life 1 s, speed 1 m/s, radius 0.1 m (REMOVE_DIRT's), strength 0.01 (each point of a level top is under
/// about 300 landings of 10,000 particles per m², so about a third of the dirt stays there);
/// erode 2,000 particles (the gargoyle script's), radius 0.03 m; lichen 40,000 particles
/// (the gargoyle script's), speed 0.05 m/s ("minimal particle motion"), radius 0.05 m,
/// strength 0.1, colour (0.32, 0.36, 0.12) (a yellow-green crustose lichen).
ParticleOptions particleDefaults(ParticleTool tool);

/// What a particle tool did.
struct ParticleStats {
  size_t landed = 0;     ///< particles that reached the surface
  size_t steps = 0;      ///< surface steps over all particles
  size_t drips = 0;      ///< drips (falls from a downward face)
  size_t lost = 0;       ///< particles that fell off the model
  size_t vertexHits = 0; ///< (vertex, step) actions applied
  size_t removed = 0;    ///< erode: tetrahedra removed (inside spheres, and loose pieces)
  /// Per vertex of the mesh (before erode changes it): how many particle steps acted on it.
  std::vector<uint32_t> passes;
};

/// Blends the visible vertices of the affected materials toward color by amount (the
/// paper's DIRT: an even layer). Returns how many vertices it tinted.
size_t dirt(TetMesh& mesh, const std::vector<Material>& materials, const DirtOptions& options);

/// Runs a particle tool (above). Throws std::invalid_argument for non-finite or
/// out-of-range options or an `affects` id with no material.
ParticleStats runParticles(TetMesh& mesh, const std::vector<Material>& materials, const ParticleOptions& options);

}  // namespace sprig::solids
