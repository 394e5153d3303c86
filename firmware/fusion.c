/* Truncated signed distance fusion in a voxel grid (struct fusion_volume), and marching cubes
 * over it. */
#include "fusion.h"
#include "fusion_grid.h"

#include "camray.h"
#include "lens.h"
#include "mc_table.h"
#include "mem.h"
#include "vec3.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#define NO_VERTEX 0xFFFFFFFFu

int fusion_dims(const struct fusion_params *p, uint32_t dims[3])
{
    double span[3] = {2.0 * p->radius_mm, 2.0 * p->radius_mm, p->top_mm - p->bottom_mm};
    for (int a = 0; a < 3; a++) {
        double d = span[a] / p->voxel_mm + 1.0;
        if (d < 2.0 || d > FUSION_MAX_DIM)
            return -E2BIG;
        dims[a] = (uint32_t)d;
    }
    if ((uint64_t)dims[0] * dims[1] * dims[2] > FUSION_MAX_VOXELS ||
        p->max_weight * WEIGHT_SCALE > 65535.0)
        return -E2BIG;
    return 0;
}

int fusion_begin(struct fusion_volume *vol, const struct fusion_params *p)
{
    int rc = fusion_dims(p, vol->dims);
    if (rc != 0)
        return rc;
    vol->p = *p;
    vol->origin = v3(p->centre_mm[0] - p->radius_mm, p->centre_mm[1] - p->radius_mm, p->bottom_mm);
    size_t grid_bytes = (size_t)vol->dims[0] * vol->dims[1] * vol->dims[2] * sizeof(vol->grid[0]);
    mem_fill(vol->grid, 0, grid_bytes);
    vol->mp.prepared = 0; /* an earlier model's mesh tables are no longer this one's */
    vol->grid_spent = 0;
    memset(&vol->outside, 0, sizeof(vol->outside));
    mc_table_build();
    return 0;
}

void *fusion_spend_grid(struct fusion_volume *vol, size_t *bytes)
{
    *bytes = 0;
    if (!vol->mp.prepared || !vol->mp.fits)
        return NULL;
    vol->grid_spent = 1;
    *bytes = sizeof(vol->grid);
    return vol->grid;
}

/* The rectangle of pixels a view's work covers: its valid pixels and a ring of one pixel
 * around them (within the image), x0 <= x < x1, y0 <= y < y1. The object fills a part of the
 * frame; the passes over pixels stay inside. */

/* @retval 0 when the view has no valid pixel */
static int find_rect(struct fusion_volume *vol, const struct decode_maps *m)
{
    const uint32_t w = m->width, h = m->height;
    uint32_t x0 = w, x1 = 0, y0 = h, y1 = 0;
    for (uint32_t y = 0; y < h; y++) {
        const uint8_t *row = m->reason + (size_t)y * w;
        const uint8_t *first = memchr(row, SCAN_VALID, w); /* SCAN_VALID is 0: a fast scan */
        if (first == NULL)
            continue;
        uint32_t last = w - 1;
        while (row[last] != SCAN_VALID)
            last--;
        x0 = (uint32_t)(first - row) < x0 ? (uint32_t)(first - row) : x0;
        x1 = last + 1 > x1 ? last + 1 : x1;
        y0 = y < y0 ? y : y0;
        y1 = y + 1;
    }
    if (x1 == 0)
        return 0;
    vol->rect.x0 = x0 > 0 ? x0 - 1 : 0;
    vol->rect.y0 = y0 > 0 ? y0 - 1 : 0;
    vol->rect.x1 = x1 < w ? x1 + 1 : w;
    vol->rect.y1 = y1 < h ? y1 + 1 : h;
    return 1;
}

/* City-block distance of each valid pixel to the nearest invalid one (two passes), capped.
 * Inside the rectangle only: its ring holds no valid pixel, so nothing outside is read. */
