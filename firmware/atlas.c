/* The texture atlas (atlas.h): charts of the prepared mesh by the axis direction its normals lie
 * nearest (a "box projection": every normal of a chart within 55 degrees of its axis, so the
 * orthographic projection along the axis unfolds it stretched by at most 1/cos 55 degrees; a
 * chart that folds back over itself, rare on a scan, shares the texels where it overlaps), packed
 * into shelves; then each texel's surface point projected into every view. */
#include "atlas.h"

#include "hal_thread.h"
#include "camray.h"
#include "frames.h"
#include "mem.h"
#include "srgb.h"
#include "unionfind.h"

#include <errno.h>
#include <stdint.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define NONE 0xFFFFFFFFu
/* A texel's point and what a view measured along its ray agree within this many voxels: else the
 * view sees another surface in front of it (or none there). */
#define ATLAS_DEPTH_VOXELS 2.0
/* The packing's target: the texture's area over the charts' (the shelves' waste). */
#define ATLAS_SLACK 1.15

static const uint32_t *tri_at(const struct fusion_volume *vol, uint32_t t)
{
    return &vol->mesh_tri[3 * (size_t)t];
}

static vec3 vertex_pos(const struct fusion_volume *vol, uint32_t v)
{
    const float *p = &vol->mesh_pos[3 * (size_t)v];
    return v3(p[0], p[1], p[2]);
}

/* A triangle's normal: the mean of its vertices' (the volume's gradient, smoother than the face's
 * own, so neighbouring triangles agree and the charts are few and large). */
static vec3 tri_normal(const struct fusion_volume *vol, uint32_t t)
{
    vec3 n = v3(0, 0, 0);
    for (int k = 0; k < 3; k++) {
        const float *m = &vol->mesh_nrm[3 * (size_t)tri_at(vol, t)[k]];
        n = v3_add(n, v3(m[0], m[1], m[2]));
    }
    return n;
}

/* The axis direction nearest @p n: 2 x axis + (1 when negative). */
static uint8_t nearest_axis(vec3 n)
{
    const double c[3] = {n.x, n.y, n.z};
    int best = 0;
    for (int k = 1; k < 3; k++)
        if (fabs(c[k]) > fabs(c[best]))
            best = k;
    return (uint8_t)(2 * best + (c[best] < 0.0));
}

/* @p p projected along axis direction @p axis: its two other coordinates (mm). */
static void project(uint8_t axis, vec3 p, double *u, double *v)
{
    const double c[3] = {p.x, p.y, p.z};
    int d = axis / 2;
    *u = c[(d + 1) % 3];
    *v = c[(d + 2) % 3];
}

/* Where @p p lies in the texture (texels, centres at +0.5) through chart @p ch. */
static void texel_xy(const struct atlas *a, const struct atlas_chart *ch, vec3 p, double *x,
                     double *y)
{
    double u, v;
    project(ch->axis, p, &u, &v);
    *x = ch->x0 + ATLAS_GUTTER + (u - ch->min_u) / a->texel_mm;
    *y = ch->y0 + ATLAS_GUTTER + (v - ch->min_v) / a->texel_mm;
}

/* ---- charts: union-find over triangles through the vertices they share ---- */

/* Every kept triangle's axis direction and chart number; each chart's projected extent (min in
 * min_u/min_v, the extent's far corner in w/h as mm, made texels by size_charts).
 * @retval 0 @retval -ENOSPC more charts than ATLAS_MAX_CHARTS */
