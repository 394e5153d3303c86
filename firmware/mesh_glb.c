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
 * the cluster's (a primitive each, sharing the vertices). */
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
    const uint8_t rgba[4] = {v->rgb[0], v->rgb[1], v->rgb[2], 255};
    outbuf_put(o, rgba, 4);
    return o->rc;
}

/* The mesh's materials: one per cluster of [colour] method = fit (reflect.h), else one matte. */
struct glb_parts {
    uint32_t count;                           /* materials, one primitive each */
    uint32_t triangles[REFLECT_MAX_CLUSTERS]; /* of each */
    const struct reflect_model *model;        /* NULL: matte */
};

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
static void json_material(struct fusion_volume *vol, const struct reflect_cluster *c, uint32_t k)
{
    double a = c->roughness, f0[3];
    for (int ch = 0; ch < 3; ch++)
        f0[ch] = 4.0 * a * a * c->specular[ch];
    json_put(vol,
             "%s{\"name\":\"cluster %u\",\"pbrMetallicRoughness\":{\"baseColorFactor\":"
             "[1,1,1,1],\"metallicFactor\":0,\"roughnessFactor\":%.4f},\"extensions\":"
             "{\"KHR_materials_specular\":{\"specularFactor\":1,\"specularColorFactor\":"
             "[%.5f,%.5f,%.5f]}}}",
             k ? "," : "", (unsigned)k, fmin(1.0, sqrt(a)), f0[0] / 0.04, f0[1] / 0.04,
             f0[2] / 0.04);
}

/* The JSON chunk's text for @p vertices and @p parts within @p b, padded with spaces to a
 * multiple of 4: buffer views positions, normals, colours, then each part's indices.
 * @retval its length @retval -EOVERFLOW it did not fit vol->glb_json */
static int glb_json_text(struct fusion_volume *vol, uint32_t vertices,
                         const struct glb_parts *parts, const struct glb_bounds *b,
                         uint64_t bin_len)
{
    uint64_t v = vertices, pos_len = 12 * v, col_len = 4 * v, at = 2 * pos_len + col_len;
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
                     "%s{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"COLOR_0\":2},"
                     "\"indices\":%u,\"material\":%u,\"mode\":4}",
                     n ? "," : "", (unsigned)(3 + n), (unsigned)k);
            n++;
        }
    json_put(vol, "]}],\"materials\":[");
    if (parts->model == NULL)
        json_put(vol, "{\"name\":\"matte\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[1,1,1,1],"
                      "\"metallicFactor\":0,\"roughnessFactor\":1}}");
    for (uint32_t k = 0; parts->model != NULL && k < parts->count; k++)
        json_material(vol, &parts->model->cluster[k], k);
    json_put(vol,
             "],\"buffers\":[{\"byteLength\":%llu}],\"bufferViews\":["
             "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%llu,\"target\":%d},"
             "{\"buffer\":0,\"byteOffset\":%llu,\"byteLength\":%llu,\"target\":%d},"
             "{\"buffer\":0,\"byteOffset\":%llu,\"byteLength\":%llu,\"target\":%d}",
             (unsigned long long)bin_len, (unsigned long long)pos_len, GL_ARRAY_BUFFER,
             (unsigned long long)pos_len, (unsigned long long)pos_len, GL_ARRAY_BUFFER,
             (unsigned long long)(2 * pos_len), (unsigned long long)col_len, GL_ARRAY_BUFFER);
    for (uint32_t k = 0; k < parts->count; k++) {
        uint64_t len = 12 * (uint64_t)parts->triangles[k];
        if (len > 0)
            json_put(vol, ",{\"buffer\":0,\"byteOffset\":%llu,\"byteLength\":%llu,\"target\":%d}",
                     (unsigned long long)at, (unsigned long long)len, GL_ELEMENT_ARRAY_BUFFER);
        at += len;
    }
    json_put(vol,
             "],\"accessors\":["
             "{\"bufferView\":0,\"componentType\":%d,\"count\":%u,\"type\":\"VEC3\","
             "\"min\":[%.9g,%.9g,%.9g],\"max\":[%.9g,%.9g,%.9g]},"
             "{\"bufferView\":1,\"componentType\":%d,\"count\":%u,\"type\":\"VEC3\"},"
             "{\"bufferView\":2,\"componentType\":%d,\"normalized\":true,\"count\":%u,"
             "\"type\":\"VEC4\"}",
             GL_FLOAT, (unsigned)vertices, (double)b->lo[0], (double)b->lo[1], (double)b->lo[2],
             (double)b->hi[0], (double)b->hi[1], (double)b->hi[2], GL_FLOAT, (unsigned)vertices,
             GL_UNSIGNED_BYTE, (unsigned)vertices);
    for (uint32_t k = 0, n = 0; k < parts->count; k++)
        if (parts->triangles[k] > 0)
            json_put(vol,
                     ",{\"bufferView\":%u,\"componentType\":%d,\"count\":%llu,\"type\":"
                     "\"SCALAR\"}",
                     (unsigned)(3 + n++), GL_UNSIGNED_INT,
                     (unsigned long long)(3 * (uint64_t)parts->triangles[k]));
    json_put(vol, "]}");
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
    double rho[3] = {v->rgb[0] / 255.0, v->rgb[1] / 255.0, v->rgb[2] / 255.0};
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

int fusion_write_glb(struct fusion_volume *vol, const struct hal_storage *st, const char *path,
                     const struct reflect_model *model)
{
    struct mesh_summary ms;
    struct outbuf o;
    int rc = fusion_mesh_counts(vol, &ms);
    if (rc != 0)
        return rc;
    if (ms.kept_vertices == 0)
        return -ENODATA; /* an accessor must count at least one element */
    struct glb_scan gs = {vol->vertex_part,
                          {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}},
                          {1, {0}, model},
                          0};
    if (gs.parts.model != NULL)
        gs.parts.count = gs.parts.model->count;
    struct mesh_sink scan_pass = {scan_vertex, scan_triangle, &gs};
    fusion_extract_prepared(vol, &scan_pass);
    const struct glb_parts parts = gs.parts;
    uint64_t bin_len = 28 * (uint64_t)ms.kept_vertices;
    for (uint32_t k = 0; k < parts.count; k++)
        bin_len += 12 * (uint64_t)parts.triangles[k];
    int json = glb_json_text(vol, ms.kept_vertices, &parts, &gs.bounds, bin_len);
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
    struct mesh_sink passes[3] = {
        {position_vertex, NULL, &o}, {normal_vertex, NULL, &o}, {colour_vertex, NULL, &o}};
    for (int k = 0; k < 3 && o.rc == 0; k++)
        fusion_extract_prepared(vol, &passes[k]);
    for (uint32_t k = 0; k < parts.count && o.rc == 0; k++) {
        struct index_pass ip = {vol->vertex_part, &o, (uint8_t)k};
        struct mesh_sink pass = {NULL, index_triangle, &ip};
        if (parts.triangles[k] > 0)
            fusion_extract_prepared(vol, &pass);
    }
    return outbuf_close(&o);
}
