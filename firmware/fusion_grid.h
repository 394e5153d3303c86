/* What the fusion's own files share of the grid (fusion.c, fusion_close.c): not for other
 * modules, which go through fusion.h. */
#ifndef FUSION_GRID_H
#define FUSION_GRID_H

#include "fusion.h"
#include "vec3.h"

_Static_assert(sizeof(struct voxel) == 8, "voxel layout");

#define WEIGHT_SCALE 1000.0
#define COLOUR_WEIGHT_SCALE 32.0
#define COLOUR_BEST_EFFORT 1u /* colour_weight of a voxel coloured by weightless estimates only */

static inline size_t vidx(const struct fusion_volume *vol, uint32_t x, uint32_t y, uint32_t z)
{
    return ((size_t)z * vol->dims[1] + y) * vol->dims[0] + x;
}

#endif