static void distance_to_edge(struct fusion_volume *vol, const struct decode_maps *m, uint16_t cap)
{
    const uint32_t w = m->width, h = m->height;
    for (uint32_t y = vol->rect.y0; y < vol->rect.y1; y++) {
        for (uint32_t x = vol->rect.x0; x < vol->rect.x1; x++) {
            size_t i = (size_t)y * w + x;
            uint16_t d = 0;
            if (m->reason[i] == SCAN_VALID) {
                d = cap;
                if (x > 0 && vol->edge_dist[i - 1] + 1 < d)
                    d = (uint16_t)(vol->edge_dist[i - 1] + 1);
                if (y > 0 && vol->edge_dist[i - w] + 1 < d)
                    d = (uint16_t)(vol->edge_dist[i - w] + 1);
                if (x == 0 || y == 0 || x + 1 == w || y + 1 == h)
                    d = 1;
            }
            vol->edge_dist[i] = d;
        }
    }
    for (uint32_t y = vol->rect.y1; y-- > vol->rect.y0;) {
        for (uint32_t x = vol->rect.x1; x-- > vol->rect.x0;) {
            size_t i = (size_t)y * w + x;
            if (x + 1 < w && vol->edge_dist[i + 1] + 1 < vol->edge_dist[i])
                vol->edge_dist[i] = (uint16_t)(vol->edge_dist[i + 1] + 1);
            if (y + 1 < h && vol->edge_dist[i + w] + 1 < vol->edge_dist[i])
                vol->edge_dist[i] = (uint16_t)(vol->edge_dist[i + w] + 1);
        }
    }
}

/* What the rows of a view's weights share (pixel_weights). */
struct weight_rows {
    struct fusion_volume *vol;
    const struct scan_calib *c;
    const struct decode_maps *m;
    const struct tri_range *r;
    struct camray rays;
    double fade;
    unsigned parts;
};

/* Part @p k of the image's rows: each valid pixel's weight, 0 for every other pixel (its own
 * pixels only); the rectangle's ring and the rows beyond it hold no valid pixel. */
static void weight_rows(void *arg, unsigned k)
{
    const struct weight_rows *p = arg;
    struct fusion_volume *vol = p->vol;
    const struct decode_maps *m = p->m;
    const uint32_t x0 = vol->rect.x0, x1 = vol->rect.x1;
    for (uint32_t y = m->height * k / p->parts; y < m->height * (k + 1u) / p->parts; y++) {
        float *row = &vol->weight_map[(size_t)y * m->width];
        if (y < vol->rect.y0 || y >= vol->rect.y1) {
            memset(row, 0, m->width * sizeof(*row));
            continue;
        }
        memset(row, 0, x0 * sizeof(*row));
        memset(row + x1, 0, (m->width - x1) * sizeof(*row));
        for (uint32_t x = x0; x < x1; x++) {
            size_t i = (size_t)y * m->width + x;
            row[x] = 0.0f;
            if (m->reason[i] != SCAN_VALID)
                continue;
            vec3 ray = v3_norm(camray_at(p->c, p->rays, x, y));
            vec3 n = v3(p->r->normal[3 * i], p->r->normal[3 * i + 1], p->r->normal[3 * i + 2]);
            double head_on = -v3_dot(n, ray), z = p->r->xyz_mm[3 * i + 2];
            double w = head_on * (600.0 / z) * (600.0 / z) * fmin(1.0, vol->edge_dist[i] / p->fade);
            row[x] = w >= vol->p.min_weight ? (float)w : 0.0f;
        }
    }
}

/* How much a pixel is trusted: head-on, close (finer sampling), and away from the view's edge,
 * where depth is least reliable and colour seams would show (Jost et al., boundary filtering).
 * The rows split across @p threads (NULL: this one).
 * @retval 0 when no pixel is valid */
static int pixel_weights(struct fusion_volume *vol, const struct hal_thread *threads,
                         const struct scan_calib *c, const struct decode_maps *m,
                         const struct tri_range *r)
{
    struct weight_rows p = {.vol = vol,
                            .c = c,
                            .m = m,
                            .r = r,
                            .rays =
                                camray_lookup(c), /* the table, where it is this calibration's */
                            .fade = vol->p.edge_fade_px > 0 ? (double)vol->p.edge_fade_px : 1.0,
                            .parts = hal_thread_parts(threads, 64)};
    if (!find_rect(vol, m)) {
        memset(vol->weight_map, 0, (size_t)m->width * m->height * sizeof(vol->weight_map[0]));
        return 0;
    }
    distance_to_edge(vol, m, (uint16_t)(vol->p.edge_fade_px > 0 ? vol->p.edge_fade_px : 1));
    hal_thread_run(threads, p.parts, weight_rows, &p);
    return 1;
}

const float *fusion_view_weights(struct fusion_volume *vol, const struct hal_thread *threads,
                                 const struct scan_calib *calib, const struct decode_maps *maps,
                                 const struct tri_range *range)
{
    return pixel_weights(vol, threads, calib, maps, range) ? vol->weight_map : NULL;
}

/* Blend colour @p rgb with weight @p cw into the voxel; a voxel no confident view has coloured
 * yet takes any estimate (weight 0: a best effort), so that every surface gets some colour.
 * colour_weight: 0 never coloured, COLOUR_BEST_EFFORT only best efforts, else the summed weight
 * x COLOUR_WEIGHT_SCALE. */
