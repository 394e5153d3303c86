/* The views' colour on the fused mesh: each vertex's, and a texture atlas (charts on the prepared
 * mesh packed into one image), each vertex and texel coloured from the views that see its point
 * best, so the model keeps the colour detail the camera resolved (the fusion grid holds one
 * colour byte a voxel, fused from where the voxel's centre is seen, not the surface). */
#ifndef ATLAS_H
#define ATLAS_H

#include "fusion.h"

#include <stdint.h>

#define ATLAS_GUTTER 2u /* texels around each chart: bilinear and mipmapped reads stay inside */

/** A chart: triangles joined through shared vertices whose normals lie nearest one axis
 *  direction, projected along it (orthographic), in the atlas at (x0, y0), w x h texels. */
struct atlas_chart {
    uint8_t axis;       /* 0..5: +x, -x, +y, -y, +z, -z (object frame) */
    uint8_t facing;     /* a triangle of it faces the view being added (atlas_add_view) */
    float min_u, min_v; /* the projection's corner, mm */
    uint32_t x0, y0, w, h;
    uint32_t triangles;
};

/** What atlas_build made. */
struct atlas_report {
    uint32_t width, height; /**< the texture, texels */
    double texel_mm;        /**< a texel's edge on the object */
    uint32_t charts;        /**< charts packed */
    double used_share;      /**< share of the texture inside charts */
};

/** What atlas_build needs of its work space: a texel's weighted colour and weight (4 floats),
 *  its place in its triangle (2 doubles), its triangle (uint32) and its sRGB colour (3 bytes); a
 * triangle's chart (uint32) and axis (a byte); a vertex's chart (uint32), its place in a view (5
 * floats) and its weighted colour and weight (4 floats); a chart; a camera pixel's weight and
 * depth (2 floats). */
#define ATLAS_TEXEL_BYTES (4u * sizeof(float) + 2u * sizeof(float) + sizeof(uint32_t) + 3u)
#define ATLAS_WORK_BYTES(texels, triangles, vertices)                                              \
    ((uint64_t)(texels)*ATLAS_TEXEL_BYTES + 5ull * (triangles) + 40ull * (vertices) +              \
     (uint64_t)ATLAS_MAX_CHARTS * sizeof(struct atlas_chart) + 8ull * HAL_MAX_PIXELS +             \
     16u /* alignment */)

/** The atlas: its size and texel, and where its parts lie in the work space atlas_build is given
 *  (the fusion grid's, spent once the mesh is made: fusion_spend_grid), so that it costs no memory
 *  of its own; the fields are atlas.c's. */
struct atlas {
    int built;                           /* atlas_build made it (with or without a texture) */
    uint32_t width, height, chart_count; /* 0 x 0: the vertices' colours only */
    double texel_mm;
    size_t max_texels;
    float *accum;              /* weighted linear colour and the weight, 4 a texel */
    float *bary;               /* each owned texel's first two barycentric weights in it (2) */
    uint32_t *owner;           /* each texel's triangle (atlas.c's raster) */
    uint32_t *tri_chart;       /* each prepared triangle's chart (or none) */
    uint32_t *vertex_tri;      /* a triangle at each vertex, then its chart */
    struct atlas_chart *chart; /* the charts */
    float *vertex_cam;         /* each vertex in the view's camera frame, and its pixel (5) */
    float *vertex_accum;       /* each vertex's weighted linear colour and the weight (4) */
    float *pixel;              /* each pixel of the view: its weight and depth (2) */
    uint8_t *texture;          /* sRGB-encoded RGB, rows top down */
    uint8_t *tri_axis;         /* each triangle's axis direction; FACING (atlas.c) */
};

/** Charts on @p vol's prepared mesh (fusion_mesh_prepare, holes closed), packed at @p texel_mm
 *  or, when that does not fit ATLAS_MAX_SIDE a side, ATLAS_MAX_TEXELS or the work space, the
 *  smallest texel (a quarter larger a step) that does; the colour accumulators emptied. With
 *  @p texel_mm 0, no texture: the vertices' colours only.
 *  @param work  the atlas's space (8-byte aligned), ATLAS_WORK_BYTES, the atlas's until it is
 *  built again @param rep  out
 *  @retval 0 @retval -EINVAL not prepared, texel_mm < 0 or no work space @retval -E2BIG the mesh
 *  did not fit the tables (no atlas) @retval -ENOSPC more charts than ATLAS_MAX_CHARTS or the
 *  work space holds */
int atlas_build(struct atlas *a, const struct fusion_volume *vol, double texel_mm, void *work,
                size_t work_bytes, struct atlas_report *rep);

/** Add one view's colour: each vertex facing the camera and each texel of a triangle facing
 *  it, projected into the view through @p obj_from_cam, takes the colour about where it lands
 *  (bilinear over valid pixels) when the view measured the surface there (the view's own depth
 *  within two voxels: else the point is hidden or off the view's surface), weighed as fusion
 *  weighs the pixel (fusion.h: head-on, near, away from the view's edge) times the colour's
 *  @p confidence (NULL: 1).
 *  Uses @p vol's pixel weights (fusion_view_weights): after the mesh is prepared. The pixels,
 *  the vertices and the charts split across @p threads (NULL: this one); each texel and vertex
 *  takes one sample a view, so the sums are the same on any number of threads.
 *  @retval 0 @retval -EINVAL no atlas built */
int atlas_add_view(struct atlas *a, struct fusion_volume *vol, const struct hal_thread *threads,
                   const struct scan_calib *calib, const struct frame_xform *obj_from_cam,
                   const struct decode_maps *maps, const struct tri_range *range,
                   const uint8_t *rgb, const float *confidence);

/** The vertices' colours and the texture: each vertex a view saw takes its weighted colour in
 *  @p vol's tables (16 bits, MESH_RGB_ONE; the others keep the fusion grid's); each texel its
 *  weighted colour, sRGB-encoded, and texels no view coloured the mesh's vertex colours there
 *  (barycentric); the gutters take their chart's edge.
 *  @param uncoloured  out: texels inside charts that no view coloured @param vertices  out:
 *  vertices the views coloured @retval 0 @retval -EINVAL not built */
int atlas_finish(struct atlas *a, struct fusion_volume *vol, uint32_t *uncoloured,
                 uint32_t *vertices);

/** Texture coordinates of corner @p k (0..2) of prepared triangle @p t, as glTF takes them:
 *  0..1, origin at the image's top left. @retval 0 @retval -EINVAL not in a chart */
int atlas_uv(const struct atlas *a, const struct fusion_volume *vol, uint32_t t, int k,
             float uv[2]);

/** Texture coordinates of prepared vertex @p v in its own chart (that of its first triangle), as
 *  atlas_uv gives them. @retval 0 @retval -EINVAL in no chart */
int atlas_vertex_uv(const struct atlas *a, const struct fusion_volume *vol, uint32_t v,
                    float uv[2]);

/** @retval 1 corner @p k of triangle @p t lies in its vertex's own chart: atlas_vertex_uv's
 *  coordinates serve it (a writer shares them) @retval 0 the vertex is on a chart's border and
 *  the triangle in another chart: atlas_uv's own */
int atlas_corner_is_vertex(const struct atlas *a, const struct fusion_volume *vol, uint32_t t,
                           int k);

#endif
