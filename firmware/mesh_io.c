/* The fused mesh as binary PLY, OBJ and binary STL, without its floating fragments.
 *
 * fusion_mesh_prepare runs marching cubes once and keeps the mesh in static tables (position,
 * normal and colour per vertex, three vertex numbers per triangle); the connected pieces are
 * found over those (union-find over vertex numbers) and every writer reads the tables,
 * renumbering the vertices it keeps. A mesh too large for the tables (more than
 * MESH_MAX_VERTICES or MESH_MAX_TRIANGLES) keeps every piece and gets no STL; PLY and OBJ then
 * stream from marching cubes again, which is deterministic. */
#include "atlas.h"
#include "fusion.h"
#include "mem.h"
#include "outbuf.h"
#include "ply.h"
#include "srgb.h"
#include "unionfind.h"

#include <errno.h>
#include <string.h>

/* The tables (struct fusion_volume): vol->mesh_index is each vertex's union-find parent, and after
 * prepare its new number or MESH_DROPPED; vol->mesh_coloured 0 where no view coloured the surface
 * (colour_fill gives it one). */

static int keep_vertex(void *priv, const struct mesh_vertex *mv)
{
    struct fusion_volume *vol = priv;
    uint32_t v = vol->mp.s.vertices++;
    if (v < MESH_MAX_VERTICES) {
        memcpy(&vol->mesh_pos[3 * (size_t)v], mv->pos, 3 * sizeof(float));
        memcpy(&vol->mesh_nrm[3 * (size_t)v], mv->normal, 3 * sizeof(float));
        memcpy(&vol->mesh_rgb[3 * (size_t)v], mv->rgb, sizeof(mv->rgb));
        vol->mesh_coloured[v] = mv->coloured;
        vol->mesh_index[v] = v;
    }
    return 0;
}

static int keep_triangle(void *priv, uint32_t a, uint32_t b, uint32_t c)
{
    struct fusion_volume *vol = priv;
    uint32_t t = vol->mp.s.triangles++;
    if (vol->mp.s.vertices <= MESH_MAX_VERTICES && t < MESH_MAX_TRIANGLES) {
        uint32_t *tri = &vol->mesh_tri[3 * (size_t)t];
        tri[0] = a;
        tri[1] = b;
        tri[2] = c;
        uf_join(vol->mesh_index, a, b);
        uf_join(vol->mesh_index, b, c);
    }
    return 0;
}

/* Number the vertices of the pieces kept (MESH_DROPPED for the others), counting what is kept. */
static void drop_fragments(struct fusion_volume *vol, double min_fragment_share)
{
    uint32_t n = vol->mp.s.vertices, largest = 0, next = 0;
    mem_fill(vol->mesh_tris, 0, n * sizeof(uint32_t));
    for (uint32_t t = 0; t < vol->mp.s.triangles; t++)
        vol->mesh_tris[uf_root(vol->mesh_index, vol->mesh_tri[3 * (size_t)t])]++;
    for (uint32_t v = 0; v < n; v++)
        vol->mesh_index[v] = uf_root(vol->mesh_index, v); /* every vertex straight to its root */
    for (uint32_t v = 0; v < n; v++)
        if (vol->mesh_index[v] == v && vol->mesh_tris[v] > largest)
            largest = vol->mesh_tris[v];
    double keep_from = min_fragment_share * largest;
    vol->mp.s.kept_triangles = 0;
    for (uint32_t v = 0; v < n; v++) {
        uint32_t root = vol->mesh_index[v], tris = vol->mesh_tris[root];
        int keep = tris > 0 && tris >= keep_from;
        if (root == v) {
            vol->mp.s.pieces++;
            vol->mp.s.removed_pieces += !keep;
            vol->mp.s.kept_triangles += keep ? tris : 0;
        }
        vol->mesh_index[v] =
            keep ? next++ : MESH_DROPPED; /* its root's entry is read before: root <= v */
    }
    vol->mp.s.kept_vertices = next;
}

/* Vertices no view coloured (every view that saw the surface there had no estimate, e.g. paint
 * too dark at every exposure) take the colour of a coloured neighbour along the kept triangles,
 * a ring a pass (a flood fill from the surface around), so the surface's own colour spreads in
 * rather than a raw or black one; what no coloured vertex reaches within COLOUR_FILL_PASSES
 * rings is marked mid grey. vol->mesh_tris, free after drop_fragments, holds each one's source. */