static void fuse_colour(struct voxel *vx, double cw, const uint8_t *rgb)
{
    double old_cw =
        vx->colour_weight > COLOUR_BEST_EFFORT ? vx->colour_weight / COLOUR_WEIGHT_SCALE : 0.0;
    double new_cw = old_cw + cw;
    if (new_cw <= 0.0) {
        memcpy(vx->rgb, rgb, 3);
        vx->colour_weight = COLOUR_BEST_EFFORT;
        return;
    }
    for (int k = 0; k < 3; k++)
        vx->rgb[k] = (uint8_t)((vx->rgb[k] * old_cw + rgb[k] * cw) / new_cw + 0.5);
    new_cw = fmin(new_cw * COLOUR_WEIGHT_SCALE, 255.0);
    vx->colour_weight = (uint8_t)fmax(new_cw + 0.5, COLOUR_BEST_EFFORT + 1);
}

static void fuse_voxel(struct fusion_volume *vol, struct voxel *vx, double sdf, double w, double cw,
                       const uint8_t *rgb)
{
    double trunc = vol->p.truncation_mm;
    if (sdf > trunc)
        sdf = trunc;
    double old_w = vx->weight / WEIGHT_SCALE, old_s = vx->sdf / 32767.0 * trunc;
    double new_w = old_w + w;
    double s = (old_s * old_w + sdf * w) / new_w;
    if (fabs(sdf) < trunc && cw >= 0.0) /* colour from near the surface, where there is one */
        fuse_colour(vx, cw, rgb);
    /* rounded half away from zero, as lround, without a libm call per voxel */
    double q = s / trunc * 32767.0;
    vx->sdf = (int16_t)(q >= 0.0 ? q + 0.5 : q - 0.5);
    vx->weight = (uint16_t)(fmin(new_w, vol->p.max_weight) * WEIGHT_SCALE + 0.5);
}

/* Voxels this view can change: those near its fused points. The grid is cut in blocks of
 * BLOCK^3 voxels; a block is marked when one of the view's points falls in it, and the marks
 * are then grown by as many blocks as the truncation band reaches, so that every voxel within
 * the band of a point is in a marked block (as Open3D's ScalableTSDFVolume touches only the
 * blocks of the current frame's points). Voxels farther in front of the surface would only be
 * told "empty", which costs a projection each and changes no surface. */
#define BLOCK FUSION_BLOCK

static size_t bidx(const uint32_t nb[3], uint32_t x, uint32_t y, uint32_t z)
{
    return ((size_t)z * nb[1] + y) * nb[0] + x;
}

void fusion_outside(const struct fusion_volume *vol, struct fusion_outside *out)
{
    *out = vol->outside;
}

#define TABLE_CLEARANCE_MM 5.0 /* nearer the table, a point beside the grid is the table's */

/* Is @p p (object frame) over the table, where the object stands (struct fusion_outside)? */
static int over_table(const struct fusion_params *fp, vec3 p)
{
    double r = fp->radius_mm;
    return p.z >= TABLE_CLEARANCE_MM && p.x * p.x + p.y * p.y <= 4.0 * r * r;
}

void fusion_outside_add(struct fusion_outside *o, const struct fusion_params *fp, vec3 p)
{
    const double xy[2] = {p.x, p.y};
    double dx = fabs(p.x - fp->centre_mm[0]), dy = fabs(p.y - fp->centre_mm[1]);
    double reach = dx > dy ? dx : dy;
    o->fused++;
    if (!over_table(fp, p))
        return;
    if (p.z > fp->top_mm) {
        o->above++;
        o->top_seen_mm = p.z > o->top_seen_mm ? p.z : o->top_seen_mm;
    }
    if (reach > fp->radius_mm) {
        o->beside++;
        o->reach_seen_mm = reach > o->reach_seen_mm ? reach : o->reach_seen_mm;
        for (int a = 0; a < 2; a++) {
            o->low_seen_mm[a] = xy[a] < o->low_seen_mm[a] ? xy[a] : o->low_seen_mm[a];
            o->high_seen_mm[a] = xy[a] > o->high_seen_mm[a] ? xy[a] : o->high_seen_mm[a];
        }
    }
}

