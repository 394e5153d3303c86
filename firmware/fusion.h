/* Volumetric fusion of views (truncated signed distance, Curless and Levoy 1996) in a voxel grid
 * (struct fusion_volume), with blended vertex colour, and the mesh of its zero level by marching
 * cubes. */
#ifndef FUSION_H
#define FUSION_H

#include "decode.h"
#include "frames.h"
#include "hal.h"
#include "tri.h"

struct reflect_model;
struct fusion_volume;

/* The grid is sized in the config and bounded by FUSION_MAX_DIM and FUSION_MAX_VOXELS
 * (hal_limits.h): 8 bytes a voxel. */

struct fusion_params {
    double voxel_mm;          /**< edge of a voxel */
    double radius_mm;         /**< grid spans centre +- radius in x and y (object frame) */
    double centre_mm[2];      /**< the grid's centre in x and y: the axis (0, 0) unless fusion_fit
                                   moved it to hold an object placed far off the axis */
    double bottom_mm, top_mm; /**< and [bottom, top] in z */
    double truncation_mm;     /**< distances are clamped to +-this */
    double max_weight;        /**< a voxel's weight stops growing here (older views fade) */
    uint32_t edge_fade_px;    /**< view weights ramp up over this many pixels from its edge */
    uint32_t fit_volume;      /**< 1: fusion_fit may grow radius and top to hold the object */
    double min_weight;        /**< pixels weighing less are not fused (grazing views) */
};

/** Grid dimensions for @p p. @retval 0 ok @retval -E2BIG above FUSION_MAX_* */
int fusion_dims(const struct fusion_params *p, uint32_t dims[3]);

/** Empty the grid of @p vol for @p p. @retval 0 ok @retval -E2BIG the grid does not fit the
 * compiled limits */
int fusion_begin(struct fusion_volume *vol, const struct fusion_params *p);

/** Fuse the last view: its range image, normals and colour, seen through @p obj_from_cam.
 *  Weight of a pixel: cos(view angle) x (600 mm / depth)^2 x edge fade; its colour weighs that
 *  times the colour's @p confidence per pixel when given (NULL: 1), so an unreliable colour
 *  estimate (a highlight, a grazing light) still gives its geometry.
 *  @param threads  the cores the voxels are split across, by slices (NULL: this thread): each
 *  voxel is its own, the volume the same to the byte however many
 *  @retval 0 */
int fusion_integrate(struct fusion_volume *vol, const struct hal_thread *threads,
                     const struct scan_calib *calib, const struct frame_xform *obj_from_cam,
                     const struct decode_maps *maps, const struct tri_range *range,
                     const uint8_t *rgb, const float *confidence);

/** What the views held beyond the grid, counted by fusion_integrate since fusion_begin (or by
 *  fusion_outside_add, of the registration's samples): an object taller or wider than the
 *  volume is cut there, and the scan should say so or grow it. */
struct fusion_outside {
    uint64_t fused;       /**< the points counted (those fused: weight above 0) */
    uint64_t above;       /**< of them over the table (5 mm up, within twice radius_mm of the
                               axis) and higher than top_mm */
    uint64_t beside;      /**< of them over the table and beyond the grid's square (x or y
                               farther than radius_mm from its centre); a point may be both */
    double top_seen_mm;   /**< the highest point above (0: none) */
    double reach_seen_mm; /**< the farthest in x or y from the centre of the points beside (0:
                               none) */
    double low_seen_mm[2], high_seen_mm[2]; /**< the least and greatest x and y of the points
                                                 beside (0 where none is lower or higher) */
    uint32_t views_cut;                     /**< views whose object runs off the image: at least
                                                 FUSION_EDGE_POINTS valid pixels on its border rows and columns
                                                 are points above the table (5 mm up, within twice radius_mm) */
};
#define FUSION_EDGE_POINTS 16u

/** A view's valid pixels on its image's border (its outer rows and columns, whatever their
 *  weight) that are points over the table (5 mm up, within twice @p p's radius_mm of the axis),
 *  seen through @p obj_from_cam: the object runs off the image where there are
 *  FUSION_EDGE_POINTS or more (a scan can say so at its first view). @retval their count */
uint32_t fusion_border_points(const struct fusion_params *p, const struct frame_xform *obj_from_cam,
                              const struct decode_maps *maps, const struct tri_range *range);

/** Count @p p_obj (object frame) in @p o as fusion_integrate counts a fused point against the
 *  grid of @p p (struct fusion_outside). */
