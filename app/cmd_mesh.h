#pragma once
/// `sprig mesh SPECIES -o OUT.{ply,obj,glb} [--cell SIZE]` (app/cmd_mesh.cpp).

#include "app/commands.h"

namespace sprig {

/// Registers `sprig mesh`: polygonizes the surface of a species of any kind at a stage
/// (app/model.h, blobtree/polygonize.h) and writes the mesh atomically (core/mesh_io.h),
/// printing the triangle count and the time.
void addMeshCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run);

}  // namespace sprig
