/* BVH built by the binned surface-area heuristic; front-to-back stack traversal. */
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

/* Surface-area heuristic, binned (Wald, "On fast construction of SAH-based bounding volume
 * hierarchies", 2007): a node's triangles are split where
 *   cost = area(left) * count(left) + area(right) * count(right)
 * is least over SAH_BINS bins of centroid along each axis; rays then open about half the nodes a
 * median split makes them open. Where every centroid falls in one bin, halved in the order they
 * are in. */
#define SAH_BINS 16

struct box {
    float lo[3], hi[3];
};

static void box_empty(struct box *b)
{
    for (int a = 0; a < 3; a++) {
        b->lo[a] = 1e30f;
        b->hi[a] = -1e30f;
    }
}

static void box_grow(struct box *b, const struct box *o)
{
    for (int a = 0; a < 3; a++) {
        b->lo[a] = o->lo[a] < b->lo[a] ? o->lo[a] : b->lo[a];
        b->hi[a] = o->hi[a] > b->hi[a] ? o->hi[a] : b->hi[a];
    }
}

static double box_area(const struct box *b)
{
    double e[3];
    for (int a = 0; a < 3; a++)
        e[a] = b->hi[a] > b->lo[a] ? (double)b->hi[a] - b->lo[a] : 0.0;
    return e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
}

static void tri_box(const struct sim_mesh *m, uint32_t tri, struct box *b)
{
    box_empty(b);
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 3; a++) {
            float p = vert(m, tri, k)[a];
            b->lo[a] = p < b->lo[a] ? p : b->lo[a];
            b->hi[a] = p > b->hi[a] ? p : b->hi[a];
        }
}

/* A node's bounds: of its triangles' boxes. */
static void node_bounds(struct sim_bvh *b, struct sim_bvh_node *n)
{
    struct box all, one;
    box_empty(&all);
    for (uint32_t i = n->first; i < n->first + n->count; i++) {
        tri_box(b->mesh, b->tri_order[i], &one);
        box_grow(&all, &one);
    }
    memcpy(n->lo, all.lo, sizeof(n->lo));
    memcpy(n->hi, all.hi, sizeof(n->hi));
}

static int bin_of(float c, float lo, float scale)
{
    int k = (int)((c - lo) * scale);
    return k < 0 ? 0 : k >= SAH_BINS ? SAH_BINS - 1 : k;
}