void fusion_outside_add(struct fusion_outside *o, const struct fusion_params *p, vec3 p_obj);

/** Are @p n points beyond the volume, of @p fused counted, many enough to say or grow for, not
 *  stray ones: at least @p least, and a thousandth of them. @retval 1 yes @retval 0 no */
int fusion_outside_many(uint64_t n, uint64_t fused, uint64_t least);

/** The volume grown to hold what @p seen counted beyond @p p's (points beyond it by the
 *  thousand of them, and at least 8): top_mm to their highest, radius_mm to their farthest,
 *  each with the truncation band and two voxels to spare, the radius by whole voxels (the
 *  grid's voxels stay where they were). A part already inside is left as it is. Where the
 *  square about the axis that holds them is beyond the compiled limits (an object placed far
 *  off the axis), the square is moved by whole voxels to hold p's and theirs (centre_mm).
 *  @param fitted  out: the grown parameters (@p p where nothing grows, or beyond the limits)
 *  @retval 1 grown @retval 0 nothing to grow, or p->fit_volume is 0 @retval -E2BIG the grown
 *  volume is beyond the compiled limits (FUSION_MAX_*) */
int fusion_fit(const struct fusion_params *p, const struct fusion_outside *seen,
               struct fusion_params *fitted);

/** What fusion_integrate counted beyond the grid (above). @param out  out: the counts */
void fusion_outside(const struct fusion_volume *vol, struct fusion_outside *out);

/** The weight fusion_integrate gives each pixel of a view (above; 0: not fused), in @p vol's
 *  work space, which the mesh's hole filling shares: once the mesh is made (the texture atlas).
 *  The rows split across @p threads (NULL: this one).
 *  @retval the weights, width x height @retval NULL no pixel is valid */
const float *fusion_view_weights(struct fusion_volume *vol, const struct hal_thread *threads,
                                 const struct scan_calib *calib, const struct decode_maps *maps,
                                 const struct tri_range *range);

/** The grid's memory for another use once the mesh is made (fusion_mesh_prepare, and the whole
 *  mesh fit the tables: the writers read the tables, never the grid again): the texture atlas's
 *  work space. Until fusion_begin, fusion_extract refuses (-EINVAL).
 *  @param bytes  out: its size @retval the grid's memory (8-byte aligned) @retval NULL the mesh
 *  is not made, or did not fit the tables */
void *fusion_spend_grid(struct fusion_volume *vol, size_t *bytes);

/** Set every voxel from a signed distance function of the object-frame position (mm), weight 1
 *  and grey colour (NAN: never observed): synthetic objects and tests of the extraction.
 *  @retval 0 */
int fusion_fill(struct fusion_volume *vol, double (*sdf_mm)(vec3 p, void *ctx), void *ctx);

/** Fill holes up to @p max_hole_mm across: the signed distance diffused into unobserved voxels
 *  from their observed neighbours, a voxel layer a pass (fusion_close.c). After the last
 *  fusion, before the mesh. @param filled  out: voxels filled @retval 0 @retval -EINVAL no grid */
int fusion_fill_holes(struct fusion_volume *vol, double max_hole_mm, uint32_t *filled);

/** Decide every voxel still unobserved, so that the mesh is closed: outside when reachable from
 *  the grid's sides or top (sideways or down only when @p one_pass: what its cameras did not
 *  see under a surface is solid) through passages wider than @p max_hole_mm,
 *  without crossing the object's observed inside or the table plane (object frame z = 0);
 *  inside otherwise; at and below the table plane, outside (the object is closed there).
 *  @param inside  out: voxels decided inside @retval 0 @retval -EINVAL no grid */
int fusion_close_watertight(struct fusion_volume *vol, double max_hole_mm, int one_pass,
                            uint32_t *inside);

/** A vertex's colour channel at full scale (mesh_vertex.rgb, linear): 16 bits, so that the mean
 *  of several views keeps the shades between two linear bytes (on a paint of albedo 0.03 a byte
 *  is a step of 13%). A linear byte b is b x MESH_RGB_PER_BYTE. */
#define MESH_RGB_ONE 65535u
#define MESH_RGB_PER_BYTE (MESH_RGB_ONE / 255u) /* 257 */

/** A vertex of the mesh: object frame, mm; its colour linear (0..MESH_RGB_ONE), and whether any
 *  view gave the surface there a colour estimate (else rgb is 0 and the writers fill it from the
 *  mesh around it: mesh_io.c). */
