/* Binary PLY writer: fixed-size chunk buffer, explicit little-endian byte order. */
#include "ply.h"

#include <stdio.h>
#include <string.h>

#define PLY_VERTEX_BYTES 27u /* 6 floats + 3 uchar */
static uint8_t chunk[64u * 1024u];

static uint8_t *put_f32le(uint8_t *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof(u));
    p[0] = (uint8_t)u;
    p[1] = (uint8_t)(u >> 8);
    p[2] = (uint8_t)(u >> 16);
    p[3] = (uint8_t)(u >> 24);
    return p + 4;
}

static uint32_t count_valid(const struct decode_maps *maps)
{
    uint32_t n = 0;
    size_t total = (size_t)maps->width * maps->height;
    for (size_t i = 0; i < total; i++)
        n += maps->reason[i] == SCAN_VALID;
    return n;
}

int ply_write_cloud(const struct hal_storage *st, const char *path, const struct decode_maps *maps,
                    const struct tri_range *range, const uint8_t *rgb,
                    const struct frame_xform *xform, uint32_t *vertex_count)
{
    struct hal_file file;
    uint32_t n = count_valid(maps);
    int rc = hal_storage_open(st, &file, path);
    if (rc != 0)
        return rc;
    int len = snprintf((char *)chunk, sizeof(chunk),
                       "ply\nformat binary_little_endian 1.0\n"
                       "comment turntable colour scanner, one view; units: millimetres\n"
                       "element vertex %u\n"
                       "property float x\nproperty float y\nproperty float z\n"
                       "property float nx\nproperty float ny\nproperty float nz\n"
                       "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                       "end_header\n",
                       (unsigned)n);
    size_t used = (size_t)len;
    size_t total = (size_t)maps->width * maps->height;
    for (size_t i = 0; i < total && rc == 0; i++) {
        if (maps->reason[i] != SCAN_VALID)
            continue;
        if (used + PLY_VERTEX_BYTES > sizeof(chunk)) {
            rc = hal_storage_write(st, &file, chunk, used);
            used = 0;
        }
        vec3 p = frame_point(
            xform, v3(range->xyz_mm[3 * i], range->xyz_mm[3 * i + 1], range->xyz_mm[3 * i + 2]));
        vec3 nn = frame_dir(
            xform, v3(range->normal[3 * i], range->normal[3 * i + 1], range->normal[3 * i + 2]));
        uint8_t *q = chunk + used;
        q = put_f32le(q, (float)p.x);
        q = put_f32le(q, (float)p.y);
        q = put_f32le(q, (float)p.z);
        q = put_f32le(q, (float)nn.x);
        q = put_f32le(q, (float)nn.y);
        q = put_f32le(q, (float)nn.z);
        memcpy(q, rgb + 3 * i, 3);
        used += PLY_VERTEX_BYTES;
    }
    if (rc == 0 && used > 0)
        rc = hal_storage_write(st, &file, chunk, used);
    if (rc == 0)
        rc = hal_storage_commit(st, &file);
    if (rc != 0)
        goto out_abort;
    *vertex_count = n;
    return 0;
out_abort:
    hal_storage_abort(st, &file);
    return rc;
}