static int make_charts(struct atlas *a, const struct fusion_volume *vol, double far_uv[][2])
{
    const uint32_t nt = vol->mp.s.triangles, nv = vol->mp.s.vertices;
    for (uint32_t t = 0; t < nt; t++) {
        a->tri_chart[t] = t;
        a->tri_axis[t] = vol->mesh_index[tri_at(vol, t)[0]] == MESH_DROPPED
                             ? 0xFF
                             : nearest_axis(tri_normal(vol, t));
    }
    for (uint8_t axis = 0; axis < 6; axis++) { /* joined only with triangles of its own axis */
        memset(a->vertex_tri, 0xFF, nv * sizeof(a->vertex_tri[0]));
        for (uint32_t t = 0; t < nt; t++) {
            if (a->tri_axis[t] != axis)
                continue;
            for (int k = 0; k < 3; k++) {
                uint32_t v = tri_at(vol, t)[k];
                if (a->vertex_tri[v] == NONE)
                    a->vertex_tri[v] = t;
                else
                    uf_join(a->tri_chart, t, a->vertex_tri[v]);
            }
        }
    }
    /* Each triangle straight to its root (a root is its piece's smallest triangle, and
     * parents are smaller than their children), then in increasing order each root given its
     * chart's number before the other triangles of its piece read it. */
    for (uint32_t t = 0; t < nt; t++)
        a->tri_chart[t] = uf_root(a->tri_chart, t);
    a->chart_count = 0;
    for (uint32_t t = 0; t < nt; t++) {
        if (a->tri_axis[t] == 0xFF) {
            a->tri_chart[t] = NONE;
            continue;
        }
        if (a->tri_chart[t] == t) {
            if (a->chart_count >= ATLAS_MAX_CHARTS)
                return -ENOSPC;
            struct atlas_chart *ch = &a->chart[a->chart_count];
            memset(ch, 0, sizeof(*ch));
            ch->axis = a->tri_axis[t];
            ch->min_u = ch->min_v = INFINITY;
            far_uv[a->chart_count][0] = far_uv[a->chart_count][1] = -INFINITY;
            a->tri_chart[t] = a->chart_count++;
        } else {
            a->tri_chart[t] = a->tri_chart[a->tri_chart[t]]; /* its root's, numbered already */
        }
        uint32_t c = a->tri_chart[t];
        struct atlas_chart *ch = &a->chart[c];
        ch->triangles++;
        for (int k = 0; k < 3; k++) {
            double u, v;
            project(ch->axis, vertex_pos(vol, tri_at(vol, t)[k]), &u, &v);
            ch->min_u = (float)fmin(ch->min_u, u);
            ch->min_v = (float)fmin(ch->min_v, v);
            far_uv[c][0] = fmax(far_uv[c][0], u);
            far_uv[c][1] = fmax(far_uv[c][1], v);
        }
    }
    return 0;
}

/* Each chart's size in texels at texel_mm: its extent, one texel for the reach, the gutters.
 * @retval the charts' texels in all */
static uint64_t size_charts(struct atlas *a, const double far_uv[][2])
{
    uint64_t area = 0;
    for (uint32_t c = 0; c < a->chart_count; c++) {
        struct atlas_chart *ch = &a->chart[c];
        ch->w = (uint32_t)ceil((far_uv[c][0] - ch->min_u) / a->texel_mm) + 1 + 2 * ATLAS_GUTTER;
        ch->h = (uint32_t)ceil((far_uv[c][1] - ch->min_v) / a->texel_mm) + 1 + 2 * ATLAS_GUTTER;
        area += (uint64_t)ch->w * ch->h;
    }
    return area;
}

static int taller_first(const void *x, const void *y)
{
    uint64_t a = *(const uint64_t *)x, b = *(const uint64_t *)y;
    return a < b ? -1 : a > b;
}

/* Shelf packing (tallest first, left to right, a new shelf when the row is full) into a texture
 * @p width wide. @retval its height, or 0 when a chart is wider than the texture */
static uint32_t pack(struct atlas *a, uint64_t *keys, uint32_t width)
{
    uint32_t x = 0, y = 0, shelf = 0;
    for (uint32_t i = 0; i < a->chart_count; i++) {
        struct atlas_chart *ch = &a->chart[keys[i] & 0xFFFFFFFFu];
        if (ch->w > width)
            return 0;
        if (x + ch->w > width)
            y += shelf, x = 0, shelf = 0;
        ch->x0 = x, ch->y0 = y;
        x += ch->w;
        shelf = ch->h > shelf ? ch->h : shelf;
    }
    return y + shelf;
}

static void assign_texels(struct atlas *a, const struct fusion_volume *vol);

_Static_assert((uint64_t)FUSION_MAX_VOXELS * sizeof(struct voxel) >=
                   ATLAS_WORK_BYTES(ATLAS_MAX_TEXELS, MESH_MAX_TRIANGLES, MESH_MAX_VERTICES),
               "the spent fusion grid holds the largest texture's work space");

/* The atlas's parts in @p work, the mesh's tables first and the texels' after them, so that a
 * texture touches only the memory its own size needs (the grid's pages the fusion did not use
 * are mapped only when touched): the charts, each vertex's place in a view, each triangle's and
 * each vertex's chart and each triangle's axis; then, 8-byte aligned, the texels (placed by
 * place_texels once their number is known; until then the packing's far corners and sort keys).
 * @retval 0 @retval -ENOSPC too small */
