/* Small holes filled in the volume, and a watertight closure, before the mesh is extracted.
 *
 * A hole in the mesh is a place where some corner of a cell was never observed (a fold no view
 * reached, a dark stripe that did not decode). fusion_fill_holes diffuses the signed distance
 * into unobserved voxels from their observed neighbours, one voxel layer per pass, so a hole up
 * to 2 x passes voxels across closes with a smooth membrane (volumetric diffusion, Davis et al.
 * 2002). fusion_close_watertight then decides every voxel still unobserved: outside when it can
 * be reached from the grid's sides or top (one pass: sideways or down only) through passages
 * wider than the widest hole, without crossing the observed inside of the object or the table
 * plane; inside otherwise; everything at or below the table plane outside. Marching cubes over
 * the whole grid then gives a closed surface (the object closed at the table). */
#include "fusion_grid.h"
#include "mem.h"

#include <errno.h>
#include <string.h>

/* Bitmaps, one bit a voxel: "filled in this pass" during diffusion; during the closure the
 * voxels outside may pass through, and two scratch maps for the flood and its opening. */

static size_t grid_voxels(struct fusion_volume *vol)
{
    return (size_t)vol->dims[0] * vol->dims[1] * vol->dims[2];
}

static int bit(const uint8_t *map, size_t i)
{
    return (map[i >> 3] >> (i & 7u)) & 1u;
}

static void set_bit(uint8_t *map, size_t i, int on)
{
    if (on)
        map[i >> 3] |= (uint8_t)(1u << (i & 7u));
    else
        map[i >> 3] &= (uint8_t) ~(1u << (i & 7u));
}

static int marked(struct fusion_volume *vol, size_t i)
{
    return bit(vol->mark, i);
}

static void set_mark(struct fusion_volume *vol, size_t i)
{
    set_bit(vol->mark, i, 1);
}

static void clear_marks(struct fusion_volume *vol)
{
    mem_fill(vol->mark, 0, (grid_voxels(vol) + 7) / 8);
}

/* The six neighbours of (x, y, z) inside the grid: their indices, @retval how many. */
static int neighbours(struct fusion_volume *vol, uint32_t x, uint32_t y, uint32_t z, size_t out[6])
{
    const uint32_t *d = vol->dims;
    int n = 0;
    if (x > 0)
        out[n++] = vidx(vol, x - 1, y, z);
    if (x + 1 < d[0])
        out[n++] = vidx(vol, x + 1, y, z);
    if (y > 0)
        out[n++] = vidx(vol, x, y - 1, z);
    if (y + 1 < d[1])
        out[n++] = vidx(vol, x, y + 1, z);
    if (z > 0)
        out[n++] = vidx(vol, x, y, z - 1);
    if (z + 1 < d[2])
        out[n++] = vidx(vol, x, y, z + 1);
    return n;
}

/* One diffusion pass: every unobserved voxel next to a known one (observed, or filled by an
 * earlier pass) takes the mean distance and colour of its known neighbours. @retval voxels
 * filled */
static uint32_t diffuse_once(struct fusion_volume *vol)
{
    const uint32_t *d = vol->dims;
    uint32_t filled = 0;
    clear_marks(vol);
    for (uint32_t z = 0; z < d[2]; z++)
        for (uint32_t y = 0; y < d[1]; y++)
            for (uint32_t x = 0; x < d[0]; x++) {
                size_t i = vidx(vol, x, y, z), nb[6];
                if (vol->grid[i].weight != 0)
                    continue;
                int n = neighbours(vol, x, y, z, nb);
                for (int k = 0; k < n; k++)
                    if (vol->grid[nb[k]].weight != 0) { /* marked ones are still unobserved */
                        set_mark(vol, i); /* filled in this pass: no source for its neighbours */
                        break;
                    }
            }
    for (uint32_t z = 0; z < d[2]; z++)
        for (uint32_t y = 0; y < d[1]; y++)
            for (uint32_t x = 0; x < d[0]; x++) {
                size_t i = vidx(vol, x, y, z), nb[6];
                if (!marked(vol, i))
                    continue;
                int n = neighbours(vol, x, y, z, nb), used = 0;
                double sdf = 0.0, rgb[3] = {0, 0, 0};
                int coloured = 0;
                for (int k = 0; k < n; k++) {
                    const struct voxel *v = &vol->grid[nb[k]];
                    if (v->weight == 0 || marked(vol, nb[k]))
                        continue;
                    sdf += v->sdf;
                    for (int c = 0; c < 3 && v->colour_weight > 0; c++)
                        rgb[c] += v->rgb[c];
                    coloured += v->colour_weight > 0;
                    used++;
                }
                struct voxel *v = &vol->grid[i];
                v->sdf = (int16_t)lround(sdf / used);
                for (int c = 0; c < 3; c++) /* the colour of the neighbours that have one */
                    v->rgb[c] = (uint8_t)lround(coloured ? rgb[c] / coloured : 0.0);
                v->weight = 1; /* the least weight there is: any observation outweighs it */
                v->colour_weight = coloured ? COLOUR_BEST_EFFORT : 0;
                filled++;
            }
    return filled;
}

