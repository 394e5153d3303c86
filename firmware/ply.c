/* Binary PLY point cloud of a view, explicit little-endian byte order. */
#include "ply.h"

#include "outbuf.h"
#include "srgb.h"

/* x, y, z, nx, ny, nz, then red, green, blue bytes and their three linear floats */
#define PLY_VERTEX_BYTES (6 * 4 + 3 + 3 * 4)

static uint32_t count_valid(const struct decode_maps *maps)
{
    uint32_t n = 0;
    size_t total = (size_t)maps->width * maps->height;
    for (size_t i = 0; i < total; i++)
        n += maps->reason[i] == SCAN_VALID;
    return n;
}

/* A vertex: its position and normal, @p encoded (sRGB bytes: viewers show 8-bit colours as
 * sRGB), then the linear values @p num / @p den as floats. Made whole and appended at once
 * (a view's cloud has 10^5 to 10^6 of them: ten appends each were a fifth of its writing's
 * instructions, callgrind). */
static void put_vertex(struct outbuf *o, vec3 p, vec3 n, const uint8_t encoded[3],
                       const float num[3], float den)
{
    uint8_t rec[PLY_VERTEX_BYTES], *at = rec;
    const float xyz_n[6] = {(float)p.x, (float)p.y, (float)p.z, (float)n.x, (float)n.y, (float)n.z};
    for (int k = 0; k < 6; k++)
        at = outbuf_f32le_at(at, xyz_n[k]);
    for (int k = 0; k < 3; k++)
        *at++ = encoded[k];
    for (int k = 0; k < 3; k++)
        at = outbuf_f32le_at(at, num[k] / den);
    outbuf_put(o, rec, sizeof(rec));
}

void ply_put_vertex(struct outbuf *o, vec3 p, vec3 n, const uint8_t rgb[3])
{
    const uint8_t encoded[3] = {srgb_encode(rgb[0]), srgb_encode(rgb[1]), srgb_encode(rgb[2])};
    const float num[3] = {rgb[0], rgb[1], rgb[2]};
    put_vertex(o, p, n, encoded, num, 255.0f);
}

void ply_put_vertex16(struct outbuf *o, vec3 p, vec3 n, const uint16_t rgb[3])
{
    const uint8_t encoded[3] = {srgb_encode16(rgb[0]), srgb_encode16(rgb[1]),
                                srgb_encode16(rgb[2])};
    const float num[3] = {rgb[0], rgb[1], rgb[2]};
    put_vertex(o, p, n, encoded, num, 65535.0f);
}

void ply_put_header(struct outbuf *o, const char *what, uint32_t vertices, uint32_t faces,
                    int with_quality)
{
    outbuf_printf(o,
                  "ply\nformat binary_little_endian 1.0\n"
                  "comment turntable colour scanner: %s; units: millimetres\n"
                  "comment red green blue: sRGB-encoded colour; red_linear green_linear "
                  "blue_linear: the same colour in linear units 0..1\n"
                  "element vertex %u\n"
                  "property float x\nproperty float y\nproperty float z\n"
                  "property float nx\nproperty float ny\nproperty float nz\n",
                  what, (unsigned)vertices);
    outbuf_printf(o, "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                     "property float red_linear\nproperty float green_linear\n"
                     "property float blue_linear\n");
    if (with_quality)
        outbuf_printf(o, "property float quality\n");
    if (faces > 0)
        outbuf_printf(o, "element face %u\nproperty list uchar uint vertex_indices\n",
                      (unsigned)faces);
    outbuf_printf(o, "end_header\n");
}

int ply_write_cloud(const struct hal_storage *st, const char *path, const struct decode_maps *maps,
                    const struct tri_range *range, const uint8_t *rgb, const float *confidence,
                    const struct frame_xform *xform, uint32_t *vertex_count)
{
    struct outbuf o;
    uint32_t n = count_valid(maps);
    if (outbuf_open(&o, st, path) != 0)
        return o.rc;
    ply_put_header(&o, "one view; quality: colour confidence 0..1", n, 0, 1);
    size_t total = (size_t)maps->width * maps->height;
    for (size_t i = 0; i < total && o.rc == 0; i++) {
        if (maps->reason[i] != SCAN_VALID)
            continue;
        const float *p = &range->xyz_mm[3 * i], *nn = &range->normal[3 * i];
        ply_put_vertex(&o, frame_point(xform, v3(p[0], p[1], p[2])),
                       frame_dir(xform, v3(nn[0], nn[1], nn[2])), rgb + 3 * i);
        outbuf_f32le(&o, confidence != NULL ? confidence[i] : 1.0f);
    }
    int rc = outbuf_close(&o);
    if (rc == 0)
        *vertex_count = n;
    return rc;
}