static int carve(struct atlas *a, const struct fusion_volume *vol, void *work, size_t bytes)
{
    const uint64_t nt = vol->mp.s.triangles, nv = vol->mp.s.vertices;
    const uint64_t fixed = ATLAS_WORK_BYTES(0, nt, nv);
    if (bytes < fixed)
        return -ENOSPC;
    uint64_t texels = (bytes - fixed) / ATLAS_TEXEL_BYTES;
    a->max_texels = (size_t)(texels < ATLAS_MAX_TEXELS ? texels : ATLAS_MAX_TEXELS);
    if (24u * (uint64_t)ATLAS_MAX_CHARTS > 16u * (uint64_t)a->max_texels)
        return -ENOSPC;
    a->chart = work;
    a->vertex_cam = (float *)(void *)(a->chart + ATLAS_MAX_CHARTS);
    a->vertex_accum = a->vertex_cam + 5 * nv;
    a->tri_chart = (uint32_t *)(void *)(a->vertex_accum + 4 * nv);
    a->vertex_tri = a->tri_chart + nt;
    a->tri_axis = (uint8_t *)(void *)(a->vertex_tri + nv);
    uintptr_t texel_start = ((uintptr_t)(a->tri_axis + nt) + 7u) & ~(uintptr_t)7u;
    a->accum = (float *)texel_start;
    return 0;
}

/* The texels' parts for @p texels texels, from the accumulators on (carve), the camera pixels'
 * weights and depths after them. */
static void place_texels(struct atlas *a, size_t texels)
{
    a->bary = a->accum + 4 * texels;
    a->owner = (uint32_t *)(void *)(a->bary + 2 * texels);
    a->texture = (uint8_t *)(void *)(a->owner + texels);
    a->pixel = (float *)(((uintptr_t)(a->texture + 3 * texels) + 3u) & ~(uintptr_t)3u);
}

int atlas_build(struct atlas *a, const struct fusion_volume *vol, double texel_mm, void *work,
                size_t work_bytes, struct atlas_report *rep)
{
    memset(rep, 0, sizeof(*rep));
    a->built = 0;
    a->width = a->height = a->chart_count = 0;
    if (!vol->mp.prepared || !(texel_mm >= 0.0) || work == NULL || ((uintptr_t)work & 7u) != 0)
        return -EINVAL;
    if (!vol->mp.fits)
        return -E2BIG;
    int rc = carve(a, vol, work, work_bytes);
    if (rc != 0)
        return rc;
    mem_fill(a->vertex_accum, 0, 4 * sizeof(float) * (size_t)vol->mp.s.vertices);
    if (texel_mm == 0.0) { /* no texture: the vertices' colours only */
        place_texels(a, 0);
        a->built = 1;
        return 0;
    }
    double(*far_uv)[2] = (double(*)[2])(void *)a->accum;
    uint64_t *keys = (uint64_t *)(void *)(far_uv + ATLAS_MAX_CHARTS);
    rc = make_charts(a, vol, far_uv);
    if (rc != 0)
        return rc;
    /* each vertex's chart: its first triangle's (a vertex on a chart's border has another
     * place in the texture for its other charts' triangles) */
    mem_fill(a->vertex_tri, 0xFF, vol->mp.s.vertices * sizeof(a->vertex_tri[0]));
    for (uint32_t t = 0; t < vol->mp.s.triangles; t++)
        for (int k = 0; k < 3 && a->tri_chart[t] != NONE; k++)
            if (a->vertex_tri[tri_at(vol, t)[k]] == NONE)
                a->vertex_tri[tri_at(vol, t)[k]] = a->tri_chart[t];
    for (a->texel_mm = texel_mm;; a->texel_mm *= 1.25) {
        uint64_t area = size_charts(a, far_uv);
        uint32_t widest = 0;
        for (uint32_t c = 0; c < a->chart_count; c++) {
            widest = a->chart[c].w > widest ? a->chart[c].w : widest;
            keys[c] = (uint64_t)(0xFFFFFFFFu - a->chart[c].h) << 32 | c;
        }
        uint32_t width = (uint32_t)ceil(sqrt((double)area * ATLAS_SLACK));
        width = ((width > widest ? width : widest) + 3u) & ~3u; /* rows of whole words */
        if (width <= ATLAS_MAX_SIDE && area <= a->max_texels) {
            qsort(keys, a->chart_count, sizeof(keys[0]), taller_first);
            uint32_t height = (pack(a, keys, width) + 3u) & ~3u;
            if (height > 0 && height <= ATLAS_MAX_SIDE &&
                (uint64_t)width * height <= a->max_texels) {
                a->width = width, a->height = height;
                rep->used_share = (double)area / ((double)width * height);
                break;
            }
        }
    }
    place_texels(a, (size_t)a->width * a->height);
    mem_fill(a->accum, 0, (size_t)a->width * a->height * 4 * sizeof(a->accum[0]));
    assign_texels(a, vol);
    a->built = 1;
    rep->width = a->width, rep->height = a->height;
    rep->texel_mm = a->texel_mm;
    rep->charts = a->chart_count;
    return 0;
}

