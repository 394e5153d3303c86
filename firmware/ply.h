/* Binary little-endian PLY output of a view's point cloud, written atomically through the HAL. */
#ifndef PLY_H
#define PLY_H

#include "decode.h"
#include "frames.h"
#include "hal.h"
#include "tri.h"

/** Write every valid pixel as a vertex with position, normal (both through @p xform) and colour.
 *  @param storage  where to write (atomic: the old file survives any failure)
 *  @param path     final file path
 *  @param maps     reason per pixel; only SCAN_VALID pixels are written
 *  @param range    positions and normals in the camera frame
 *  @param rgb      colour per pixel (RGB24, same size as the maps)
 *  @param confidence  the colour's confidence per pixel (0..1), written as `quality`; NULL: 1
 *  @param xform    camera frame to output frame
 *  @param vertex_count  out: vertices written
 *  @retval 0 ok @retval -errno from storage */
int ply_write_cloud(const struct hal_storage *storage, const char *path,
                    const struct decode_maps *maps, const struct tri_range *range,
                    const uint8_t *rgb, const float *confidence, const struct frame_xform *xform,
                    uint32_t *vertex_count);

struct outbuf;
/** The PLY header of a cloud (faces = 0) or a mesh, vertex layout as ply_put_vertex writes, and
 *  a float `quality` after it when @p with_quality. */
void ply_put_header(struct outbuf *o, const char *what, uint32_t vertices, uint32_t faces,
                    int with_quality);
/** One vertex: float x y z nx ny nz, uchar red green blue sRGB-encoded from the linear @p rgb,
 *  float red_linear green_linear blue_linear (@p rgb / 255): 39 bytes. */
void ply_put_vertex(struct outbuf *o, vec3 pos, vec3 normal, const uint8_t rgb[3]);

/** The same with a 16-bit linear colour (0..65535, a mesh vertex's: fusion.h MESH_RGB_ONE); a
 *  linear byte b given as b x 257 is written as ply_put_vertex writes b. */
void ply_put_vertex16(struct outbuf *o, vec3 pos, vec3 normal, const uint16_t rgb[3]);

#endif