/* @p part's counts into @p o: the counts added, the highest and widest points kept. */
static void fusion_outside_merge(struct fusion_outside *o, const struct fusion_outside *part)
{
    o->fused += part->fused;
    o->above += part->above;
    o->beside += part->beside;
    o->top_seen_mm = part->top_seen_mm > o->top_seen_mm ? part->top_seen_mm : o->top_seen_mm;
    o->reach_seen_mm =
        part->reach_seen_mm > o->reach_seen_mm ? part->reach_seen_mm : o->reach_seen_mm;
    for (int a = 0; a < 2; a++) {
        o->low_seen_mm[a] = fmin(o->low_seen_mm[a], part->low_seen_mm[a]);
        o->high_seen_mm[a] = fmax(o->high_seen_mm[a], part->high_seen_mm[a]);
    }
}

int fusion_outside_many(uint64_t n, uint64_t fused, uint64_t least)
{
    return n >= least && n * 1000 >= fused;
}

/* The square that holds @p p's and every point beside it (@p seen) with @p spare, its centre
 * moved from p's by whole voxels (the grid's voxels stay where they were) and its half side by
 * whole voxels with one to spare for the centre's rounding: @p fitted's radius and centre (its
 * top as fusion_fit grew it). Why: a person who puts the object near the table's rim (a
 * bunny 150 mm off the axis) had 69% of its points cut off, for a square about the axis holding it
 * was beyond the grid's limits where one about the object was not. @retval 0 @retval -E2BIG beyond
 * the limits all the same */
static int grown_off_axis(const struct fusion_params *p, const struct fusion_outside *seen,
                          double spare, struct fusion_params *fitted)
{
    double half = 0.0, mid[2];
    for (int a = 0; a < 2; a++) {
        double lo = fmin(p->centre_mm[a] - p->radius_mm, seen->low_seen_mm[a] - spare);
        double hi = fmax(p->centre_mm[a] + p->radius_mm, seen->high_seen_mm[a] + spare);
        mid[a] = 0.5 * (lo + hi);
        half = fmax(half, 0.5 * (hi - lo));
    }
    for (int a = 0; a < 2; a++)
        fitted->centre_mm[a] =
            p->centre_mm[a] + p->voxel_mm * round((mid[a] - p->centre_mm[a]) / p->voxel_mm);
    fitted->radius_mm =
        p->radius_mm + p->voxel_mm * ceil((half + p->voxel_mm - p->radius_mm) / p->voxel_mm);
    uint32_t dims[3];
    return fusion_dims(fitted, dims);
}

int fusion_fit(const struct fusion_params *p, const struct fusion_outside *seen,
               struct fusion_params *fitted)
{
    *fitted = *p;
    if (!p->fit_volume)
        return 0;
    double spare = p->truncation_mm + 2.0 * p->voxel_mm;
    int grown = 0;
    if (fusion_outside_many(seen->above, seen->fused, 8)) { /* each of them above top_mm */
        fitted->top_mm = seen->top_seen_mm + spare;
        grown = 1;
    }
    if (fusion_outside_many(seen->beside, seen->fused, 8)) { /* each beyond radius_mm */
        double voxels = ceil((seen->reach_seen_mm + spare - p->radius_mm) / p->voxel_mm);
        fitted->radius_mm = p->radius_mm + voxels * p->voxel_mm;
        grown = 1;
    }
    uint32_t dims[3];
    if (grown && fusion_dims(fitted, dims) != 0 && grown_off_axis(p, seen, spare, fitted) != 0) {
        *fitted = *p;
        return -E2BIG;
    }
    return grown;
}

uint32_t fusion_border_points(const struct fusion_params *fp,
                              const struct frame_xform *obj_from_cam, const struct decode_maps *m,
                              const struct tri_range *r)
{
    const uint32_t w = m->width, h = m->height;
    uint32_t n = 0;
    for (uint32_t k = 0; k < 2 * (w + h); k++) {
        /* top row, bottom row, left column, right column */
        uint32_t x = k < 2 * w ? k % w : k < 2 * w + h ? 0 : w - 1;
        uint32_t y = k < w ? 0 : k < 2 * w ? h - 1 : (k - 2 * w) % h;
        size_t i = (size_t)y * w + x;
        if (m->reason[i] == SCAN_VALID &&
            over_table(fp, frame_point(obj_from_cam, v3(r->xyz_mm[3 * i], r->xyz_mm[3 * i + 1],
                                                        r->xyz_mm[3 * i + 2]))))
            n++;
    }
    return n;
}

/* What the rows of a view's block marks share (mark_blocks), and each part's count of the
 * points beyond the grid and whether it marked a block. */
struct mark_rows {
    struct fusion_volume *vol;
    const struct frame_xform *obj_from_cam;
    const struct decode_maps *m;
    const struct tri_range *r;
    const uint32_t *nb;
    unsigned parts;
    struct fusion_outside outside[HAL_MAX_PARTS];
    int any[HAL_MAX_PARTS];
};