/* ---- texels: each triangle rasterised in its chart ---- */

/* A texel is owned by the triangle its centre lies in or, outside every triangle of its chart,
 * by one whose edges it lies within this many texels of: a bilinear read at a point of the
 * surface reads texels up to sqrt(2) texels from it, and near a chart's border those must hold
 * the surface's colour (extrapolated on the triangle's plane), not the gutter's. */
#define ATLAS_REACH 1.5
/* tri_axis's flag of a triangle that faces the view being added (atlas_add_view) */
#define FACING 0x80u

/* Triangle @p t's corners in the texture and twice its signed area there.
 * @retval 0 @retval -1 on edge in the projection: no texel of its own */
static int tri_texels(const struct atlas *a, const struct fusion_volume *vol, uint32_t t,
                      double x[3], double y[3], double *area2)
{
    const struct atlas_chart *ch = &a->chart[a->tri_chart[t]];
    for (int k = 0; k < 3; k++)
        texel_xy(a, ch, vertex_pos(vol, tri_at(vol, t)[k]), &x[k], &y[k]);
    *area2 = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
    return fabs(*area2) < 1e-12 ? -1 : 0;
}

/* The barycentric weights @p l of point (@p cx, @p cy) in the triangle of corners @p x, @p y
 * (@p inv: one over twice its signed area): negative outside. */
static void barycentric(const double x[3], const double y[3], double inv, double cx, double cy,
                        double l[3])
{
    l[0] = ((x[1] - cx) * (y[2] - cy) - (x[2] - cx) * (y[1] - cy)) * inv;
    l[1] = ((x[2] - cx) * (y[0] - cy) - (x[0] - cx) * (y[2] - cy)) * inv;
    l[2] = 1.0 - l[0] - l[1];
}

/* What raster does with the texels about a triangle: claim those its centre lies in, or claim
 * those nobody owns within ATLAS_REACH of it (assign_texels). */
enum raster_mode { CLAIM_INSIDE, CLAIM_NEAR };

/* Texel @p texel is triangle @p t's, at barycentric weights @p l there. */
static void claim(struct atlas *a, size_t texel, uint32_t t, const double l[3])
{
    a->owner[texel] = t;
    a->bary[2 * texel] = (float)l[0];
    a->bary[2 * texel + 1] = (float)l[1];
}

/* The texels about triangle @p t: its bounding box, and ATLAS_REACH about it when it claims the
 * near ones. */
static void raster(struct atlas *a, const struct fusion_volume *vol, uint32_t t,
                   enum raster_mode mode)
{
    double x[3], y[3], area2, height[3] = {0.0, 0.0, 0.0};
    if (tri_texels(a, vol, t, x, y, &area2) != 0)
        return;
    for (int k = 0; k < 3 && mode == CLAIM_NEAR; k++) { /* over the edge opposite corner k */
        double ex = x[(k + 2) % 3] - x[(k + 1) % 3], ey = y[(k + 2) % 3] - y[(k + 1) % 3];
        height[k] = fabs(area2) / sqrt(ex * ex + ey * ey);
    }
    const struct atlas_chart *ch = &a->chart[a->tri_chart[t]];
    const double reach = mode == CLAIM_NEAR ? ATLAS_REACH : 0.0;
    long xa = (long)floor(fmin(x[0], fmin(x[1], x[2])) - reach);
    long xb = (long)ceil(fmax(x[0], fmax(x[1], x[2])) + reach);
    long ya = (long)floor(fmin(y[0], fmin(y[1], y[2])) - reach);
    long yb = (long)ceil(fmax(y[0], fmax(y[1], y[2])) + reach);
    xa = xa < (long)ch->x0 ? (long)ch->x0 : xa;
    ya = ya < (long)ch->y0 ? (long)ch->y0 : ya;
    xb = xb > (long)(ch->x0 + ch->w) ? (long)(ch->x0 + ch->w) : xb;
    yb = yb > (long)(ch->y0 + ch->h) ? (long)(ch->y0 + ch->h) : yb;
    const double inv = 1.0 / area2;
    for (long ty = ya; ty < yb; ty++)
        for (long tx = xa; tx < xb; tx++) {
            size_t texel = (size_t)ty * a->width + (size_t)tx;
            double l[3];
            if (mode == CLAIM_NEAR && a->owner[texel] != NONE)
                continue; /* taken (most of the box is, by the triangles' own texels) */
            barycentric(x, y, inv, tx + 0.5, ty + 0.5, l);
            if (mode == CLAIM_INSIDE) {
                if (l[0] >= 0.0 && l[1] >= 0.0 && l[2] >= 0.0)
                    claim(a, texel, t, l);
            } else if (l[0] * height[0] >= -ATLAS_REACH && l[1] * height[1] >= -ATLAS_REACH &&
                       l[2] * height[2] >= -ATLAS_REACH) {
                claim(a, texel, t, l);
            }
        }
}