#define COLOUR_FILL_PASSES 64
#define GREY_LINEAR 55 /* sRGB 128 */
#define NO_SOURCE 0xFFFFFFFFu
static void colour_fill(struct fusion_volume *vol)
{
    uint32_t n = vol->mp.s.vertices, missing = 0;
    for (uint32_t v = 0; v < n; v++)
        missing += vol->mesh_index[v] != MESH_DROPPED && !vol->mesh_coloured[v];
    for (int pass = 0; pass < COLOUR_FILL_PASSES && missing > 0; pass++) {
        uint32_t filled = 0;
        memset(vol->mesh_tris, 0xFF, n * sizeof(uint32_t));
        for (uint32_t t = 0; t < vol->mp.s.triangles; t++) {
            const uint32_t *tri = &vol->mesh_tri[3 * (size_t)t];
            for (int k = 0; k < 3 && vol->mesh_index[tri[0]] != MESH_DROPPED; k++) {
                uint32_t a = tri[k], b = tri[(k + 1) % 3];
                if (!vol->mesh_coloured[a] && vol->mesh_coloured[b])
                    vol->mesh_tris[a] = b;
                else if (!vol->mesh_coloured[b] && vol->mesh_coloured[a])
                    vol->mesh_tris[b] = a;
            }
        }
        for (uint32_t v = 0; v < n; v++) {
            if (vol->mesh_tris[v] == NO_SOURCE)
                continue;
            /* sources were coloured before this pass: one ring a pass, whatever the numbering */
            memcpy(&vol->mesh_rgb[3 * (size_t)v], &vol->mesh_rgb[3 * (size_t)vol->mesh_tris[v]],
                   3 * sizeof(vol->mesh_rgb[0]));
            filled++;
        }
        for (uint32_t v = 0; v < n; v++)
            vol->mesh_coloured[v] |= vol->mesh_tris[v] != NO_SOURCE;
        vol->mp.s.colour_filled += filled;
        missing -= filled;
        if (filled == 0)
            break;
    }
    for (uint32_t v = 0; v < n && missing > 0; v++)
        if (vol->mesh_index[v] != MESH_DROPPED && !vol->mesh_coloured[v]) {
            for (int k = 0; k < 3; k++)
                vol->mesh_rgb[3 * (size_t)v + (size_t)k] = GREY_LINEAR * MESH_RGB_PER_BYTE;
            vol->mp.s.uncoloured++;
        }
}

int fusion_mesh_prepare(struct fusion_volume *vol, double min_fragment_share,
                        struct mesh_summary *out)
{
    memset(&vol->mp, 0, sizeof(vol->mp));
    struct mesh_sink keep = {keep_vertex, keep_triangle, vol};
    int rc = fusion_extract(vol, &keep);
    if (rc != 0)
        return rc;
    vol->mp.fits =
        vol->mp.s.vertices <= MESH_MAX_VERTICES && vol->mp.s.triangles <= MESH_MAX_TRIANGLES;
    vol->mp.s.kept_vertices = vol->mp.s.vertices;
    vol->mp.s.kept_triangles = vol->mp.s.triangles;
    if (vol->mp.fits) {
        drop_fragments(vol, min_fragment_share);
        colour_fill(vol);
    }
    vol->mp.prepared = 1;
    *out = vol->mp.s;
    return vol->mp.fits ? 0 : -E2BIG;
}

/* Vertex @p v of the tables as the sinks take it (valid until the next call). */
static const struct mesh_vertex *mesh_vertex_at(struct fusion_volume *vol, uint32_t v)
{
    struct mesh_vertex *mv = &vol->mv;
    memcpy(mv->pos, &vol->mesh_pos[3 * (size_t)v], sizeof(mv->pos));
    memcpy(mv->normal, &vol->mesh_nrm[3 * (size_t)v], sizeof(mv->normal));
    memcpy(mv->rgb, &vol->mesh_rgb[3 * (size_t)v], sizeof(mv->rgb));
    mv->coloured = vol->mesh_coloured[v];
    return mv;
}

/* The kept mesh from the tables: the vertices, then the triangles, renumbered. */
static int emit_kept(struct fusion_volume *vol, const struct mesh_sink *sink)
{
    int rc = 0;
    for (uint32_t v = 0; v < vol->mp.s.vertices && sink->vertex != NULL && rc == 0; v++)
        if (vol->mesh_index[v] != MESH_DROPPED)
            rc = sink->vertex(sink->priv, mesh_vertex_at(vol, v));
    for (uint32_t t = 0; t < vol->mp.s.triangles && sink->triangle != NULL && rc == 0; t++) {
        const uint32_t *tri = &vol->mesh_tri[3 * (size_t)t];
        if (vol->mesh_index[tri[0]] != MESH_DROPPED)
            rc = sink->triangle(sink->priv, vol->mesh_index[tri[0]], vol->mesh_index[tri[1]],
                                vol->mesh_index[tri[2]]);
    }
    return rc;
}

int fusion_extract_prepared(struct fusion_volume *vol, const struct mesh_sink *sink)
{
    if (!vol->mp.prepared)
        return -EINVAL;
    /* too large for the tables: marching cubes again, every piece kept */
    return vol->mp.fits ? emit_kept(vol, sink) : fusion_extract(vol, sink);
}

