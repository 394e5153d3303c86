/* BVH built by median split of triangle centroids along the longest axis; stack traversal. */
#include "sim_bvh.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

#define LEAF_TRIS 4u
#define STACK_DEPTH 64

static const float *vert(const struct sim_mesh *m, uint32_t tri, int k)
{
    return &m->pos[3 * m->tri[3 * tri + (uint32_t)k]];
}

static float centroid(const struct sim_mesh *m, uint32_t tri, int axis)
{
    return (vert(m, tri, 0)[axis] + vert(m, tri, 1)[axis] + vert(m, tri, 2)[axis]) / 3.0f;
}

static void node_bounds(struct sim_bvh *b, struct sim_bvh_node *n)
{
    for (int a = 0; a < 3; a++) {
        n->lo[a] = 1e30f;
        n->hi[a] = -1e30f;
    }
    for (uint32_t i = n->first; i < n->first + n->count; i++)
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++) {
                float p = vert(b->mesh, b->tri_order[i], k)[a];
                n->lo[a] = p < n->lo[a] ? p : n->lo[a];
                n->hi[a] = p > n->hi[a] ? p : n->hi[a];
            }
}

/* Sort a node's triangles by centroid along one axis; the build runs once, at start-up, so a
 * plain qsort with file-scope context is simpler than an in-place selection and fast enough. */
static const struct sim_mesh *sort_mesh;
static int sort_axis;
static int by_centroid(const void *pa, const void *pb)
{
    float a = centroid(sort_mesh, *(const uint32_t *)pa, sort_axis);
    float b = centroid(sort_mesh, *(const uint32_t *)pb, sort_axis);
    return (a > b) - (a < b);
}

static void select_median(struct sim_bvh *b, uint32_t lo, uint32_t hi, int axis)
{
    sort_mesh = b->mesh;
    sort_axis = axis;
    qsort(b->tri_order + lo, hi - lo, sizeof(uint32_t), by_centroid);
}

int sim_bvh_build(struct sim_bvh *b, const struct sim_mesh *m)
{
    memset(b, 0, sizeof(*b));
    b->mesh = m;
    b->nodes = calloc((size_t)m->tri_count * 2 + 1, sizeof(*b->nodes));
    b->tri_order = malloc((size_t)m->tri_count * sizeof(uint32_t));
    if (b->nodes == NULL || b->tri_order == NULL) {
        sim_bvh_free(b);
        return -ENOMEM;
    }
    for (uint32_t i = 0; i < m->tri_count; i++)
        b->tri_order[i] = i;
    b->nodes[0].first = 0;
    b->nodes[0].count = m->tri_count;
    b->node_count = 1;
    uint32_t stack[STACK_DEPTH * 2], sp = 0;
    stack[sp++] = 0;
    while (sp > 0) {
        struct sim_bvh_node *n = &b->nodes[stack[--sp]];
        node_bounds(b, n);
        if (n->count <= LEAF_TRIS || sp + 2 > STACK_DEPTH * 2)
            continue;
        int axis = 0;
        for (int a = 1; a < 3; a++)
            if (n->hi[a] - n->lo[a] > n->hi[axis] - n->lo[axis])
                axis = a;
        uint32_t mid = n->first + n->count / 2;
        select_median(b, n->first, n->first + n->count, axis);
        uint32_t left = b->node_count;
        b->node_count += 2;
        b->nodes[left].first = n->first;
        b->nodes[left].count = mid - n->first;
        b->nodes[left + 1].first = mid;
        b->nodes[left + 1].count = n->first + n->count - mid;
        n->first = left;
        n->count = 0;
        stack[sp++] = left;
        stack[sp++] = left + 1;
    }
    return 0;
}

void sim_bvh_free(struct sim_bvh *b)
{
    free(b->nodes);
    free(b->tri_order);
    memset(b, 0, sizeof(*b));
}

/* Slab test. @retval entry distance, or a negative value on a miss */
static double box_hit(const struct sim_bvh_node *n, vec3 o, vec3 inv, double t_max)
{
    double t0 = 0.0, t1 = t_max;
    double oa[3] = {o.x, o.y, o.z}, ia[3] = {inv.x, inv.y, inv.z};
    for (int a = 0; a < 3; a++) {
        double ta = (n->lo[a] - oa[a]) * ia[a], tb = (n->hi[a] - oa[a]) * ia[a];
        if (ta > tb) {
            double t = ta;
            ta = tb;
            tb = t;
        }
        t0 = ta > t0 ? ta : t0;
        t1 = tb < t1 ? tb : t1;
        if (t0 > t1)
            return -1.0;
    }
    return t0;
}

