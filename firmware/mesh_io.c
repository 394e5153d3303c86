/* The fused mesh as binary PLY and OBJ. PLY needs its counts first and its vertices before its
 * faces, so marching cubes runs three times (count, vertices, faces); it is deterministic. */
#include "fusion.h"
#include "outbuf.h"
#include "ply.h"

struct mesh_count {
    uint32_t vertices, triangles;
};

static int count_vertex(void *priv, const float p[3], const float n[3], const uint8_t rgb[3])
{
    (void)p;
    (void)n;
    (void)rgb;
    ((struct mesh_count *)priv)->vertices++;
    return 0;
}

static int count_triangle(void *priv, uint32_t a, uint32_t b, uint32_t c)
{
    (void)a;
    (void)b;
    (void)c;
    ((struct mesh_count *)priv)->triangles++;
    return 0;
}

static int ply_vertex(void *priv, const float p[3], const float n[3], const uint8_t rgb[3])
{
    struct outbuf *o = priv;
    ply_put_vertex(o, v3(p[0], p[1], p[2]), v3(n[0], n[1], n[2]), rgb);
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

int fusion_write_ply(const struct hal_storage *st, const char *path, uint32_t *vertices,
                     uint32_t *triangles)
{
    struct mesh_count count = {0, 0};
    struct mesh_sink counter = {count_vertex, count_triangle, &count};
    int rc = fusion_extract(&counter);
    if (rc != 0)
        return rc;
    struct outbuf o;
    if (outbuf_open(&o, st, path) != 0)
        return o.rc;
    ply_put_header(&o, "fused mesh", count.vertices, count.triangles, 0);
    struct mesh_sink vertex_pass = {ply_vertex, NULL, &o};
    struct mesh_sink face_pass = {NULL, ply_triangle, &o};
    fusion_extract(&vertex_pass);
    fusion_extract(&face_pass);
    rc = outbuf_close(&o);
    if (rc == 0) {
        *vertices = count.vertices;
        *triangles = count.triangles;
    }
    return rc;
}

static int obj_vertex(void *priv, const float p[3], const float n[3], const uint8_t rgb[3])
{
    struct outbuf *o = priv;
    /* "v x y z r g b": vertex colours as MeshLab, Blender and Open3D read them */
    outbuf_printf(o, "v %.4f %.4f %.4f %.4f %.4f %.4f\nvn %.5f %.5f %.5f\n", p[0], p[1], p[2],
                  rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0, n[0], n[1], n[2]);
    return o->rc;
}

static int obj_triangle(void *priv, uint32_t a, uint32_t b, uint32_t c)
{
    struct outbuf *o = priv;
    outbuf_printf(o, "f %u//%u %u//%u %u//%u\n", a + 1, a + 1, b + 1, b + 1, c + 1, c + 1);
    return o->rc;
}

int fusion_write_obj(const struct hal_storage *st, const char *path)
{
    struct outbuf o;
    if (outbuf_open(&o, st, path) != 0)
        return o.rc;
    outbuf_printf(&o, "# turntable colour scanner: fused mesh; units: millimetres\n");
    struct mesh_sink sink = {obj_vertex, obj_triangle, &o};
    fusion_extract(&sink);
    return outbuf_close(&o);
}
