// Control for module_boundaries: render/ may include its own headers and those of
// blobtree/, textures/ and core/. This file must compile.
#include "blobtree/compiled.h"
#include "core/mesh.h"
#include "render/scene.h"
#include "textures/registry.h"

int sprigBoundaryAllowed() { return 0; }
