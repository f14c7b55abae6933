// Probe for module_boundaries: render/ must not see lsystem/ (render takes neutral
// geometry only). This file must fail to compile.
#include "lsystem/skeleton.h"

int sprigBoundaryForbidden() { return 0; }