/* Moller-Trumbore ray/triangle intersection. */
static int tri_hit(const struct sim_mesh *m, uint32_t tri, vec3 o, vec3 d, double *t, double *u,
                   double *v)
{
    const float *p0 = vert(m, tri, 0), *p1 = vert(m, tri, 1), *p2 = vert(m, tri, 2);
    vec3 a = v3(p0[0], p0[1], p0[2]);
    vec3 e1 = v3_sub(v3(p1[0], p1[1], p1[2]), a), e2 = v3_sub(v3(p2[0], p2[1], p2[2]), a);
    vec3 pv = v3_cross(d, e2);
    double det = v3_dot(e1, pv);
    if (fabs(det) < 1e-14)
        return 0;
    double inv = 1.0 / det;
    vec3 tv = v3_sub(o, a);
    *u = v3_dot(tv, pv) * inv;
    if (*u < 0.0 || *u > 1.0)
        return 0;
    vec3 qv = v3_cross(tv, e1);
    *v = v3_dot(d, qv) * inv;
    if (*v < 0.0 || *u + *v > 1.0)
        return 0;
    *t = v3_dot(e2, qv) * inv;
    return 1;
}

static int traverse(const struct sim_bvh *b, vec3 o, vec3 d, double t_min, double t_max,
                    struct sim_hit *hit, int any)
{
    vec3 inv = v3(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
    uint32_t stack[STACK_DEPTH * 2], sp = 0;
    int found = 0;
    stack[sp++] = 0;
    while (sp > 0) {
        const struct sim_bvh_node *n = &b->nodes[stack[--sp]];
        if (box_hit(n, o, inv, t_max) < 0.0)
            continue;
        if (n->count == 0) {
            stack[sp++] = n->first;
            stack[sp++] = n->first + 1;
            continue;
        }
        for (uint32_t i = n->first; i < n->first + n->count; i++) {
            double t, u, v;
            uint32_t tri = b->tri_order[i];
            if (!tri_hit(b->mesh, tri, o, d, &t, &u, &v) || t <= t_min || t >= t_max)
                continue;
            if (any)
                return 1;
            t_max = t;
            hit->t = t;
            hit->tri = tri;
            hit->u = u;
            hit->v = v;
            found = 1;
        }
    }
    return found;
}

int sim_bvh_intersect(const struct sim_bvh *b, vec3 o, vec3 d, double t_min, double t_max,
                      struct sim_hit *hit)
{
    return traverse(b, o, d, t_min, t_max, hit, 0);
}

int sim_bvh_occluded(const struct sim_bvh *b, vec3 o, vec3 d, double t_min, double t_max)
{
    struct sim_hit unused;
    return traverse(b, o, d, t_min, t_max, &unused, 1);
}

/* Closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5). */
static vec3 closest_on_triangle(vec3 p, vec3 a, vec3 b, vec3 c)
{
    vec3 ab = v3_sub(b, a), ac = v3_sub(c, a), ap = v3_sub(p, a);
    double d1 = v3_dot(ab, ap), d2 = v3_dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0)
        return a;
    vec3 bp = v3_sub(p, b);
    double d3 = v3_dot(ab, bp), d4 = v3_dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3)
        return b;
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
        return v3_add(a, v3_scale(ab, d1 / (d1 - d3)));
    vec3 cp = v3_sub(p, c);
    double d5 = v3_dot(ab, cp), d6 = v3_dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6)
        return c;
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
        return v3_add(a, v3_scale(ac, d2 / (d2 - d6)));
    double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
        return v3_add(b, v3_scale(v3_sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6))));
    double denom = 1.0 / (va + vb + vc);
    return v3_add(a, v3_add(v3_scale(ab, vb * denom), v3_scale(ac, vc * denom)));
}

static double box_distance(const struct sim_bvh_node *n, vec3 p)
{
    double pa[3] = {p.x, p.y, p.z}, sum = 0.0;
    for (int a = 0; a < 3; a++) {
        double d = pa[a] < n->lo[a] ? n->lo[a] - pa[a] : pa[a] > n->hi[a] ? pa[a] - n->hi[a] : 0.0;
        sum += d * d;
    }
    return sqrt(sum);
}

double sim_bvh_distance(const struct sim_bvh *b, vec3 p, double max_dist)
{
    vec3 closest;
    return sim_bvh_closest(b, p, max_dist, &closest);
}

double sim_bvh_closest(const struct sim_bvh *b, vec3 p, double max_dist, vec3 *closest)
{
    uint32_t stack[STACK_DEPTH * 2], sp = 0;
    double best = max_dist;
    *closest = p;
    stack[sp++] = 0;
    while (sp > 0) {
        const struct sim_bvh_node *n = &b->nodes[stack[--sp]];
        if (box_distance(n, p) >= best)
            continue;
        if (n->count == 0) {
            /* nearer child last, so it is searched first */
            uint32_t l = n->first, r = n->first + 1;
            int left_first = box_distance(&b->nodes[l], p) <= box_distance(&b->nodes[r], p);
            stack[sp++] = left_first ? r : l;
            stack[sp++] = left_first ? l : r;
            continue;
        }
        for (uint32_t i = n->first; i < n->first + n->count; i++) {
            uint32_t t = b->tri_order[i];
            const float *a = vert(b->mesh, t, 0), *bb = vert(b->mesh, t, 1),
                        *c = vert(b->mesh, t, 2);
            vec3 q = closest_on_triangle(p, v3(a[0], a[1], a[2]), v3(bb[0], bb[1], bb[2]),
                                         v3(c[0], c[1], c[2]));
            double d = v3_len(v3_sub(p, q));
            if (d < best) {
                best = d;
                *closest = q;
            }
        }
    }
    return best;
}
