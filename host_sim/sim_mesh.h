/* Triangle meshes of the simulated object: analytic shapes tessellated finely, or a PLY file. */
#ifndef SIM_MESH_H
#define SIM_MESH_H

#include <stdint.h>

struct sim_mesh {
    uint32_t vert_count, tri_count;
    float *pos;     /**< 3 per vertex, object frame, mm (z up, base on z = 0 once placed) */
    float *normal;  /**< 3 per vertex, area-weighted smooth normals */
    uint32_t *tri;  /**< 3 vertex indices per triangle, counter-clockwise seen from outside */
    uint8_t *rgb;   /**< 3 per vertex when the PLY file has vertex colours, else NULL; the linear
                       floats (red_linear...) where the file has them, else its bytes as they are */
    float *lin;     /**< 3 per vertex, 0..1, when the file has the linear floats, else NULL: the
                       colour as written, finer than a byte (sim_mesh_linear reads either) */
    float *quality; /**< per vertex when the PLY file has `quality` (clouds: colour confidence) */
};

/** Vertex @p i's linear colour 0..1: the file's floats where it has them, else its bytes / 255.
 *  @p m must have colours (rgb not NULL). */
void sim_mesh_linear(const struct sim_mesh *m, uint32_t i, double out[3]);

/** @retval 0 ok @retval -ENOMEM */
int sim_mesh_sphere(struct sim_mesh *m, double radius_mm, uint32_t segments);
int sim_mesh_cylinder(struct sim_mesh *m, double radius_mm, double height_mm, uint32_t segments);
/** A spray can: a cylinder of @p radius_mm whose top quarter narrows in a rounded shoulder. */
int sim_mesh_can(struct sim_mesh *m, double radius_mm, double height_mm, uint32_t segments);
int sim_mesh_box(struct sim_mesh *m, double sx_mm, double sy_mm, double sz_mm, uint32_t segments);
/** An open box corner, concave: a floor and two walls of @p side_mm meeting at (-s/2, -s/2, 0),
 *  facing +x, +y, +z (where the camera and projector are at table angle 0): light bounces
 *  between its faces. */
int sim_mesh_corner(struct sim_mesh *m, double side_mm, uint32_t segments);
/** A V groove on a floor: two walls of @p side_mm meeting along a vertical edge at x = -s/2,
 *  opening towards +x at @p opening_deg; deeply concave, its walls light each other. */
int sim_mesh_groove(struct sim_mesh *m, double side_mm, double opening_deg, uint32_t segments);
int sim_mesh_torus(struct sim_mesh *m, double major_mm, double minor_mm, uint32_t segments);
/** Load an ASCII or binary little-endian PLY (vertex x y z, uchar red green blue when present,
 *  faces as lists; other properties are skipped). @param err out: what is wrong, with the file name
 * @retval 0 ok @retval -EINVAL -ENOMEM -errno */
int sim_mesh_load_ply(struct sim_mesh *m, const char *path, char *err, unsigned err_len);
/** The same for a point cloud: faces are optional. */
int sim_mesh_load_ply_points(struct sim_mesh *m, const char *path, char *err, unsigned err_len);
/** Rotate y-up data to z-up (the bunny's convention). */
void sim_mesh_y_up_to_z_up(struct sim_mesh *m);
/** Scale to @p height_mm, centre on the z axis, base on z = 0, then recompute normals. */
void sim_mesh_place(struct sim_mesh *m, double height_mm);
/** Area-weighted vertex normals. */
void sim_mesh_compute_normals(struct sim_mesh *m);
void sim_mesh_free(struct sim_mesh *m);

#endif