/* Each texel's triangle (owner), for the views' colour and the vertex colours': the texels each
 * triangle's centre lies in, then the ones near a triangle that nobody owns. */
static void assign_texels(struct atlas *a, const struct fusion_volume *vol)
{
    mem_fill(a->owner, 0xFF, (size_t)a->width * a->height * sizeof(a->owner[0]));
    for (uint32_t t = 0; t < vol->mp.s.triangles; t++)
        if (a->tri_chart[t] != NONE)
            raster(a, vol, t, CLAIM_INSIDE);
    for (uint32_t t = 0; t < vol->mp.s.triangles; t++)
        if (a->tri_chart[t] != NONE)
            raster(a, vol, t, CLAIM_NEAR);
}

struct view_ctx {
    struct atlas *a;
    const struct decode_maps *m;
    const uint8_t *rgb;
    double depth_tol_mm;
    /* the triangle of the texels being coloured: where its corners are seen (pixels) and their
     * depth, and the depth's scale to a distance along the ray */
    uint32_t t;
    double u[3], v[3], z[3], ray;
};

/* Triangle @p t's corners as the view sees them, in @p s. */
static void view_triangle(struct view_ctx *s, const struct fusion_volume *vol, uint32_t t)
{
    const float *c[3];
    for (int k = 0; k < 3; k++) {
        c[k] = &s->a->vertex_cam[5 * (size_t)tri_at(vol, t)[k]];
        s->u[k] = c[k][3], s->v[k] = c[k][4], s->z[k] = c[k][2];
    }
    vec3 p0 = v3(c[0][0], c[0][1], c[0][2]);
    s->ray = v3_len(p0) / p0.z;
    s->t = t;
}

/* The view's colour about pixel (@p fu, @p fv) of a surface point at depth @p z, bilinear over
 * the pixels that measured the surface there (their depth within @p ray: the point's distance
 * over its depth, times the tolerance), weighed, added to @p acc (colour and weight). */
static void sample(const struct view_ctx *s, double fu, double fv, double z, double ray,
                   float acc[4])
{
    if (!(fu >= 0.0 && fv >= 0.0))
        return;
    long x0 = (long)fu, y0 = (long)fv;
    if (x0 + 1 >= (long)s->m->width || y0 + 1 >= (long)s->m->height)
        return;
    const double fx = fu - x0, fy = fv - y0;
    const double wx[2] = {1.0 - fx, fx}, wy[2] = {1.0 - fy, fy};
    const size_t first = (size_t)y0 * s->m->width + (size_t)x0;
    const double z_tol = s->depth_tol_mm / ray;
    double sum[3] = {0.0, 0.0, 0.0}, wsum = 0.0;
    for (int q = 0; q < 4; q++) {
        size_t i = first + (q / 2 ? s->m->width : 0u) + (size_t)(q % 2);
        const float *px = &s->a->pixel[2 * i];
        if (px[0] <= 0.0f || fabs(px[1] - z) > z_tol)
            continue;
        double w = px[0] * wx[q % 2] * wy[q / 2];
        for (int k = 0; k < 3; k++)
            sum[k] += w * s->rgb[3 * i + k];
        wsum += w;
    }
    for (int k = 0; k < 3; k++)
        acc[k] += (float)sum[k];
    acc[3] += (float)wsum;
}

/* One texel of the triangle seen by the view (atlas_add_view): where it is seen and its depth
 * interpolated from the corners' (a triangle spans a pixel or two: the lens's bending and the
 * perspective's across it are thousandths of a pixel). */
static void view_texel(struct view_ctx *s, size_t texel, const double l[3])
{
    double fu = l[0] * s->u[0] + l[1] * s->u[1] + l[2] * s->u[2];
    double fv = l[0] * s->v[0] + l[1] * s->v[1] + l[2] * s->v[2];
    double z = l[0] * s->z[0] + l[1] * s->z[1] + l[2] * s->z[2];
    sample(s, fu, fv, z, s->ray, &s->a->accum[4 * texel]);
}

