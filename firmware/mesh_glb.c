/* The fused mesh as glTF 2.0 binary (mesh.glb): what web viewers, Blender and game engines open.
 *
 * Written by hand rather than with a library: Debian's glTF writer (libtinygltf-dev) is C++ and
 * builds the whole document in heap memory, while a GLB of one mesh is a fixed JSON text and four
 * arrays that stream from the prepared tables (fusion_extract_prepared) with no allocation.
 *
 * The file (glTF 2.0 specification, "Binary glTF Layout"): a 12-byte header (magic "glTF",
 * version 2, total length), a JSON chunk padded with spaces to 4 bytes, a BIN chunk padded with
 * zeros. The BIN chunk holds, in this order: positions (float VEC3), normals (float VEC3, unit),
 * colours (normalized ubyte VEC4: 4 bytes so that every element is 4-byte aligned, as vertex
 * attributes must be), triangle indices (uint SCALAR). glTF's conventions: metres, +Y up (the
 * object frame's (x, y, z), z up the turntable's axis, is written (x, z, -y), as for OBJ), and
 * COLOR_0 is linear, so the fused albedo goes in as it is; the material multiplies it by its
 * base colour factor 1. One material, matte; with [colour] method = fit one per material
 * cluster (json_material), each with the triangles whose first vertex's colour is nearest to
 * the cluster's (a primitive each, sharing the vertices).
 *
 * With a texture atlas (fusion_write_glb_textured) COLOR_0 gives way to TEXCOORD_0 (glTF
 * multiplies the two: the texture alone is the colour) and the texture's PNG follows the indices
 * in the BIN chunk, the base colour texture of every material (sRGB, as glTF's base colour is).
 * A vertex on a chart's border has one place in the texture for each chart about it: after the
 * kept vertices come the "border corners", one vertex each (position and normal repeated), in
 * the order of their triangles (atlas_corner_is_vertex). */
#include "atlas.h"
#include "fusion.h"
#include "outbuf.h"
#include "reflect.h"

#include <errno.h>
#include <stdarg.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define GLB_MAGIC 0x46546C67u      /* "glTF" */
#define GLB_CHUNK_JSON 0x4E4F534Au /* "JSON" */
#define GLB_CHUNK_BIN 0x004E4942u  /* "BIN\0" */
#define GL_FLOAT 5126
#define GL_UNSIGNED_BYTE 5121
#define GL_UNSIGNED_INT 5125
#define GL_ARRAY_BUFFER 34962
#define GL_ELEMENT_ARRAY_BUFFER 34963

/* The JSON of one mesh (vol->glb_json): about 1 KB, and about 650 bytes more per material
 * cluster (a material, a primitive, a buffer view and an accessor each): REFLECT_MAX_CLUSTERS fit
 * well within FUSION_GLB_JSON_MAX. */

/* Position in glTF's frame: metres, Y up. */
static void gltf_position(const float p[3], float out[3])
{
    out[0] = p[0] / 1000.0f;
    out[1] = p[2] / 1000.0f;
    out[2] = -p[1] / 1000.0f;
}

struct glb_bounds {
    float lo[3], hi[3];
};

static int position_vertex(void *priv, const struct mesh_vertex *v)
{
    struct outbuf *o = priv;
    float q[3];
    gltf_position(v->pos, q);
    for (int k = 0; k < 3; k++)
        outbuf_f32le(o, q[k]);
    return o->rc;
}

/* Normals must be unit length (the validator checks): a degenerate one points up. */
static int normal_vertex(void *priv, const struct mesh_vertex *v)
{
    struct outbuf *o = priv;
    const float *n = v->normal;
    double len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
    float q[3] = {0.0f, 1.0f, 0.0f};
    if (len > 1e-12) {
        q[0] = (float)(n[0] / len);
        q[1] = (float)(n[2] / len);
        q[2] = (float)(-n[1] / len);
    }
    for (int k = 0; k < 3; k++)
        outbuf_f32le(o, q[k]);
    return o->rc;
}

static int colour_vertex(void *priv, const struct mesh_vertex *v)
{
    struct outbuf *o = priv;
    /* normalized bytes, linear (the vertex's 16 bits rounded: a viewer shows no more) */
    uint8_t rgba[4] = {0, 0, 0, 255};
    for (int k = 0; k < 3; k++)
        rgba[k] = (uint8_t)((v->rgb[k] + MESH_RGB_PER_BYTE / 2u) / MESH_RGB_PER_BYTE);
    outbuf_put(o, rgba, 4);
    return o->rc;
}

