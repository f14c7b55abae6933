#pragma once
/// Private: all field math of the BlobTree in one include: primitives (primitive.h), PCM
/// (pcm.h), warps (warp.h) and the geometric helpers behind their bounds (geometry.h).

#include "blobtree/detail/geometry.h"
#include "blobtree/detail/pcm.h"
#include "blobtree/detail/primitive.h"
#include "blobtree/detail/warp.h"