int fusion_fill_holes(struct fusion_volume *vol, double max_hole_mm, uint32_t *filled)
{
    *filled = 0;
    if (vol->dims[0] == 0)
        return -EINVAL;
    /* a hole closes from both sides: half its width in layers */
    uint32_t passes = (uint32_t)ceil(0.5 * max_hole_mm / vol->p.voxel_mm);
    for (uint32_t p = 0; p < passes; p++)
        *filled += diffuse_once(vol);
    return 0;
}

/* The height of voxel layer @p z above the table plane (object frame z, mm). */
static double layer_height(struct fusion_volume *vol, uint32_t z)
{
    return vol->origin.z + z * vol->p.voxel_mm;
}

/* A voxel outside can pass through: not observed inside, above the table plane. */
static int passable(struct fusion_volume *vol, size_t i, uint32_t z)
{
    return layer_height(vol, z) > 0.0 && (vol->grid[i].weight == 0 || vol->grid[i].sdf > 0);
}

/* One axis of a separable box filter of half-width @p r on bitmap @p in into @p out: erosion
 * (every voxel of the window set; beyond the grid counts as set) or dilation (any set). */
static void box_filter(struct fusion_volume *vol, const uint8_t *in, uint8_t *out, int axis,
                       uint32_t r, int erode)
{
    const uint32_t *d = vol->dims;
    const uint32_t len = d[axis];
    uint32_t u_end = d[axis == 0 ? 1 : 0], w_end = d[axis == 2 ? 1 : 2];
    for (uint32_t w = 0; w < w_end; w++)
        for (uint32_t u = 0; u < u_end; u++) {
            /* the line along axis through (u, w) */
            uint32_t c[3];
            c[axis] = 0;
            c[axis == 0 ? 1 : 0] = u;
            c[axis == 2 ? 1 : 2] = w;
            size_t first = vidx(vol, c[0], c[1], c[2]);
            size_t step = axis == 0 ? 1 : axis == 1 ? d[0] : (size_t)d[0] * d[1];
            /* count of the voxels in the window that decide (unset for erosion, set for
             * dilation); the window of t is [t - r, t + r] */
            uint32_t count = 0;
            for (uint32_t t = 0; t < r && t < len; t++)
                count += bit(in, first + t * step) != erode;
            for (uint32_t t = 0; t < len; t++) {
                if (t + r < len)
                    count += bit(in, first + (t + r) * step) != erode;
                if (t > r)
                    count -= bit(in, first + (t - r - 1) * step) != erode;
                set_bit(out, first + t * step, erode ? count == 0 : count > 0);
            }
        }
}

/* Erode (or dilate) @p map in place by a cube of half-width @p r, through vol->scratch_b. */
static void box_3d(struct fusion_volume *vol, uint8_t *map, uint32_t r, int erode)
{
    box_filter(vol, map, vol->scratch_b, 0, r, erode);
    box_filter(vol, vol->scratch_b, map, 1, r, erode);
    box_filter(vol, map, vol->scratch_b, 2, r, erode);
    memcpy(map, vol->scratch_b, (grid_voxels(vol) + 7) / 8);
}

/* Flood @p flood from the grid's sides and top through the voxels set in @p through. With
 * @p down_only, by moves sideways or down, never up: the cameras of a one-pass scan look down
 * on the object, so what no camera saw under a surface (a belly between the legs, the inside of
 * an upturned cup) is taken as solid, while a pocket open to the side or the top is outside; a
 * second pass has seen the underside, so every direction. Sweeps in both directions until
 * nothing changes (no queue: the memory stays one bit a voxel). */