/* The mesh's materials: one per cluster of [colour] method = fit (reflect.h), else one matte;
 * with a texture, its PNG's length (0: none, vertex colours). */
struct glb_parts {
    uint32_t count;                           /* materials, one primitive each */
    uint32_t triangles[REFLECT_MAX_CLUSTERS]; /* of each */
    const struct reflect_model *model;        /* NULL: matte */
    uint64_t png_len;
};

/* A material's base colour texture, when there is one. */
static const char *texture_ref(const struct glb_parts *parts)
{
    return parts->png_len > 0 ? ",\"baseColorTexture\":{\"index\":0}" : "";
}

static void json_put(struct fusion_volume *vol, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    if (vol->glb_json_len >= 0) {
        int n = vsnprintf(vol->glb_json + vol->glb_json_len,
                          sizeof(vol->glb_json) - (size_t)vol->glb_json_len, fmt, ap);
        vol->glb_json_len = n < 0 || (size_t)n >= sizeof(vol->glb_json) - (size_t)vol->glb_json_len
                                ? -1
                                : vol->glb_json_len + n;
    }
    va_end(ap);
}

/* A cluster's lobe as a glTF material (metallic-roughness, KHR_materials_specular). The lobe
 * K D(alpha) / cos(theta_r), D GGX scaled to 1 at its peak, in units where a matte surface gives
 * rho cos(theta_i), is pi f cos(theta_i) of a microfacet BRDF f = D G F / (4 cos_i cos_o) with
 * the normalised GGX D (peak 1 / (pi a^2)) and G = 1: F0 = 4 a^2 K. glTF's GGX takes
 * alpha = roughness^2. Dielectric (metallic 0): a metal's tinted F0 is the specular colour. */
static void json_material(struct fusion_volume *vol, const struct reflect_cluster *c, uint32_t k,
                          const char *texture)
{
    double a = c->roughness, f0[3];
    for (int ch = 0; ch < 3; ch++)
        f0[ch] = 4.0 * a * a * c->specular[ch];
    json_put(vol,
             "%s{\"name\":\"cluster %u\",\"pbrMetallicRoughness\":{\"baseColorFactor\":"
             "[1,1,1,1],\"metallicFactor\":0,\"roughnessFactor\":%.4f%s},\"extensions\":"
             "{\"KHR_materials_specular\":{\"specularFactor\":1,\"specularColorFactor\":"
             "[%.5f,%.5f,%.5f]}}}",
             k ? "," : "", (unsigned)k, fmin(1.0, sqrt(a)), texture, f0[0] / 0.04, f0[1] / 0.04,
             f0[2] / 0.04);
}

/* The JSON chunk's text for @p vertices and @p parts within @p b, padded with spaces to a
 * multiple of 4: buffer views positions, normals, colours, then each part's indices.
 * @retval its length @retval -EOVERFLOW it did not fit vol->glb_json */
