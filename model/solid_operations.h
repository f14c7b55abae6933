#pragma once
/// The `operations:` list of a `kind: solid` species (Cutler et al., "A procedural approach to
/// authoring solid models", §3.1 and §5): simulation tools applied in order to the solid's
/// tetrahedral mesh after meshing. A replayable history: the same list at a finer grid
/// replays the same operations on the finer model (forces are totals, not per vertex).
///
/// ```
///   solid:
///     ...
///     operations:
///       - hammer: {position: [0.5, 0, 0], orientation: [-1, 0, 0], magnitude: 1e7, size: 0.1, affects: [fired_clay]}
///       - displace: {moving: [wood], offset: [0, 0.02, 0]}
/// ```
/// Keys, defaults and units: docs/SOLIDS.md ("Simulation operators"). Unknown tools and
/// keys are errors at their file:line:col with "did you mean".

#include <string>
#include <variant>
#include <vector>

#include "core/diagnostics.h"
#include "model/yaml_reader.h"
#include "solids/operators.h"
#include "solids/particles.h"

namespace sprig {

/// One entry of `operations:`: the tool, its options, and where it was written.
struct SolidOperation {
  std::string tool;  ///< "hammer", "displace", "polish", "dirt", "wash", "erode" or "lichen"
  SourceLoc loc;
  std::string sourceLine;
  std::variant<solids::HammerOptions, solids::DisplaceOptions, solids::PolishOptions, solids::DirtOptions,
               solids::ParticleOptions>
      options;
};

/// Reads an `operations:` sequence. Material names resolve against materials (built-ins
/// are appended to it when first named); every error goes to diags.
std::vector<SolidOperation> readSolidOperations(const YNode& list, solids::MaterialTable& materials, DiagnosticList& diags);

/// Applies operations to mesh in order, then drops the vertices no tetrahedron uses any
/// more. An operation that fails (say, a part of the mesh nothing holds) throws InputError
/// at its entry.
void applySolidOperations(solids::TetMesh& mesh, const std::vector<solids::Material>& materials,
                          const std::vector<SolidOperation>& operations);

/// Applies one operation (as applySolidOperations does, without dropping unused vertices).
void applySolidOperation(solids::TetMesh& mesh, const std::vector<solids::Material>& materials, const SolidOperation& op);

}  // namespace sprig
