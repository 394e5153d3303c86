/* The fusion grid as the fusion's own files share it (fusion.c, fusion_close.c): not for
 * other modules, which go through fusion.h. */
#ifndef FUSION_GRID_H
#define FUSION_GRID_H

#include "fusion.h"
#include "vec3.h"

/* 8 bytes: distance in units of truncation / 32767, weight in thousandths, colour, and the
 * colour's own weight in 1/32 (it saturates at ~8: a voxel's colour stops changing once about
 * eight good views agree). The colour has its own weight because a colour estimate can be
 * unreliable (a highlight, a grazing light) where the geometry is fine. */
struct voxel {
    int16_t sdf;
    uint16_t weight;
    uint8_t rgb[3];
    uint8_t colour_weight;
};
_Static_assert(sizeof(struct voxel) == 8, "voxel layout");

#define WEIGHT_SCALE 1000.0
#define COLOUR_WEIGHT_SCALE 32.0
#define COLOUR_BEST_EFFORT 1u /* colour_weight of a voxel coloured by weightless estimates only */

extern struct voxel fusion_grid[FUSION_MAX_VOXELS];

/* The grid's parameters, dimensions and where voxel (0, 0, 0) is (object frame, mm). */
struct fusion_state {
    struct fusion_params p;
    uint32_t dims[3];
    vec3 origin;
};
extern struct fusion_state fusion_vol;

static inline size_t vidx(uint32_t x, uint32_t y, uint32_t z)
{
    return ((size_t)z * fusion_vol.dims[1] + y) * fusion_vol.dims[0] + x;
}

#endif
