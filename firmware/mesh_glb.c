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
 * base colour factor 1. */
#include "fusion.h"
#include "outbuf.h"

#include <errno.h>
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

/* The JSON of one mesh with four accessors: well under this, whatever the counts. */
static char glb_json[4096];

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

/* POSITION needs its min and max in the JSON, which precedes the data: a pass for them. */
static int bounds_vertex(void *priv, const struct mesh_vertex *v)
{
    struct glb_bounds *b = priv;
    float q[3];
    gltf_position(v->pos, q);
    for (int k = 0; k < 3; k++) {
        b->lo[k] = q[k] < b->lo[k] ? q[k] : b->lo[k];
        b->hi[k] = q[k] > b->hi[k] ? q[k] : b->hi[k];
    }
    return 0;
}

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

static int index_triangle(void *priv, uint32_t a, uint32_t b, uint32_t c)
{
    struct outbuf *o = priv;
    outbuf_u32le(o, a);
    outbuf_u32le(o, b);
    outbuf_u32le(o, c);
    return o->rc;
}

/* The JSON chunk's text for @p vertices and @p triangles within @p b, padded with spaces to a
 * multiple of 4. @retval its length @retval -EOVERFLOW it did not fit glb_json */
static int glb_json_text(uint32_t vertices, uint32_t triangles, const struct glb_bounds *b)
{
    uint64_t v = vertices, pos_len = 12 * v, col_len = 4 * v, idx_len = 12 * (uint64_t)triangles;
    int n = snprintf(
        glb_json, sizeof(glb_json),
        "{\"asset\":{\"version\":\"2.0\",\"generator\":\"turntable colour scanner\"},"
        "\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
        "\"nodes\":[{\"mesh\":0,\"name\":\"scan\"}],"
        "\"meshes\":[{\"name\":\"fused mesh\",\"primitives\":[{\"attributes\":{\"POSITION\":0,"
        "\"NORMAL\":1,\"COLOR_0\":2},\"indices\":3,\"material\":0,\"mode\":4}]}],"
        "\"materials\":[{\"name\":\"diffuse\",\"pbrMetallicRoughness\":{\"baseColorFactor\":"
        "[1,1,1,1],\"metallicFactor\":0,\"roughnessFactor\":1}}],"
        "\"buffers\":[{\"byteLength\":%llu}],"
        "\"bufferViews\":["
        "{\"buffer\":0,\"byteOffset\":0,\"byteLength\":%llu,\"target\":%d},"
        "{\"buffer\":0,\"byteOffset\":%llu,\"byteLength\":%llu,\"target\":%d},"
        "{\"buffer\":0,\"byteOffset\":%llu,\"byteLength\":%llu,\"target\":%d},"
        "{\"buffer\":0,\"byteOffset\":%llu,\"byteLength\":%llu,\"target\":%d}],"
        "\"accessors\":["
        "{\"bufferView\":0,\"componentType\":%d,\"count\":%u,\"type\":\"VEC3\","
        "\"min\":[%.9g,%.9g,%.9g],\"max\":[%.9g,%.9g,%.9g]},"
        "{\"bufferView\":1,\"componentType\":%d,\"count\":%u,\"type\":\"VEC3\"},"
        "{\"bufferView\":2,\"componentType\":%d,\"normalized\":true,\"count\":%u,"
        "\"type\":\"VEC4\"},"
        "{\"bufferView\":3,\"componentType\":%d,\"count\":%llu,\"type\":\"SCALAR\"}]}",
        (unsigned long long)(2 * pos_len + col_len + idx_len), (unsigned long long)pos_len,
        GL_ARRAY_BUFFER, (unsigned long long)pos_len, (unsigned long long)pos_len, GL_ARRAY_BUFFER,
        (unsigned long long)(2 * pos_len), (unsigned long long)col_len, GL_ARRAY_BUFFER,
        (unsigned long long)(2 * pos_len + col_len), (unsigned long long)idx_len,
        GL_ELEMENT_ARRAY_BUFFER, GL_FLOAT, (unsigned)vertices, (double)b->lo[0], (double)b->lo[1],
        (double)b->lo[2], (double)b->hi[0], (double)b->hi[1], (double)b->hi[2], GL_FLOAT,
        (unsigned)vertices, GL_UNSIGNED_BYTE, (unsigned)vertices, GL_UNSIGNED_INT,
        (unsigned long long)(3 * (uint64_t)triangles));
    if (n < 0 || (size_t)n + 4 > sizeof(glb_json))
        return -EOVERFLOW;
    while (n % 4 != 0)
        glb_json[n++] = ' ';
    return n;
}

int fusion_write_glb(const struct hal_storage *st, const char *path)
{
    struct mesh_summary ms;
    struct outbuf o;
    int rc = fusion_mesh_counts(&ms);
    if (rc != 0)
        return rc;
    if (ms.kept_vertices == 0)
        return -ENODATA; /* an accessor must count at least one element */
    struct glb_bounds b = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    struct mesh_sink bounds_pass = {bounds_vertex, NULL, &b};
    fusion_extract_prepared(&bounds_pass);
    int json_len = glb_json_text(ms.kept_vertices, ms.kept_triangles, &b);
    if (json_len < 0)
        return json_len;
    uint64_t bin_len = 28 * (uint64_t)ms.kept_vertices + 12 * (uint64_t)ms.kept_triangles;
    uint64_t total = 12 + 8 + (uint64_t)json_len + 8 + bin_len; /* bin_len is 4-aligned */
    if (total > UINT32_MAX)
        return -EFBIG; /* GLB counts its length in 32 bits */
    if (outbuf_open(&o, st, path) != 0)
        return o.rc;
    outbuf_u32le(&o, GLB_MAGIC);
    outbuf_u32le(&o, 2);
    outbuf_u32le(&o, (uint32_t)total);
    outbuf_u32le(&o, (uint32_t)json_len);
    outbuf_u32le(&o, GLB_CHUNK_JSON);
    outbuf_put(&o, glb_json, (size_t)json_len);
    outbuf_u32le(&o, (uint32_t)bin_len);
    outbuf_u32le(&o, GLB_CHUNK_BIN);
    struct mesh_sink passes[4] = {{position_vertex, NULL, &o},
                                  {normal_vertex, NULL, &o},
                                  {colour_vertex, NULL, &o},
                                  {NULL, index_triangle, &o}};
    for (int k = 0; k < 4 && o.rc == 0; k++)
        fusion_extract_prepared(&passes[k]);
    return outbuf_close(&o);
}