static int glb_json_text(struct fusion_volume *vol, uint32_t vertices,
                         const struct glb_parts *parts, const struct glb_bounds *b,
                         uint64_t bin_len)
{
    const int textured = parts->png_len > 0;
    uint64_t v = vertices, pos_len = 12 * v, col_len = (textured ? 8 : 4) * v;
    uint64_t at = 2 * pos_len + col_len;
    vol->glb_json_len = 0;
    json_put(vol, "{\"asset\":{\"version\":\"2.0\",\"generator\":\"turntable colour scanner\"},");
    if (parts->model != NULL)
        json_put(vol, "\"extensionsUsed\":[\"KHR_materials_specular\"],");
    json_put(vol,
             "\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0,\"name\":\"scan\"}],"
             "\"meshes\":[{\"name\":\"fused mesh\",\"primitives\":[");
    /* a cluster without triangles has no primitive, view nor accessor (none may be empty) */
    for (uint32_t k = 0, n = 0; k < parts->count; k++)
        if (parts->triangles[k] > 0) {
            json_put(vol,
                     "%s{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"%s\":2},"
                     "\"indices\":%u,\"material\":%u,\"mode\":4}",
                     n ? "," : "", textured ? "TEXCOORD_0" : "COLOR_0", (unsigned)(3 + n),
                     (unsigned)k);
            n++;
        }
    json_put(vol, "]}],\"materials\":[");
    if (parts->model == NULL)
        json_put(vol,
                 "{\"name\":\"matte\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,1],"
                 "\"metallicFactor\":0,\"roughnessFactor\":1%s}}",
                 texture_ref(parts));
    for (uint32_t k = 0; parts->model != NULL && k < parts->count; k++)
        json_material(vol, &parts->model->cluster[k], k, texture_ref(parts));
    json_put(vol,
             "],\"buffers\":[{\"byteLength\":%llu}],\"bufferViews\":["
             "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%llu,\"target\":%d},"
             "{\"buffer\":0,\"byteOffset\":%llu,\"byteLength\":%llu,\"target\":%d},"
             "{\"buffer\":0,\"byteOffset\":%llu,\"byteLength\":%llu,\"target\":%d}",
             (unsigned long long)bin_len, (unsigned long long)pos_len, GL_ARRAY_BUFFER,
             (unsigned long long)pos_len, (unsigned long long)pos_len, GL_ARRAY_BUFFER,
             (unsigned long long)(2 * pos_len), (unsigned long long)col_len, GL_ARRAY_BUFFER);
    uint32_t views = 3;
    for (uint32_t k = 0; k < parts->count; k++) {
        uint64_t len = 12 * (uint64_t)parts->triangles[k];
        if (len > 0)
            json_put(vol, ",{\"buffer\":0,\"byteOffset\":%llu,\"byteLength\":%llu,\"target\":%d}",
                     (unsigned long long)at, (unsigned long long)len, GL_ELEMENT_ARRAY_BUFFER);
        views += len > 0;
        at += len;
    }
    if (textured) /* the image's view: no target (not a vertex attribute nor indices) */
        json_put(vol, ",{\"buffer\":0,\"byteOffset\":%llu,\"byteLength\":%llu}",
                 (unsigned long long)at, (unsigned long long)parts->png_len);
    json_put(vol,
             "],\"accessors\":["
             "{\"bufferView\":0,\"componentType\":%d,\"count\":%u,\"type\":\"VEC3\","
             "\"min\":[%.9g,%.9g,%.9g],\"max\":[%.9g,%.9g,%.9g]},"
             "{\"bufferView\":1,\"componentType\":%d,\"count\":%u,\"type\":\"VEC3\"},"
             "{\"bufferView\":2,\"componentType\":%d%s,\"count\":%u,"
             "\"type\":\"%s\"}",
             GL_FLOAT, (unsigned)vertices, (double)b->lo[0], (double)b->lo[1], (double)b->lo[2],
             (double)b->hi[0], (double)b->hi[1], (double)b->hi[2], GL_FLOAT, (unsigned)vertices,
             textured ? GL_FLOAT : GL_UNSIGNED_BYTE, textured ? "" : ",\"normalized\":true",
             (unsigned)vertices, textured ? "VEC2" : "VEC4");
    for (uint32_t k = 0, n = 0; k < parts->count; k++)
        if (parts->triangles[k] > 0)
            json_put(vol,
                     ",{\"bufferView\":%u,\"componentType\":%d,\"count\":%llu,\"type\":"
                     "\"SCALAR\"}",
                     (unsigned)(3 + n++), GL_UNSIGNED_INT,
                     (unsigned long long)(3 * (uint64_t)parts->triangles[k]));
    json_put(vol, "]");
    if (textured) /* linear magnification, trilinear minification, edges clamped */
        json_put(vol,
                 ",\"images\":[{\"bufferView\":%u,\"mimeType\":\"image/png\"}],"
                 "\"samplers\":[{\"magFilter\":9729,\"minFilter\":9987,\"wrapS\":33071,"
                 "\"wrapT\":33071}],\"textures\":[{\"sampler\":0,\"source\":0}]",
                 (unsigned)views);
    json_put(vol, "}");
    if (vol->glb_json_len < 0 || (size_t)vol->glb_json_len + 4 > sizeof(vol->glb_json))
        return -EOVERFLOW;
    while (vol->glb_json_len % 4 != 0)
        vol->glb_json[vol->glb_json_len++] = ' ';
    return vol->glb_json_len;
}

/* What the JSON, which precedes the data, must say, in one pass over the mesh (its vertices
 * come before its triangles): POSITION's min and max, each vertex's cluster (by its colour) and
 * each cluster's triangles (by their first vertex). */
struct glb_scan {
    uint8_t *vertex_part; /* each vertex's cluster */
    struct glb_bounds bounds;
    struct glb_parts parts;
    uint32_t vertices;
};