int fusion_mesh_counts(struct fusion_volume *vol, struct mesh_summary *summary)
{
    if (!vol->mp.prepared)
        return -EINVAL;
    *summary = vol->mp.s;
    return vol->mp.fits ? 0 : -E2BIG;
}

static int ply_vertex(void *priv, const struct mesh_vertex *v)
{
    struct outbuf *o = priv;
    const float *p = v->pos, *n = v->normal;
    ply_put_vertex16(o, v3(p[0], p[1], p[2]), v3(n[0], n[1], n[2]), v->rgb);
    return o->rc;
}

static int ply_triangle(void *priv, uint32_t a, uint32_t b, uint32_t c)
{
    struct outbuf *o = priv;
    uint8_t three = 3;
    outbuf_put(o, &three, 1);
    outbuf_u32le(o, a);
    outbuf_u32le(o, b);
    outbuf_u32le(o, c);
    return o->rc;
}

int fusion_write_ply(struct fusion_volume *vol, const struct hal_storage *st, const char *path)
{
    struct outbuf o;
    if (!vol->mp.prepared)
        return -EINVAL;
    if (outbuf_open(&o, st, path) != 0)
        return o.rc;
    /* PLY wants its counts first and its vertices before its faces */
    ply_put_header(&o, "fused mesh", vol->mp.s.kept_vertices, vol->mp.s.kept_triangles, 0);
    struct mesh_sink vertex_pass = {ply_vertex, NULL, &o};
    struct mesh_sink face_pass = {NULL, ply_triangle, &o};
    fusion_extract_prepared(vol, &vertex_pass);
    fusion_extract_prepared(vol, &face_pass);
    return outbuf_close(&o);
}

/* One OBJ line: @p tag and @p n numbers with @p decimals digits after the point ("%.4f"). */
static void obj_numbers(struct outbuf *o, const char *tag, const double *x, int n,
                        unsigned decimals)
{
    outbuf_put(o, tag, strlen(tag));
    for (int k = 0; k < n; k++) {
        outbuf_put(o, " ", 1);
        outbuf_fixed(o, x[k], decimals);
    }
    outbuf_put(o, "\n", 1);
}

/* One face: each corner's vertex, texture coordinate (0: none, "v//vn") and normal. */
static void obj_face(struct outbuf *o, const uint32_t corner[3][3])
{
    outbuf_put(o, "f", 1);
    for (int k = 0; k < 3; k++) {
        outbuf_put(o, " ", 1);
        outbuf_u32(o, corner[k][0]);
        outbuf_put(o, "/", 1);
        if (corner[k][1] > 0)
            outbuf_u32(o, corner[k][1]);
        outbuf_put(o, "/", 1);
        outbuf_u32(o, corner[k][2]);
    }
    outbuf_put(o, "\n", 1);
}

static int obj_vertex(void *priv, const struct mesh_vertex *v)
{
    struct outbuf *o = priv;
    const float *p = v->pos, *n = v->normal;
    const uint16_t *rgb = v->rgb;
    /* "v x y z r g b": vertex colours as MeshLab, Blender and Open3D read them (and show them:
     * sRGB-encoded, see srgb.h). Y up, as OBJ readers assume (Blender's importer turns Y up
     * into its Z up): the object frame's (x, y, z) with z up is written (x, z, -y), a
     * right-handed turn about x. */
    const double vertex[6] = {p[0],
                              p[2],
                              -p[1],
                              srgb_encode16(rgb[0]) / 255.0,
                              srgb_encode16(rgb[1]) / 255.0,
                              srgb_encode16(rgb[2]) / 255.0};
    const double normal[3] = {n[0], n[2], -n[1]};
    obj_numbers(o, "v", vertex, 6, 4);
    obj_numbers(o, "vn", normal, 3, 5);
    return o->rc;
}

static int obj_triangle(void *priv, uint32_t a, uint32_t b, uint32_t c)
{
    struct outbuf *o = priv;
    const uint32_t corner[3][3] = {{a + 1, 0, a + 1}, {b + 1, 0, b + 1}, {c + 1, 0, c + 1}};
    obj_face(o, corner);
    return o->rc;
}

int fusion_write_obj(struct fusion_volume *vol, const struct hal_storage *st, const char *path)
{
    return fusion_write_obj_textured(vol, NULL, NULL, st, path);
}

/* One "vt" line (OBJ's v runs up from the image's bottom). */
static void obj_vt(struct outbuf *o, const float uv[2])
{
    const double x[2] = {uv[0], 1.0 - uv[1]};
    obj_numbers(o, "vt", x, 2, 6);
}

