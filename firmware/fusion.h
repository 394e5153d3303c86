/* Volumetric fusion of views (truncated signed distance, Curless and Levoy 1996) in a static grid,
 * with blended vertex colour, and the mesh of its zero level by marching cubes. */
#ifndef FUSION_H
#define FUSION_H

#include "decode.h"
#include "frames.h"
#include "hal.h"
#include "tri.h"

struct reflect_model;

/* The grid is sized in the config and bounded by FUSION_MAX_DIM and FUSION_MAX_VOXELS
 * (hal_limits.h): 8 bytes a voxel. */

struct fusion_params {
    double voxel_mm;          /**< edge of a voxel */
    double radius_mm;         /**< grid spans [-radius, radius] in x and y (object frame) */
    double bottom_mm, top_mm; /**< and [bottom, top] in z */
    double truncation_mm;     /**< distances are clamped to +-this */
    double max_weight;        /**< a voxel's weight stops growing here (older views fade) */
    uint32_t edge_fade_px;    /**< view weights ramp up over this many pixels from its edge */
    double min_weight;        /**< pixels weighing less are not fused (grazing views) */
};

/** Grid dimensions for @p p. @retval 0 ok @retval -E2BIG above FUSION_MAX_* */
int fusion_dims(const struct fusion_params *p, uint32_t dims[3]);

/** Empty grid. @retval 0 ok @retval -E2BIG the grid does not fit the compiled limits */
int fusion_begin(const struct fusion_params *p);

/** Fuse the last view: its range image, normals and colour, seen through @p obj_from_cam.
 *  Weight of a pixel: cos(view angle) x (600 mm / depth)^2 x edge fade; its colour weighs that
 *  times the colour's @p confidence per pixel when given (NULL: 1), so an unreliable colour
 *  estimate (a highlight, a grazing light) still gives its geometry.
 *  @retval 0 */
int fusion_integrate(const struct scan_calib *calib, const struct frame_xform *obj_from_cam,
                     const struct decode_maps *maps, const struct tri_range *range,
                     const uint8_t *rgb, const float *confidence);

/** Set every voxel from a signed distance function of the object-frame position (mm), weight 1
 *  and grey colour (NAN: never observed): synthetic objects and tests of the extraction.
 *  @retval 0 */
int fusion_fill(double (*sdf_mm)(vec3 p, void *ctx), void *ctx);

/** Fill holes up to @p max_hole_mm across: the signed distance diffused into unobserved voxels
 *  from their observed neighbours, a voxel layer a pass (fusion_close.c). After the last
 *  fusion, before the mesh. @param filled  out: voxels filled @retval 0 @retval -EINVAL no grid */
int fusion_fill_holes(double max_hole_mm, uint32_t *filled);

/** Decide every voxel still unobserved, so that the mesh is closed: outside when reachable from
 *  the grid's sides or top (sideways or down only when @p one_pass: what its cameras did not
 *  see under a surface is solid) through passages wider than @p max_hole_mm,
 *  without crossing the object's observed inside or the table plane (object frame z = 0);
 *  inside otherwise; at and below the table plane, outside (the object is closed there).
 *  @param inside  out: voxels decided inside @retval 0 @retval -EINVAL no grid */
int fusion_close_watertight(double max_hole_mm, int one_pass, uint32_t *inside);

/** A vertex of the mesh: object frame, mm; its colour linear (0..255), and whether any view gave
 *  the surface there a colour estimate (else rgb is 0 and the writers fill it from the mesh
 *  around it: mesh_io.c). */
struct mesh_vertex {
    float pos[3], normal[3];
    uint8_t rgb[3];
    uint8_t coloured;
};

/** Receives the mesh: vertices are numbered from 0 in the order given. */
struct mesh_sink {
    int (*vertex)(void *priv, const struct mesh_vertex *v);
    int (*triangle)(void *priv, uint32_t a, uint32_t b, uint32_t c);
    void *priv;
};

/** Marching cubes over the cells whose eight corners were all observed. Deterministic: two
 *  runs give the same vertices in the same order (writers count in a first pass).
 *  @retval 0 or what the sink returned */
int fusion_extract(const struct mesh_sink *sink);

/** What fusion_mesh_prepare found. */
struct mesh_summary {
    uint32_t vertices, triangles;           /**< the whole marching-cubes mesh */
    uint32_t kept_vertices, kept_triangles; /**< what the writers write */
    uint32_t pieces, removed_pieces;        /**< connected pieces; those left out */
    uint32_t colour_filled; /**< kept vertices no view coloured, given their neighbours' colour */
    uint32_t uncoloured;    /**< kept vertices no coloured one reached: marked mid grey */
};

/** Run marching cubes once to find the mesh's connected pieces: the writers then leave out
 *  floating fragments, pieces with fewer than @p min_fragment_share of the largest piece's
 *  triangles (0: keep every piece). Must come before the writers, after the last fusion.
 *  @param summary  out
 *  @retval 0 @retval -E2BIG more vertices than MESH_MAX_VERTICES: the writers keep every piece
 *  and no STL can be written (PLY and OBJ still can) */
int fusion_mesh_prepare(double min_fragment_share, struct mesh_summary *summary);

/** Marching cubes into @p sink as the writers see it: the pieces fusion_mesh_prepare left out
 *  are not given, the vertices renumbered. @retval 0 @retval -EINVAL not prepared */
int fusion_extract_prepared(const struct mesh_sink *sink);

/** What fusion_mesh_prepare found, for a writer that needs the counts first.
 *  @retval 0 @retval -EINVAL not prepared @retval -E2BIG the mesh did not fit the tables */
int fusion_mesh_counts(struct mesh_summary *summary);

/** Write the prepared mesh as binary PLY (vertex x y z nx ny nz red green blue, faces), as OBJ
 *  (with vertex colours and normals) or as binary STL (for printing: triangles only), atomically,
 *  in millimetres. @retval 0 @retval -EINVAL not prepared @retval -E2BIG (STL) the mesh did not
 *  fit MESH_MAX_VERTICES @retval -errno from storage */
int fusion_write_ply(const struct hal_storage *st, const char *path);
int fusion_write_obj(const struct hal_storage *st, const char *path);
int fusion_write_stl(const struct hal_storage *st, const char *path);

/** Write the prepared mesh as glTF 2.0 binary (firmware/mesh_glb.c): metres, +Y up, linear vertex
 *  colours, atomically; one material, or one per cluster of @p model (the reflectance fitted, or
 *  NULL). @retval 0 @retval -EINVAL not prepared @retval -E2BIG the
 *  mesh did not fit MESH_MAX_VERTICES @retval -ENODATA no vertex @retval -EFBIG over 4 GiB
 *  @retval -errno from storage */
int fusion_write_glb(const struct hal_storage *st, const char *path,
                     const struct reflect_model *model);

#endif