static int scan_vertex(void *priv, const struct mesh_vertex *v)
{
    struct glb_scan *gs = priv;
    const struct reflect_model *m = gs->parts.model;
    float q[3];
    gltf_position(v->pos, q);
    for (int k = 0; k < 3; k++) {
        gs->bounds.lo[k] = q[k] < gs->bounds.lo[k] ? q[k] : gs->bounds.lo[k];
        gs->bounds.hi[k] = q[k] > gs->bounds.hi[k] ? q[k] : gs->bounds.hi[k];
    }
    double rho[3] = {(double)v->rgb[0] / MESH_RGB_ONE, (double)v->rgb[1] / MESH_RGB_ONE,
                     (double)v->rgb[2] / MESH_RGB_ONE};
    gs->vertex_part[gs->vertices++] = m != NULL ? (uint8_t)reflect_cluster_of(m, rho) : 0;
    return 0;
}

static int scan_triangle(void *priv, uint32_t a, uint32_t b, uint32_t c)
{
    struct glb_scan *gs = priv;
    (void)b;
    (void)c;
    gs->parts.triangles[gs->vertex_part[a]]++;
    return 0;
}

/* The indices of part @p part only. */
struct index_pass {
    const uint8_t *vertex_part;
    struct outbuf *o;
    uint8_t part;
};

static int index_triangle(void *priv, uint32_t a, uint32_t b, uint32_t c)
{
    struct index_pass *ip = priv;
    if (ip->vertex_part[a] != ip->part)
        return 0;
    outbuf_u32le(ip->o, a);
    outbuf_u32le(ip->o, b);
    outbuf_u32le(ip->o, c);
    return ip->o->rc;
}

/* ---- a texture's border corners (atlas.h) ---- */

/* Whether corner @p k of kept triangle @p t is a border corner: a vertex of its own. */
static int border_corner(const struct fusion_volume *vol, const struct atlas *atlas, uint32_t t,
                         int k)
{
    return atlas != NULL && !atlas_corner_is_vertex(atlas, vol, t, k);
}

static int kept_triangle(const struct fusion_volume *vol, uint32_t t)
{
    return vol->mesh_index[vol->mesh_tri[3 * (size_t)t]] != MESH_DROPPED;
}

static uint32_t count_border_corners(const struct fusion_volume *vol, const struct atlas *atlas)
{
    uint32_t n = 0;
    for (uint32_t t = 0; t < vol->mp.s.triangles; t++)
        for (int k = 0; k < 3 && kept_triangle(vol, t); k++)
            n += (uint32_t)border_corner(vol, atlas, t, k);
    return n;
}

/* The border corners' positions or normals (@p sink's vertex callback), in their order. */
static void border_vertices(struct fusion_volume *vol, const struct atlas *atlas,
                            const struct mesh_sink *sink)
{
    struct mesh_vertex mv;
    memset(&mv, 0, sizeof(mv));
    for (uint32_t t = 0; t < vol->mp.s.triangles; t++)
        for (int k = 0; k < 3 && kept_triangle(vol, t); k++) {
            if (!border_corner(vol, atlas, t, k))
                continue;
            uint32_t v = vol->mesh_tri[3 * (size_t)t + (size_t)k];
            memcpy(mv.pos, &vol->mesh_pos[3 * (size_t)v], sizeof(mv.pos));
            memcpy(mv.normal, &vol->mesh_nrm[3 * (size_t)v], sizeof(mv.normal));
            sink->vertex(sink->priv, &mv);
        }
}

/* TEXCOORD_0 of the kept vertices, then of the border corners. */
static void texcoords(struct fusion_volume *vol, const struct atlas *atlas, struct outbuf *o)
{
    float uv[2];
    for (uint32_t v = 0; v < vol->mp.s.vertices; v++) {
        if (vol->mesh_index[v] == MESH_DROPPED)
            continue;
        if (atlas_vertex_uv(atlas, vol, v, uv) != 0)
            uv[0] = uv[1] = 0.0f;
        outbuf_f32le(o, uv[0]);
        outbuf_f32le(o, uv[1]);
    }
    for (uint32_t t = 0; t < vol->mp.s.triangles; t++)
        for (int k = 0; k < 3 && kept_triangle(vol, t); k++)
            if (border_corner(vol, atlas, t, k) && atlas_uv(atlas, vol, t, k, uv) == 0) {
                outbuf_f32le(o, uv[0]);
                outbuf_f32le(o, uv[1]);
            }
}