/* Part @p k of the rectangle's rows: the block of each fused point marked (parts may mark the
 * same block: each stores a 1, atomically), the points beyond the grid counted in its own. */
static void mark_rows(void *arg, unsigned k)
{
    struct mark_rows *p = arg;
    struct fusion_volume *vol = p->vol;
    const float *xyz = p->r->xyz_mm;
    const uint32_t *nb = p->nb, rows = vol->rect.y1 - vol->rect.y0;
    const double scale = 1.0 / (vol->p.voxel_mm * BLOCK);
    struct fusion_outside outside = {0};
    int any = 0;
    for (size_t y = vol->rect.y0 + rows * k / p->parts;
         y < vol->rect.y0 + rows * (k + 1u) / p->parts; y++) {
        for (size_t i = y * p->m->width + vol->rect.x0; i < y * p->m->width + vol->rect.x1; i++) {
            if (vol->weight_map[i] <= 0.0f)
                continue;
            vec3 p_obj =
                frame_point(p->obj_from_cam, v3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]));
            fusion_outside_add(&outside, &vol->p, p_obj);
            vec3 q = v3_sub(p_obj, vol->origin);
            double g[3] = {q.x * scale, q.y * scale, q.z * scale};
            uint32_t b[3];
            int inside = 1;
            for (int a = 0; a < 3; a++) {
                /* a point up to a block outside the grid: its band may reach in */
                inside = inside && g[a] >= -1.0 && g[a] < nb[a] + 1.0;
                b[a] = g[a] < 0.0 ? 0u : g[a] >= nb[a] ? nb[a] - 1u : (uint32_t)g[a];
            }
            if (inside) {
                __atomic_store_n(&vol->block_mark[bidx(nb, b[0], b[1], b[2])], 1, __ATOMIC_RELAXED);
                any = 1;
            }
        }
    }
    p->outside[k] = outside;
    p->any[k] = any;
}

/* Mark the blocks of the view's fused points, and count those beyond the grid; the rows split
 * across @p threads, their counts added (and their highest and widest points taken) after.
 * @retval 0 when the view has none */
static int mark_blocks(struct fusion_volume *vol, const struct hal_thread *threads,
                       const struct frame_xform *obj_from_cam, const struct decode_maps *m,
                       const struct tri_range *r, const uint32_t nb[3])
{
    static struct mark_rows p; /* a kilobyte of counts: one view is fused at a time */
    p = (struct mark_rows){.vol = vol,
                           .obj_from_cam = obj_from_cam,
                           .m = m,
                           .r = r,
                           .nb = nb,
                           .parts = hal_thread_parts(threads, HAL_MAX_PARTS)};
    memset(vol->block_mark, 0, (size_t)nb[0] * nb[1] * nb[2]);
    hal_thread_run(threads, p.parts, mark_rows, &p);
    int any = 0;
    for (unsigned k = 0; k < p.parts; k++) {
        any |= p.any[k];
        fusion_outside_merge(&vol->outside, &p.outside[k]);
    }
    return any;
}

/* Grow the marks by @p reach blocks along each axis in turn (a cube of 2 reach + 1 blocks). */
static void grow_blocks(struct fusion_volume *vol, const uint32_t nb[3], uint32_t reach)
{
    for (int axis = 0; axis < 3; axis++) {
        size_t stride = axis == 0 ? 1 : axis == 1 ? nb[0] : (size_t)nb[0] * nb[1];
        memcpy(vol->block_grown, vol->block_mark, (size_t)nb[0] * nb[1] * nb[2]);
        for (uint32_t z = 0; z < nb[2]; z++)
            for (uint32_t y = 0; y < nb[1]; y++)
                for (uint32_t x = 0; x < nb[0]; x++) {
                    uint32_t c[3] = {x, y, z};
                    size_t i = bidx(nb, x, y, z);
                    if (!vol->block_mark[i])
                        continue;
                    for (uint32_t d = 1; d <= reach; d++) {
                        if (c[axis] >= d)
                            vol->block_grown[i - d * stride] = 1;
                        if (c[axis] + d < nb[axis])
                            vol->block_grown[i + d * stride] = 1;
                    }
                }
        memcpy(vol->block_mark, vol->block_grown, (size_t)nb[0] * nb[1] * nb[2]);
    }
}