static void flood_from_outside(struct fusion_volume *vol, const uint8_t *through, uint8_t *flood,
                               int down_only)
{
    const uint32_t *d = vol->dims;
    mem_fill(flood, 0, (grid_voxels(vol) + 7) / 8);
    for (uint32_t z = 0; z < d[2]; z++)
        for (uint32_t y = 0; y < d[1]; y++)
            for (uint32_t x = 0; x < d[0]; x++) {
                size_t i = vidx(vol, x, y, z);
                int side = x == 0 || y == 0 || x + 1 == d[0] || y + 1 == d[1] || z + 1 == d[2];
                set_bit(flood, i, side && bit(through, i));
            }
    for (int changed = 1; changed;) {
        changed = 0;
        for (int dir = 0; dir < 2; dir++)
            for (uint32_t k = 0; k < d[2]; k++) {
                uint32_t z = dir == 0 ? k : d[2] - 1 - k;
                for (uint32_t j = 0; j < d[1]; j++) {
                    uint32_t y = dir == 0 ? j : d[1] - 1 - j;
                    for (uint32_t m = 0; m < d[0]; m++) {
                        uint32_t x = dir == 0 ? m : d[0] - 1 - m;
                        size_t i = vidx(vol, x, y, z), nb[6];
                        if (bit(flood, i) || !bit(through, i))
                            continue;
                        int n = neighbours(vol, x, y, z, nb);
                        for (int q = 0; q < n; q++)
                            if (bit(flood, nb[q]) &&
                                !(down_only && z > 0 && nb[q] == vidx(vol, x, y, z - 1))) {
                                set_bit(flood, i, 1);
                                changed = 1;
                                break;
                            }
                    }
                }
            }
    }
}

/* The outside, in vol->mark: the flood from outside through the passable voxels opened by
 * @p r voxels (eroded, flooded, dilated back), so that it cannot leak into the object through
 * a hole narrower than 2 r + 1 voxels. */
static void find_outside(struct fusion_volume *vol, uint32_t r, int down_only)
{
    const uint32_t *d = vol->dims;
    for (uint32_t z = 0; z < d[2]; z++)
        for (uint32_t y = 0; y < d[1]; y++)
            for (uint32_t x = 0; x < d[0]; x++)
                set_bit(vol->mark, vidx(vol, x, y, z), passable(vol, vidx(vol, x, y, z), z));
    memcpy(vol->scratch_a, vol->mark, (grid_voxels(vol) + 7) / 8);
    box_3d(vol, vol->scratch_a, r, 1);
    flood_from_outside(vol, vol->scratch_a, vol->scratch_b, down_only);
    memcpy(vol->scratch_a, vol->scratch_b, (grid_voxels(vol) + 7) / 8);
    box_3d(vol, vol->scratch_a, r, 0);
    size_t n = grid_voxels(vol);
    for (size_t i = 0; i < (n + 7) / 8; i++)
        vol->mark[i] &= vol->scratch_a[i];
}

int fusion_close_watertight(struct fusion_volume *vol, double max_hole_mm, int one_pass,
                            uint32_t *inside)
{
    const uint32_t *d = vol->dims;
    const int16_t out_sdf = 32767, in_sdf = -32767;
    *inside = 0;
    if (d[0] == 0)
        return -EINVAL;
    find_outside(vol, (uint32_t)ceil(0.5 * max_hole_mm / vol->p.voxel_mm), one_pass);
    for (uint32_t z = 0; z < d[2]; z++)
        for (uint32_t y = 0; y < d[1]; y++)
            for (uint32_t x = 0; x < d[0]; x++) {
                size_t i = vidx(vol, x, y, z);
                struct voxel *v = &vol->grid[i];
                int border =
                    x == 0 || y == 0 || z == 0 || x + 1 == d[0] || y + 1 == d[1] || z + 1 == d[2];
                double h = layer_height(vol, z);
                if (h <= 0.0 || border) { /* the table plane and the grid's walls close it */
                    double below = -h / vol->p.truncation_mm * 32767.0;
                    v->sdf =
                        h <= 0.0 && !border && below < out_sdf ? (int16_t)lround(below) : out_sdf;
                    if (v->weight == 0)
                        v->weight = 1;
                } else if (v->weight == 0 || (v->sdf > 0 && !marked(vol, i))) {
                    /* unseen, or seen empty but walled in (a bubble in a crack): decided */
                    *inside += !marked(vol, i);
                    v->sdf = marked(vol, i) ? out_sdf : in_sdf;
                    v->weight = v->weight == 0 ? 1 : v->weight;
                }
            }
    return 0;
}