/* The indices of part @p part with the border corners numbered after the kept vertices. */
static void textured_indices(struct fusion_volume *vol, const struct atlas *atlas, struct outbuf *o,
                             uint8_t part)
{
    uint32_t next = vol->mp.s.kept_vertices;
    for (uint32_t t = 0; t < vol->mp.s.triangles; t++) {
        const uint32_t *tri = &vol->mesh_tri[3 * (size_t)t];
        uint32_t at[3];
        if (!kept_triangle(vol, t))
            continue;
        for (int k = 0; k < 3; k++)
            at[k] = border_corner(vol, atlas, t, k) ? next++ : vol->mesh_index[tri[k]];
        if (vol->vertex_part[vol->mesh_index[tri[0]]] != part)
            continue;
        for (int k = 0; k < 3; k++)
            outbuf_u32le(o, at[k]);
    }
}

int fusion_write_glb(struct fusion_volume *vol, const struct hal_storage *st, const char *path,
                     const struct reflect_model *model)
{
    return fusion_write_glb_textured(vol, st, path, model, NULL, NULL, 0);
}

int fusion_write_glb_textured(struct fusion_volume *vol, const struct hal_storage *st,
                              const char *path, const struct reflect_model *model,
                              const struct atlas *atlas, const uint8_t *png, size_t png_len)
{
    struct mesh_summary ms;
    struct outbuf o;
    int rc = fusion_mesh_counts(vol, &ms);
    if (rc != 0)
        return rc;
    if (ms.kept_vertices == 0)
        return -ENODATA; /* an accessor must count at least one element */
    if (atlas == NULL || png == NULL || png_len == 0)
        atlas = NULL, png_len = 0;
    struct glb_scan gs = {vol->vertex_part,
                          {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}},
                          {1, {0}, model, png_len},
                          0};
    if (gs.parts.model != NULL)
        gs.parts.count = gs.parts.model->count;
    struct mesh_sink scan_pass = {scan_vertex, scan_triangle, &gs};
    fusion_extract_prepared(vol, &scan_pass);
    const struct glb_parts parts = gs.parts;
    const uint64_t vertices = ms.kept_vertices + (uint64_t)count_border_corners(vol, atlas);
    uint64_t bin_len = (atlas != NULL ? 32 : 28) * vertices + ((png_len + 3) & ~(uint64_t)3);
    for (uint32_t k = 0; k < parts.count; k++)
        bin_len += 12 * (uint64_t)parts.triangles[k];
    if (vertices > UINT32_MAX)
        return -EFBIG;
    int json = glb_json_text(vol, (uint32_t)vertices, &parts, &gs.bounds, bin_len);
    if (json < 0)
        return json;
    uint64_t total = 12 + 8 + (uint64_t)json + 8 + bin_len; /* bin_len is 4-aligned */
    if (total > UINT32_MAX)
        return -EFBIG; /* GLB counts its length in 32 bits */
    if (outbuf_open(&o, st, path) != 0)
        return o.rc;
    outbuf_u32le(&o, GLB_MAGIC);
    outbuf_u32le(&o, 2);
    outbuf_u32le(&o, (uint32_t)total);
    outbuf_u32le(&o, (uint32_t)json);
    outbuf_u32le(&o, GLB_CHUNK_JSON);
    outbuf_put(&o, vol->glb_json, (size_t)json);
    outbuf_u32le(&o, (uint32_t)bin_len);
    outbuf_u32le(&o, GLB_CHUNK_BIN);
    struct mesh_sink passes[2] = {{position_vertex, NULL, &o}, {normal_vertex, NULL, &o}};
    for (int k = 0; k < 2 && o.rc == 0; k++) {
        fusion_extract_prepared(vol, &passes[k]);
        if (atlas != NULL)
            border_vertices(vol, atlas, &passes[k]);
    }
    struct mesh_sink colours = {colour_vertex, NULL, &o};
    if (atlas != NULL)
        texcoords(vol, atlas, &o);
    else
        fusion_extract_prepared(vol, &colours);
    for (uint32_t k = 0; k < parts.count && o.rc == 0; k++) {
        struct index_pass ip = {vol->vertex_part, &o, (uint8_t)k};
        struct mesh_sink pass = {NULL, index_triangle, &ip};
        if (parts.triangles[k] > 0 && atlas != NULL)
            textured_indices(vol, atlas, &o, (uint8_t)k);
        else if (parts.triangles[k] > 0)
            fusion_extract_prepared(vol, &pass);
    }
    if (png_len > 0) {
        static const uint8_t zero[3] = {0, 0, 0};
        outbuf_put(&o, png, png_len);
        outbuf_put(&o, zero, (4 - png_len % 4) % 4);
    }
    return outbuf_close(&o);
}