/* The voxels x0 .. x1 - 1 of row (y, z). @p step_x: one voxel along x, in the camera frame. */
static void integrate_run(struct fusion_volume *vol, const struct scan_calib *c,
                          const struct frame_xform *obj_from_cam, const struct decode_maps *m,
                          const struct tri_range *r, const uint8_t *rgb, const float *confidence,
                          vec3 step_x, uint32_t x0, uint32_t x1, uint32_t y, uint32_t z,
                          int pinhole)
{
    const double trunc = vol->p.truncation_mm, vox = vol->p.voxel_mm;
    vec3 p_obj = v3_add(vol->origin, v3(x0 * vox, y * vox, z * vox));
    vec3 p = frame_point_inv(obj_from_cam, p_obj); /* camera frame */
    struct voxel *row = &vol->grid[vidx(vol, 0, y, z)];
    for (uint32_t x = x0; x < x1; x++, p = v3_add(p, step_x)) {
        if (p.z <= 1.0)
            continue;
        double iz = 1.0 / p.z, a = p.x * iz, b = p.y * iz;
        double fu = c->cam_fx_px * a + c->cam_cx_px, fv = c->cam_fy_px * b + c->cam_cy_px;
        if (!pinhole)
            camray_project(c, p, &fu, &fv);
        if (fu < -0.5 || fv < -0.5)
            continue;
        /* nearest pixel; a cast rounds correctly once the value is known >= -0.5, and avoids a
         * libm call per voxel */
        long u = (long)(fu + 0.5), v = (long)(fv + 0.5);
        if (u >= (long)m->width || v >= (long)m->height)
            continue;
        size_t i = (size_t)v * m->width + (size_t)u;
        if (vol->weight_map[i] <= 0.0f)
            continue;
        /* distance along the ray from the voxel to the measured surface */
        double sdf = (r->xyz_mm[3 * i + 2] - p.z) * sqrt(1.0 + a * a + b * b);
        if (sdf < -trunc)
            continue; /* hidden behind the surface: this view knows nothing of it */
        double w = vol->weight_map[i], cw = confidence != NULL ? w * confidence[i] : w;
        fuse_voxel(vol, &row[x], sdf, w, cw, rgb + 3 * i);
    }
}

/* The marked runs of slices z0 .. z1 of the grid, row by row in memory order. */
struct slices {
    struct fusion_volume *vol;
    const struct scan_calib *c;
    const struct frame_xform *obj_from_cam;
    const struct decode_maps *m;
    const struct tri_range *r;
    const uint8_t *rgb;
    const float *confidence;
    vec3 step_x;
    uint32_t nb[3];
    int pinhole;
    unsigned parts;
};

static void integrate_slices(void *arg, unsigned k)
{
    const struct slices *s = arg;
    const uint32_t *dims = s->vol->dims, *nb = s->nb;
    for (uint32_t z = dims[2] * k / s->parts; z < dims[2] * (k + 1u) / s->parts; z++)
        for (uint32_t y = 0; y < dims[1]; y++) {
            const uint8_t *marks = &s->vol->block_mark[bidx(nb, 0, y / BLOCK, z / BLOCK)];
            /* along a row, each run of marked blocks at once */
            for (uint32_t bx = 0; bx < nb[0];) {
                if (!marks[bx]) {
                    bx++;
                    continue;
                }
                uint32_t first = bx;
                while (bx < nb[0] && marks[bx])
                    bx++;
                uint32_t x1 = bx * BLOCK < dims[0] ? bx * BLOCK : dims[0];
                integrate_run(s->vol, s->c, s->obj_from_cam, s->m, s->r, s->rgb, s->confidence,
                              s->step_x, first * BLOCK, x1, y, z, s->pinhole);
            }
        }
}

int fusion_integrate(struct fusion_volume *vol, const struct hal_thread *threads,
                     const struct scan_calib *c, const struct frame_xform *obj_from_cam,
                     const struct decode_maps *m, const struct tri_range *r, const uint8_t *rgb,
                     const float *confidence)
{
    if (!pixel_weights(vol, threads, c, m, r))
        return 0;
    const uint32_t *dims = vol->dims;
    struct slices s = {.vol = vol,
                       .c = c,
                       .obj_from_cam = obj_from_cam,
                       .m = m,
                       .r = r,
                       .rgb = rgb,
                       .confidence = confidence,
                       /* the voxel loop's common case, inline */
                       .pinhole = lens_is_pinhole(c->cam_dist),
                       .step_x = m3_tmul(obj_from_cam->rot, v3(vol->p.voxel_mm, 0, 0)),
                       .nb = {(dims[0] + BLOCK - 1) / BLOCK, (dims[1] + BLOCK - 1) / BLOCK,
                              (dims[2] + BLOCK - 1) / BLOCK},
                       .parts = hal_thread_parts(threads, 64)};
    vol->outside.views_cut +=
        fusion_border_points(&vol->p, obj_from_cam, m, r) >= FUSION_EDGE_POINTS;
    if (!mark_blocks(vol, threads, obj_from_cam, m, r, s.nb))
        return 0;
    /* a point's band reaches truncation / voxel voxels (and one for rounding) from its block */
    double band = vol->p.truncation_mm / vol->p.voxel_mm + 1.0;
    grow_blocks(vol, s.nb, (uint32_t)ceil(band / BLOCK));
    /* each voxel is its own: slices split across the cores fuse as one thread does */
    hal_thread_run(threads, s.parts, integrate_slices, &s);
    return 0;
}