struct mesh_vertex {
    float pos[3], normal[3];
    uint16_t rgb[3];
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
int fusion_extract(struct fusion_volume *vol, const struct mesh_sink *sink);

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
int fusion_mesh_prepare(struct fusion_volume *vol, double min_fragment_share,
                        struct mesh_summary *summary);

/** What fusion_mesh_fill_holes did. */
struct mesh_hole_report {
    uint32_t boundary_edges; /**< edges of one kept triangle only, before */
    uint32_t filled;         /**< loops closed */
    uint32_t left;           /**< loops as wide as max_hole_mm or wider (the object's open
                                  bottom), or not simple loops: left open */
};

/** Close the prepared mesh's holes narrower than @p max_hole_mm (the diagonal of a boundary
 *  loop's bounding box): each loop fanned from a new vertex at its centre (firmware/mesh_holes.c).
 *  After fusion_mesh_prepare, before the writers; a mesh too large for the tables is left as it
 *  is. @param out  out @retval 0 @retval -EINVAL not prepared @retval -ENOSPC more open edges at
 *  once than the work space holds @retval -E2BIG the tables are full (what was closed stays) */
int fusion_mesh_fill_holes(struct fusion_volume *vol, double max_hole_mm,
                           struct mesh_hole_report *out);

/** Marching cubes into @p sink as the writers see it: the pieces fusion_mesh_prepare left out
 *  are not given, the vertices renumbered. @retval 0 @retval -EINVAL not prepared */
int fusion_extract_prepared(struct fusion_volume *vol, const struct mesh_sink *sink);

/** What fusion_mesh_prepare found, for a writer that needs the counts first.
 *  @retval 0 @retval -EINVAL not prepared @retval -E2BIG the mesh did not fit the tables */
int fusion_mesh_counts(struct fusion_volume *vol, struct mesh_summary *summary);

/** Write the prepared mesh as binary PLY (vertex x y z nx ny nz red green blue, faces), as OBJ
 *  (with vertex colours and normals) or as binary STL (for printing: triangles only), atomically,
 *  in millimetres. @retval 0 @retval -EINVAL not prepared @retval -E2BIG (STL) the mesh did not
 *  fit MESH_MAX_VERTICES @retval -errno from storage */
int fusion_write_ply(struct fusion_volume *vol, const struct hal_storage *st, const char *path);
int fusion_write_obj(struct fusion_volume *vol, const struct hal_storage *st, const char *path);
int fusion_write_stl(struct fusion_volume *vol, const struct hal_storage *st, const char *path);

struct atlas;
/** fusion_write_obj with texture coordinates from @p atlas (atlas.h) and the material of
 *  @p mtl_name (a file beside it, which names the texture): "mtllib", "usemtl scan", a "vt" for
 *  each corner of each triangle (NULL atlas or mtl_name: fusion_write_obj's file).
 *  @retval as fusion_write_obj */
int fusion_write_obj_textured(struct fusion_volume *vol, const struct atlas *atlas,
                              const char *mtl_name, const struct hal_storage *st, const char *path);

/** Write the prepared mesh as glTF 2.0 binary (firmware/mesh_glb.c): metres, +Y up, linear vertex
 *  colours, atomically; one material, or one per cluster of @p model (the reflectance fitted, or
 *  NULL). @retval 0 @retval -EINVAL not prepared @retval -E2BIG the
 *  mesh did not fit MESH_MAX_VERTICES @retval -ENODATA no vertex @retval -EFBIG over 4 GiB
 *  @retval -errno from storage */
int fusion_write_glb(struct fusion_volume *vol, const struct hal_storage *st, const char *path,
                     const struct reflect_model *model);

/** fusion_write_glb with the texture of @p atlas: TEXCOORD_0 instead of COLOR_0, @p png (the
 *  atlas's texture as PNG, @p png_len bytes) in the BIN chunk as every material's
 *  baseColorTexture; a vertex on a chart's border repeated for each other chart about it
 *  (NULL atlas or png: fusion_write_glb's file). @retval as fusion_write_glb */
int fusion_write_glb_textured(struct fusion_volume *vol, const struct hal_storage *st,
                              const char *path, const struct reflect_model *model,
                              const struct atlas *atlas, const uint8_t *png, size_t png_len);

/* ---- the volume: the grid and its work space, a model's worth ---- */

/* 8 bytes: distance in units of truncation / 32767, weight in thousandths, colour, and the
 * colour's own weight in 1/32 (it saturates at ~8: a voxel's colour stops changing once about
 * eight good views agree). The colour has its own weight because a colour estimate can be
 * unreliable (a highlight, a grazing light) where the geometry is fine. */
struct voxel {
    int16_t sdf;
    uint16_t weight;
    uint8_t rgb[3];
    uint8_t colour_weight;
};

#define FUSION_BLOCK 4u /* voxels along a block's edge (fusion_integrate's blocks) */
#define FUSION_BLOCKS_MAX ((FUSION_MAX_DIM + FUSION_BLOCK - 1) / FUSION_BLOCK)
#define FUSION_BITMAP_BYTES ((FUSION_MAX_VOXELS + 7) / 8) /* a bit a voxel */
#define FUSION_GLB_JSON_MAX 8192u                         /* mesh.glb's JSON chunk (mesh_glb.c) */
#define MESH_DROPPED 0xFFFFFFFFu /* mesh_index of a vertex of a piece left out (mesh_io.c) */
#define MESH_HOLE_MAX_LOOP 4096u /* a longer boundary loop is far wider than a hole to close */

/** One model's volume: the grid, the work space of the stages over it and the prepared mesh's
 *  tables. Hundreds of MB at the compiled limits: its owner (the job) keeps it static and passes
 *  it by pointer, so there is no allocation; two volumes are two independent models. Its fields
 *  are the fusion's own (fusion.c, fusion_close.c, mesh_io.c, mesh_glb.c). */
struct fusion_volume {
    _Alignas(8) struct voxel grid[FUSION_MAX_VOXELS];
    int grid_spent; /* 1: fusion_spend_grid lent it out */
    struct fusion_params p;
    uint32_t dims[3];
    vec3 origin; /* where voxel (0, 0, 0) is (object frame, mm) */
    /* fusion_integrate's: a view's pixel weights, the rectangle of its pixels, its blocks; the
     * weights' space holds mesh_holes.c's set of open edges once the views are fused */
    union {
        float weight_map[HAL_MAX_PIXELS];
        uint64_t open_edge[HAL_MAX_PIXELS / 2];
    };
    uint16_t edge_dist[HAL_MAX_PIXELS];
    struct {
        uint32_t x0, y0, x1, y1;
    } rect;
    struct fusion_outside outside; /* since fusion_begin */
    uint8_t block_mark[FUSION_BLOCKS_MAX * FUSION_BLOCKS_MAX * FUSION_BLOCKS_MAX];
    uint8_t block_grown[FUSION_BLOCKS_MAX * FUSION_BLOCKS_MAX * FUSION_BLOCKS_MAX];
    /* fusion_extract's: vertex numbers of the grid edges of two sample planes (x, y edges) and
     * between them (z) */
    uint32_t edge_vertex_x[2][FUSION_MAX_DIM * FUSION_MAX_DIM];
    uint32_t edge_vertex_y[2][FUSION_MAX_DIM * FUSION_MAX_DIM];
    uint32_t edge_vertex_z[FUSION_MAX_DIM * FUSION_MAX_DIM];
    /* fusion_close.c's bitmaps */
    uint8_t mark[FUSION_BITMAP_BYTES], scratch_a[FUSION_BITMAP_BYTES],
        scratch_b[FUSION_BITMAP_BYTES];
    /* the prepared mesh (mesh_io.c) */
    float mesh_pos[MESH_MAX_VERTICES * 3];
    float mesh_nrm[MESH_MAX_VERTICES * 3];
    uint16_t mesh_rgb[MESH_MAX_VERTICES * 3]; /* linear, 0..MESH_RGB_ONE */
    uint8_t mesh_coloured[MESH_MAX_VERTICES]; /* 1: a view gave the surface there a colour */
    uint32_t mesh_tri[MESH_MAX_TRIANGLES * 3];
    uint32_t mesh_index[MESH_MAX_VERTICES]; /* union-find parent; after prepare, new number or
                                               MESH_DROPPED (a piece left out) */
    uint32_t mesh_tris[MESH_MAX_VERTICES];  /* triangles of the piece rooted here */
    struct {
        int prepared, fits; /* fits: the whole mesh is in the tables (else nothing is dropped) */
        struct mesh_summary s;
    } mp;
    struct mesh_vertex mv;                  /* the vertex a sink is handed from the tables */
    uint32_t hole_loop[MESH_HOLE_MAX_LOOP]; /* mesh_holes.c: the loop being closed */
    /* mesh.glb's (mesh_glb.c): each vertex's material cluster, the JSON chunk */
    uint8_t vertex_part[MESH_MAX_VERTICES];
    char glb_json[FUSION_GLB_JSON_MAX];
    int glb_json_len;
};

#endif