/* Split tri_order[lo, hi) in two. @retval the first index of the right part */
static uint32_t split_sah(struct sim_bvh *b, uint32_t lo, uint32_t hi)
{
    const struct sim_mesh *m = b->mesh;
    float clo[3] = {1e30f, 1e30f, 1e30f}, chi[3] = {-1e30f, -1e30f, -1e30f};
    for (uint32_t i = lo; i < hi; i++)
        for (int a = 0; a < 3; a++) {
            float c = centroid(m, b->tri_order[i], a);
            clo[a] = c < clo[a] ? c : clo[a];
            chi[a] = c > chi[a] ? c : chi[a];
        }
    double best = 1e300;
    int best_axis = -1, best_bin = 0;
    for (int a = 0; a < 3; a++) {
        if (!(chi[a] > clo[a]))
            continue;
        float scale = SAH_BINS / (chi[a] - clo[a]);
        struct box bins[SAH_BINS], tb, acc;
        uint32_t counts[SAH_BINS] = {0};
        double right_area[SAH_BINS];
        uint32_t right_count[SAH_BINS];
        for (int k = 0; k < SAH_BINS; k++)
            box_empty(&bins[k]);
        for (uint32_t i = lo; i < hi; i++) {
            int k = bin_of(centroid(m, b->tri_order[i], a), clo[a], scale);
            tri_box(m, b->tri_order[i], &tb);
            box_grow(&bins[k], &tb);
            counts[k]++;
        }
        box_empty(&acc);
        uint32_t n = 0;
        for (int k = SAH_BINS - 1; k > 0; k--) { /* right of plane k: bins k.. */
            box_grow(&acc, &bins[k]);
            n += counts[k];
            right_area[k] = box_area(&acc);
            right_count[k] = n;
        }
        box_empty(&acc);
        n = 0;
        for (int k = 1; k < SAH_BINS; k++) { /* left of plane k: bins ..k-1 */
            box_grow(&acc, &bins[k - 1]);
            n += counts[k - 1];
            if (n == 0 || right_count[k] == 0)
                continue;
            double cost = box_area(&acc) * n + right_area[k] * right_count[k];
            if (cost < best) {
                best = cost;
                best_axis = a;
                best_bin = k;
            }
        }
    }
    if (best_axis < 0) { /* one bin holds them all: halve in the order given */
        return lo + (hi - lo) / 2;
    }
    float scale = SAH_BINS / (chi[best_axis] - clo[best_axis]);
    uint32_t i = lo, j = hi;
    while (i < j) {
        if (bin_of(centroid(m, b->tri_order[i], best_axis), clo[best_axis], scale) < best_bin) {
            i++;
        } else {
            uint32_t t = b->tri_order[i];
            b->tri_order[i] = b->tri_order[--j];
            b->tri_order[j] = t;
        }
    }
    return i;
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
    /* depth first; a node STACK_DEPTH deep stays a leaf, so that traversal's stack (two entries
     * a level) never overflows */
    uint32_t stack[STACK_DEPTH * 2], depth[STACK_DEPTH * 2], sp = 0;
    depth[sp] = 0;
    stack[sp++] = 0;
    while (sp > 0) {
        sp--;
        struct sim_bvh_node *n = &b->nodes[stack[sp]];
        uint32_t level = depth[sp];
        node_bounds(b, n);
        if (n->count <= LEAF_TRIS || level + 1 >= STACK_DEPTH)
            continue;
        uint32_t mid = split_sah(b, n->first, n->first + n->count);
        uint32_t left = b->node_count;
        b->node_count += 2;
        b->nodes[left].first = n->first;
        b->nodes[left].count = mid - n->first;
        b->nodes[left + 1].first = mid;
        b->nodes[left + 1].count = n->first + n->count - mid;
        n->first = left;
        n->count = 0;
        depth[sp] = level + 1;
        stack[sp++] = left;
        depth[sp] = level + 1;
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

/* Slab test, without a branch on the ray (each comparison is a min or a max; a NaN, from a
 * direction parallel to a slab through its plane, leaves the interval as it was).
 * @retval entry distance, or a negative value on a miss */
static inline double box_hit(const struct sim_bvh_node *n, vec3 o, vec3 inv, double t_max)
{
    double t0 = 0.0, t1 = t_max;
    double oa[3] = {o.x, o.y, o.z}, ia[3] = {inv.x, inv.y, inv.z};
    for (int a = 0; a < 3; a++) {
        double ta = (n->lo[a] - oa[a]) * ia[a], tb = (n->hi[a] - oa[a]) * ia[a];
        double near = ta > tb ? tb : ta, far = ta > tb ? ta : tb;
        t0 = near > t0 ? near : t0;
        t1 = far < t1 ? far : t1;
    }
    return t0 > t1 ? -1.0 : t0;
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

/* Front to back: of an inner node's two children the nearer is searched first, so that a
 * closest hit found there shortens the ray before the farther one is opened; a node entered
 * beyond the hit found so far is skipped when taken off the stack (the same test box_hit makes
 * with the shortened ray, so the hits are those of any order but for exact ties in t). */
static int traverse(const struct sim_bvh *b, vec3 o, vec3 d, double t_min, double t_max,
                    struct sim_hit *hit, int any)
{
    vec3 inv = v3(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
    uint32_t stack[STACK_DEPTH * 2], sp = 0;
    double entry[STACK_DEPTH * 2];
    int found = 0;
    double t_root = box_hit(&b->nodes[0], o, inv, t_max);
    if (t_root < 0.0)
        return 0;
    entry[sp] = t_root;
    stack[sp++] = 0;
    while (sp > 0) {
        sp--;
        if (entry[sp] > t_max)
            continue;
        const struct sim_bvh_node *n = &b->nodes[stack[sp]];
        if (n->count == 0) {
            double t0 = box_hit(&b->nodes[n->first], o, inv, t_max);
            double t1 = box_hit(&b->nodes[n->first + 1], o, inv, t_max);
            uint32_t near = n->first, far = n->first + 1;
            if (t1 >= 0.0 && (t0 < 0.0 || t1 < t0)) {
                double t = t0;
                t0 = t1;
                t1 = t;
                near = n->first + 1;
                far = n->first;
            }
            if (t1 >= 0.0) {
                entry[sp] = t1;
                stack[sp++] = far;
            }
            if (t0 >= 0.0) {
                entry[sp] = t0;
                stack[sp++] = near;
            }
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