int fusion_fill(struct fusion_volume *vol, double (*sdf_mm)(vec3 p, void *ctx), void *ctx)
{
    vol->grid_spent = 0;
    for (uint32_t z = 0; z < vol->dims[2]; z++)
        for (uint32_t y = 0; y < vol->dims[1]; y++)
            for (uint32_t x = 0; x < vol->dims[0]; x++) {
                struct voxel *v = &vol->grid[vidx(vol, x, y, z)];
                double d = sdf_mm(v3_add(vol->origin, v3_scale(v3(x, y, z), vol->p.voxel_mm)), ctx);
                if (isnan(d)) { /* never observed */
                    memset(v, 0, sizeof(*v));
                    continue;
                }
                d = fmax(-vol->p.truncation_mm, fmin(vol->p.truncation_mm, d));
                v->sdf = (int16_t)lround(d / vol->p.truncation_mm * 32767.0);
                v->weight = (uint16_t)WEIGHT_SCALE;
                v->rgb[0] = v->rgb[1] = v->rgb[2] = 128;
                v->colour_weight = (uint8_t)COLOUR_WEIGHT_SCALE;
            }
    return 0;
}

/* ---- marching cubes ---- */

static double sdf_at(struct fusion_volume *vol, uint32_t x, uint32_t y, uint32_t z)
{
    return vol->grid[vidx(vol, x, y, z)].sdf / 32767.0 * vol->p.truncation_mm;
}

/* Distance gradient at a sample (central differences, one-sided at the border): it points out. */
static vec3 gradient(struct fusion_volume *vol, uint32_t x, uint32_t y, uint32_t z)
{
    uint32_t lo[3] = {x ? x - 1 : x, y ? y - 1 : y, z ? z - 1 : z};
    uint32_t hi[3] = {x + 1 < vol->dims[0] ? x + 1 : x, y + 1 < vol->dims[1] ? y + 1 : y,
                      z + 1 < vol->dims[2] ? z + 1 : z};
    return v3((sdf_at(vol, hi[0], y, z) - sdf_at(vol, lo[0], y, z)) /
                  (double)(hi[0] - lo[0] + (hi[0] == lo[0])),
              (sdf_at(vol, x, hi[1], z) - sdf_at(vol, x, lo[1], z)) /
                  (double)(hi[1] - lo[1] + (hi[1] == lo[1])),
              (sdf_at(vol, x, y, hi[2]) - sdf_at(vol, x, y, lo[2])) /
                  (double)(hi[2] - lo[2] + (hi[2] == lo[2])));
}

struct extract_state {
    const struct mesh_sink *sink;
    uint32_t next_vertex;
};