/* A surface of normal @p n_obj (object frame) at @p p_cam (camera frame) faces the camera: its
 * normal against the ray to it. */
static int faces(const struct frame_xform *obj_from_cam, vec3 n_obj, vec3 p_cam)
{
    return v3_dot(frame_dir_inv(obj_from_cam, n_obj), p_cam) < 0.0;
}

/* What the parts of a view's colouring share (atlas_add_view): its pixels, its vertices and its
 * charts are split into @c parts, each part's writes its own (a pixel's, a vertex's, a chart's
 * texels). */
struct view_parts {
    struct view_ctx s; /* each part starts from a copy */
    struct fusion_volume *vol;
    const struct scan_calib *calib;
    const struct frame_xform *obj_from_cam;
    const struct tri_range *range;
    const float *weight, *confidence;
    size_t pixels;
    unsigned parts;
};

/* Part @p k of the pixels: each one's weight (fusion's times the colour's confidence, as the
 * fusion grid weighs its colour; a negative confidence is no estimate) and depth, side by side:
 * the texels read four pixels each, wherever they land. Squared, so that the most head-on view
 * dominated, the mean dE00 came out 0.01-0.06 worse on the four eval scenes tried, texture and
 * vertices alike (2026-12-06, docs/colour.md). */
static void view_pixels(void *arg, unsigned k)
{
    const struct view_parts *p = arg;
    float *pixel = p->s.a->pixel;
    for (size_t i = p->pixels * k / p->parts; i < p->pixels * (k + 1u) / p->parts; i++) {
        double c = p->confidence != NULL ? p->confidence[i] : 1.0, w = p->weight[i];
        pixel[2 * i] = w > 0.0 && c > 0.0 ? (float)(w * c) : 0.0f;
        pixel[2 * i + 1] = w > 0.0 ? p->range->xyz_mm[3 * i + 2] : 0.0f;
    }
}

/* Part @p k of the vertices: each in the camera's frame and where it is seen (vertex_cam, once:
 * a vertex has six triangles); one that faces the view and lies in front of the camera takes
 * the view's colour there. */
static void view_vertices(void *arg, unsigned k)
{
    const struct view_parts *p = arg;
    const struct fusion_volume *vol = p->vol;
    const uint32_t n = vol->mp.s.vertices;
    for (uint32_t v = (uint32_t)((uint64_t)n * k / p->parts);
         v < (uint32_t)((uint64_t)n * (k + 1u) / p->parts); v++) {
        float *c = &p->s.a->vertex_cam[5 * (size_t)v];
        const float *nrm = &vol->mesh_nrm[3 * (size_t)v];
        vec3 q = frame_point_inv(p->obj_from_cam, vertex_pos(vol, v));
        double u = 0.0, w = 0.0;
        if (q.z > 1.0)
            camray_project(p->calib, q, &u, &w);
        c[0] = (float)q.x, c[1] = (float)q.y, c[2] = (float)q.z, c[3] = (float)u, c[4] = (float)w;
        vec3 at = v3(c[0], c[1], c[2]);
        if (vol->mesh_index[v] == MESH_DROPPED || c[2] <= 1.0f ||
            !faces(p->obj_from_cam, v3(nrm[0], nrm[1], nrm[2]), at))
            continue;
        sample(&p->s, c[3], c[4], c[2], v3_len(at) / at.z, &p->s.a->vertex_accum[4 * (size_t)v]);
    }
}

/* Part @p k of the charts: the texels of each chart that faces the view (half of them face
 * away), each at its place in its triangle (a triangle's texels lie together along a row: its
 * corners are looked up again only when the triangle changes). */
static void view_charts(void *arg, unsigned k)
{
    const struct view_parts *p = arg;
    struct view_ctx s = p->s;
    const struct atlas *a = s.a;
    s.t = NONE;
    for (uint32_t c = a->chart_count * k / p->parts; c < a->chart_count * (k + 1u) / p->parts;
         c++) {
        const struct atlas_chart *ch = &a->chart[c];
        for (uint32_t y = ch->y0; y < ch->y0 + ch->h && ch->facing; y++)
            for (size_t i = (size_t)y * a->width + ch->x0;
                 i < (size_t)y * a->width + ch->x0 + ch->w; i++) {
                uint32_t t = a->owner[i];
                if (t == NONE || !(a->tri_axis[t] & FACING))
                    continue;
                if (t != s.t)
                    view_triangle(&s, p->vol, t);
                const double l[3] = {a->bary[2 * i], a->bary[2 * i + 1],
                                     1.0 - a->bary[2 * i] - a->bary[2 * i + 1]};
                view_texel(&s, i, l);
            }
    }
}

