/* Bounding-volume hierarchy over a mesh's triangles: closest hit and shadow (any-hit) queries. */
#ifndef SIM_BVH_H
#define SIM_BVH_H

#include "sim_mesh.h"
#include "vec3.h"

struct sim_bvh_node {
    float lo[3], hi[3];
    uint32_t first; /* leaf: first index into tri_order; inner: index of the left child */
    uint32_t count; /* leaf: triangle count; inner: 0 (right child = left + 1) */
};

struct sim_bvh {
    const struct sim_mesh *mesh;
    struct sim_bvh_node *nodes;
    uint32_t node_count;
    uint32_t *tri_order;
};

struct sim_hit {
    double t;     /**< distance along the (unnormalised) ray direction */
    uint32_t tri; /**< triangle index */
    double u, v;  /**< barycentric weights of vertices 1 and 2 */
};

/** @retval 0 ok @retval -ENOMEM */
int sim_bvh_build(struct sim_bvh *bvh, const struct sim_mesh *mesh);
void sim_bvh_free(struct sim_bvh *bvh);
/** Closest hit with t in (t_min, t_max). @retval 1 hit (*hit filled), 0 miss */
int sim_bvh_intersect(const struct sim_bvh *bvh, vec3 origin, vec3 dir, double t_min, double t_max,
                      struct sim_hit *hit);
/** Any hit with t in (t_min, t_max). @retval 1 occluded, 0 free */
int sim_bvh_occluded(const struct sim_bvh *bvh, vec3 origin, vec3 dir, double t_min, double t_max);

/** Distance from @p p to the nearest triangle, or @p max_dist if none is closer. */
double sim_bvh_distance(const struct sim_bvh *bvh, vec3 p, double max_dist);
/** The same, and the closest surface point in @p closest (@p p itself when none is closer). */
double sim_bvh_closest(const struct sim_bvh *bvh, vec3 p, double max_dist, vec3 *closest);

#endif