/* The vertex on the grid edge from sample s along @p axis, made once and numbered. */
static int edge_vertex(struct fusion_volume *vol, struct extract_state *st, const uint32_t s[3],
                       int axis, uint32_t *slot, uint32_t *out)
{
    if (*slot != NO_VERTEX) {
        *out = *slot;
        return 0;
    }
    uint32_t t[3] = {s[0], s[1], s[2]};
    t[axis]++;
    const struct voxel *va = &vol->grid[vidx(vol, s[0], s[1], s[2])],
                       *vb = &vol->grid[vidx(vol, t[0], t[1], t[2])];
    double da = sdf_at(vol, s[0], s[1], s[2]), db = sdf_at(vol, t[0], t[1], t[2]);
    /* Strictly inside the edge: a zero distance at a sample would otherwise put the vertices of
     * several edges on the same point (degenerate triangles, non-manifold fans). */
    double f = fmin(fmax(da / (da - db), 1e-3), 1.0 - 1e-3);
    vec3 ga = gradient(vol, s[0], s[1], s[2]), gb = gradient(vol, t[0], t[1], t[2]);
    vec3 n = v3_norm(v3_add(v3_scale(ga, 1.0 - f), v3_scale(gb, f)));
    vec3 pos = v3_add(vol->origin, v3_scale(v3(s[0], s[1], s[2]), vol->p.voxel_mm));
    double shift[3] = {0, 0, 0};
    shift[axis] = f * vol->p.voxel_mm;
    pos = v3_add(pos, v3(shift[0], shift[1], shift[2]));
    struct mesh_vertex mv = {{(float)pos.x, (float)pos.y, (float)pos.z},
                             {(float)n.x, (float)n.y, (float)n.z},
                             {0, 0, 0},
                             va->colour_weight > 0 || vb->colour_weight > 0};
    /* a sample no view coloured does not darken its neighbour's colour */
    double fc = va->colour_weight == 0 ? 1.0 : vb->colour_weight == 0 ? 0.0 : f;
    for (int k = 0; k < 3; k++) /* the voxels' bytes to the vertex's 16 bits (MESH_RGB_ONE) */
        mv.rgb[k] =
            (uint16_t)((va->rgb[k] * (1.0 - fc) + vb->rgb[k] * fc) * MESH_RGB_PER_BYTE + 0.5);
    int rc = st->sink->vertex != NULL ? st->sink->vertex(st->sink->priv, &mv) : 0;
    *slot = *out = st->next_vertex++;
    return rc;
}

static uint32_t *edge_slot(struct fusion_volume *vol, uint32_t x, uint32_t y, uint32_t z, int e)
{
    unsigned a = mc_edge_corner[e][0]; /* the lower corner of the edge */
    uint32_t sx = x + (a & 1u), sy = y + ((a >> 1) & 1u), sz = z + (a >> 2);
    size_t i = (size_t)sy * vol->dims[0] + sx;
    if (e < 4)
        return &vol->edge_vertex_x[sz & 1u][i];
    if (e < 8)
        return &vol->edge_vertex_y[sz & 1u][i];
    return &vol->edge_vertex_z[i];
}

static int extract_cell(struct fusion_volume *vol, struct extract_state *st, uint32_t x, uint32_t y,
                        uint32_t z)
{
    unsigned pattern = 0;
    for (unsigned c = 0; c < 8; c++) {
        const struct voxel *v =
            &vol->grid[vidx(vol, x + (c & 1u), y + ((c >> 1) & 1u), z + (c >> 2))];
        if (v->weight == 0)
            return 0; /* a corner no view has seen: no surface can be claimed here */
        pattern |= (v->sdf < 0 ? 1u : 0u) << c;
    }
    const struct mc_case *mc = mc_table_case(pattern);
    for (unsigned t = 0; t < mc->tri_count; t++) {
        uint32_t idx[3];
        for (int k = 0; k < 3; k++) {
            int e = mc->edge[t][k];
            unsigned a = mc_edge_corner[e][0];
            uint32_t s[3] = {x + (a & 1u), y + ((a >> 1) & 1u), z + (a >> 2)};
            int rc = edge_vertex(vol, st, s, e / 4, edge_slot(vol, x, y, z, e), &idx[k]);
            if (rc != 0)
                return rc;
        }
        int rc = st->sink->triangle != NULL
                     ? st->sink->triangle(st->sink->priv, idx[0], idx[1], idx[2])
                     : 0;
        if (rc != 0)
            return rc;
    }
    return 0;
}

int fusion_extract(struct fusion_volume *vol, const struct mesh_sink *sink)
{
    if (vol->grid_spent)
        return -EINVAL; /* the grid holds something else now (fusion_spend_grid) */
    struct extract_state st = {sink, 0};
    size_t plane = (size_t)vol->dims[0] * vol->dims[1];
    memset(vol->edge_vertex_x[0], 0xFF, plane * sizeof(uint32_t));
    memset(vol->edge_vertex_y[0], 0xFF, plane * sizeof(uint32_t));
    for (uint32_t z = 0; z + 1 < vol->dims[2]; z++) {
        /* plane z+1 starts empty; plane z keeps what the layer below made */
        memset(vol->edge_vertex_x[(z + 1) & 1u], 0xFF, plane * sizeof(uint32_t));
        memset(vol->edge_vertex_y[(z + 1) & 1u], 0xFF, plane * sizeof(uint32_t));
        memset(vol->edge_vertex_z, 0xFF, plane * sizeof(uint32_t));
        for (uint32_t y = 0; y + 1 < vol->dims[1]; y++) {
            for (uint32_t x = 0; x + 1 < vol->dims[0]; x++) {
                int rc = extract_cell(vol, &st, x, y, z);
                if (rc != 0)
                    return rc;
            }
        }
    }
    return 0;
}