int atlas_add_view(struct atlas *a, struct fusion_volume *vol, const struct hal_thread *threads,
                   const struct scan_calib *calib, const struct frame_xform *obj_from_cam,
                   const struct decode_maps *maps, const struct tri_range *range,
                   const uint8_t *rgb, const float *confidence)
{
    if (!a->built)
        return -EINVAL;
    const float *weight = fusion_view_weights(vol, threads, calib, maps, range);
    if (weight == NULL)
        return 0; /* a view of nothing */
    const size_t pixels = (size_t)maps->width * maps->height;
    if (pixels > HAL_MAX_PIXELS)
        return -EINVAL;
    struct view_parts p = {
        .s = {.a = a, .m = maps, .rgb = rgb, .depth_tol_mm = ATLAS_DEPTH_VOXELS * vol->p.voxel_mm},
        .vol = vol,
        .calib = calib,
        .obj_from_cam = obj_from_cam,
        .range = range,
        .weight = weight,
        .confidence = confidence,
        .pixels = pixels,
        .parts = hal_thread_parts(threads, 64)};
    mem_prefault(a->pixel, 2 * sizeof(a->pixel[0]) * pixels); /* both written whole */
    mem_prefault(a->vertex_cam, 5 * sizeof(a->vertex_cam[0]) * vol->mp.s.vertices);
    hal_thread_run(threads, p.parts, view_pixels, &p);
    hal_thread_run(threads, p.parts, view_vertices, &p);
    if (a->width == 0)
        return 0; /* no texture */
    for (uint32_t c = 0; c < a->chart_count; c++)
        a->chart[c].facing = 0;
    for (uint32_t t = 0; t < vol->mp.s.triangles; t++) {
        a->tri_axis[t] &= (uint8_t)~FACING;
        if (a->tri_chart[t] == NONE)
            continue;
        const float *c[3];
        for (int k = 0; k < 3; k++)
            c[k] = &a->vertex_cam[5 * (size_t)tri_at(vol, t)[k]];
        vec3 p0 = v3(c[0][0], c[0][1], c[0][2]);
        /* facing the camera at its first corner, every corner in front of it */
        if (faces(obj_from_cam, tri_normal(vol, t), p0) && c[0][2] > 1.0 && c[1][2] > 1.0 &&
            c[2][2] > 1.0) {
            a->tri_axis[t] |= FACING;
            a->chart[a->tri_chart[t]].facing = 1;
        }
    }
    hal_thread_run(threads, p.parts, view_charts, &p);
    return 0;
}

/* ---- the texture ---- */

/* A texel's state in accum[4 i + 3] once finish has taken the views' colours: */
#define SEEN (-1.0f)        /* coloured: the linear colour in accum[4 i .. 4 i + 2] */
#define FROM_MESH (-2.0f)   /* no view: the mesh's vertex colours */
#define FILLED_BASE (-3.0f) /* a gutter texel filled in pass k: FILLED_BASE - k */

/* A texel no view coloured takes the vertex colours there (atlas_finish). */
static void mesh_texel(struct atlas *a, const struct fusion_volume *vol, size_t texel,
                       const double bary[3], uint32_t t)
{
    float *acc = &a->accum[4 * texel];
    for (int k = 0; k < 3; k++) {
        double c = 0.0;
        for (int j = 0; j < 3; j++)
            c += bary[j] * vol->mesh_rgb[3 * (size_t)tri_at(vol, t)[j] + (size_t)k];
        acc[k] = (float)(c / MESH_RGB_PER_BYTE); /* the texels' scale: a linear byte */
    }
    acc[3] = FROM_MESH;
}