/* The kept triangles with their texture coordinates: a "vt" for each kept vertex (numbered as the
 * vertex, in its own chart), then the faces, each corner whose triangle lies in another chart
 * (a chart's border) with a "vt" of its own just before its face. */
static void obj_textured_faces(struct fusion_volume *vol, const struct atlas *atlas,
                               struct outbuf *o)
{
    float uv[2];
    for (uint32_t v = 0; v < vol->mp.s.vertices && o->rc == 0; v++) {
        if (vol->mesh_index[v] == MESH_DROPPED)
            continue;
        if (atlas_vertex_uv(atlas, vol, v, uv) != 0)
            uv[0] = uv[1] = 0.0f;
        obj_vt(o, uv);
    }
    uint32_t vt = vol->mp.s.kept_vertices;
    for (uint32_t t = 0; t < vol->mp.s.triangles && o->rc == 0; t++) {
        const uint32_t *tri = &vol->mesh_tri[3 * (size_t)t];
        uint32_t at[3];
        if (vol->mesh_index[tri[0]] == MESH_DROPPED)
            continue;
        for (int k = 0; k < 3; k++) {
            at[k] = vol->mesh_index[tri[k]] + 1;
            if (atlas_corner_is_vertex(atlas, vol, t, k) || atlas_uv(atlas, vol, t, k, uv) != 0)
                continue;
            obj_vt(o, uv);
            at[k] = ++vt;
        }
        uint32_t corner[3][3];
        for (int k = 0; k < 3; k++)
            corner[k][0] = corner[k][2] = vol->mesh_index[tri[k]] + 1, corner[k][1] = at[k];
        obj_face(o, corner);
    }
}

int fusion_write_obj_textured(struct fusion_volume *vol, const struct atlas *atlas,
                              const char *mtl_name, const struct hal_storage *st, const char *path)
{
    struct outbuf o;
    if (!vol->mp.prepared)
        return -EINVAL;
    if (outbuf_open(&o, st, path) != 0)
        return o.rc;
    outbuf_printf(&o, "# turntable colour scanner: fused mesh; units: millimetres; Y up (the "
                      "object frame's x, z, -y: its z, up the turntable's axis, is Y here); vertex "
                      "colours sRGB-encoded\n");
    int textured = atlas != NULL && mtl_name != NULL && vol->mp.fits;
    if (textured)
        outbuf_printf(&o, "mtllib %s\nusemtl scan\n", mtl_name);
    struct mesh_sink sink = {obj_vertex, textured ? NULL : obj_triangle, &o};
    fusion_extract_prepared(vol, &sink);
    if (textured)
        obj_textured_faces(vol, atlas, &o);
    return outbuf_close(&o);
}

/* One STL facet: its normal (right-handed from the vertex order), then the three corners, of
 * triangle @p t of the tables (vertex numbers before renumbering). */
static void stl_triangle(struct fusion_volume *vol, struct outbuf *o, uint32_t t)
{
    const uint32_t *tri = &vol->mesh_tri[3 * (size_t)t];
    const float *p[3] = {&vol->mesh_pos[3 * (size_t)tri[0]], &vol->mesh_pos[3 * (size_t)tri[1]],
                         &vol->mesh_pos[3 * (size_t)tri[2]]};
    vec3 e1 = v3(p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]);
    vec3 e2 = v3(p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]);
    vec3 n = v3_cross(e1, e2);
    double len = v3_len(n);
    n = len > 0.0 ? v3_scale(n, 1.0 / len) : v3(0, 0, 0);
    outbuf_f32le(o, (float)n.x);
    outbuf_f32le(o, (float)n.y);
    outbuf_f32le(o, (float)n.z);
    for (int k = 0; k < 3; k++)
        for (int d = 0; d < 3; d++)
            outbuf_f32le(o, p[k][d]);
    static const uint8_t no_attribute[2] = {0, 0};
    outbuf_put(o, no_attribute, 2);
}

int fusion_write_stl(struct fusion_volume *vol, const struct hal_storage *st, const char *path)
{
    struct outbuf o;
    if (!vol->mp.prepared)
        return -EINVAL;
    if (!vol->mp.fits)
        return -E2BIG;
    if (outbuf_open(&o, st, path) != 0)
        return o.rc;
    char header[80]; /* must not begin with "solid": readers would take it for ASCII STL */
    memset(header, 0, sizeof(header));
    strncpy(header, "turntable colour scanner: fused mesh, units millimetres", sizeof(header) - 1);
    outbuf_put(&o, header, sizeof(header));
    outbuf_u32le(&o, vol->mp.s.kept_triangles);
    for (uint32_t t = 0; t < vol->mp.s.triangles && o.rc == 0; t++)
        if (vol->mesh_index[vol->mesh_tri[3 * (size_t)t]] != MESH_DROPPED)
            stl_triangle(vol, &o, t);
    return outbuf_close(&o);
}