/* Gutter texels beside coloured ones take their mean, @p passes rings out. */
static void fill_gutters(struct atlas *a, int passes)
{
    const long w = a->width, h = a->height;
    for (int pass = 0; pass < passes; pass++) {
        const float mark = FILLED_BASE - (float)pass;
        for (long y = 0; y < h; y++)
            for (long x = 0; x < w; x++) {
                float *acc = &a->accum[4 * (size_t)(y * w + x)];
                if (acc[3] != 0.0f)
                    continue;
                double sum[3] = {0.0, 0.0, 0.0};
                int n = 0;
                static const int step[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
                for (int s = 0; s < 4; s++) {
                    long xs = x + step[s][0], ys = y + step[s][1];
                    if (xs < 0 || ys < 0 || xs >= w || ys >= h)
                        continue;
                    const float *nb = &a->accum[4 * (size_t)(ys * w + xs)];
                    if (nb[3] == 0.0f || nb[3] == mark) /* not this pass's own */
                        continue;
                    for (int k = 0; k < 3; k++)
                        sum[k] += nb[k];
                    n++;
                }
                if (n == 0)
                    continue;
                for (int k = 0; k < 3; k++)
                    acc[k] = (float)(sum[k] / n);
                acc[3] = mark;
            }
    }
}

/* Each vertex a view saw: its weighted colour into the tables, 16 bits (MESH_RGB_PER_BYTE a
 * linear byte).
 * @retval the vertices coloured */
static uint32_t finish_vertices(const struct atlas *a, struct fusion_volume *vol)
{
    uint32_t seen = 0;
    for (uint32_t v = 0; v < vol->mp.s.vertices; v++) {
        const float *acc = &a->vertex_accum[4 * (size_t)v];
        if (!(acc[3] > 0.0f))
            continue;
        for (int k = 0; k < 3; k++) {
            double c = acc[k] / acc[3] * (double)MESH_RGB_PER_BYTE + 0.5;
            vol->mesh_rgb[3 * (size_t)v + (size_t)k] = (uint16_t)(c < 0.0            ? 0.0
                                                                  : c > MESH_RGB_ONE ? MESH_RGB_ONE
                                                                                     : c);
        }
        vol->mesh_coloured[v] = 1;
        seen++;
    }
    return seen;
}

int atlas_finish(struct atlas *a, struct fusion_volume *vol, uint32_t *uncoloured,
                 uint32_t *vertices)
{
    *uncoloured = *vertices = 0;
    if (!a->built)
        return -EINVAL;
    *vertices = finish_vertices(a, vol); /* first: a texel no view saw takes them */
    const size_t n = (size_t)a->width * a->height;
    for (size_t i = 0; i < n; i++) {
        float *acc = &a->accum[4 * i];
        if (acc[3] > 0.0f) {
            for (int k = 0; k < 3; k++)
                acc[k] /= acc[3];
            acc[3] = SEEN;
        }
    }
    /* owned texels no view coloured: the vertex colours, through their triangle's weights there
     * (a few per cent of them: texel by texel rather than every triangle rasterised again) */
    uint32_t unseen = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t t = a->owner[i];
        if (a->accum[4 * i + 3] != 0.0f || t == NONE)
            continue;
        const double l[3] = {a->bary[2 * i], a->bary[2 * i + 1],
                             1.0 - a->bary[2 * i] - a->bary[2 * i + 1]};
        mesh_texel(a, vol, i, l, t);
        unseen++;
    }
    fill_gutters(a, (int)ATLAS_GUTTER);
    for (size_t i = 0; i < n; i++) {
        const float *acc = &a->accum[4 * i];
        for (int k = 0; k < 3; k++)
            a->texture[3 * i + (size_t)k] =
                acc[3] != 0.0f ? srgb_encode_unit(acc[k] / 255.0) : 128; /* mid grey */
    }
    *uncoloured = unseen;
    return 0;
}

/* Where vertex @p v lies through chart @p c, as glTF takes it. */
static void uv_in(const struct atlas *a, const struct fusion_volume *vol, uint32_t c, uint32_t v,
                  float uv[2])
{
    double x, y;
    texel_xy(a, &a->chart[c], vertex_pos(vol, v), &x, &y);
    uv[0] = (float)(x / a->width);
    uv[1] = (float)(y / a->height);
}

int atlas_uv(const struct atlas *a, const struct fusion_volume *vol, uint32_t t, int k, float uv[2])
{
    if (a->width == 0 || t >= vol->mp.s.triangles || a->tri_chart[t] == NONE || k < 0 || k > 2)
        return -EINVAL;
    uv_in(a, vol, a->tri_chart[t], tri_at(vol, t)[k], uv);
    return 0;
}

int atlas_vertex_uv(const struct atlas *a, const struct fusion_volume *vol, uint32_t v, float uv[2])
{
    if (a->width == 0 || v >= vol->mp.s.vertices || a->vertex_tri[v] == NONE)
        return -EINVAL;
    uv_in(a, vol, a->vertex_tri[v], v, uv);
    return 0;
}

int atlas_corner_is_vertex(const struct atlas *a, const struct fusion_volume *vol, uint32_t t,
                           int k)
{
    return a->width > 0 && t < vol->mp.s.triangles && k >= 0 && k < 3 && a->tri_chart[t] != NONE &&
           a->tri_chart[t] == a->vertex_tri[tri_at(vol, t)[k]];
}
