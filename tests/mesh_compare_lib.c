/* Mesh-to-mesh distances by area-weighted sampling and BVH closest-point queries. */
#define _POSIX_C_SOURCE 200809L
#include "mesh_compare.h"

#include "config.h"
#include "frames.h"
#include "lsq.h"
#include "scan_dir.h"
#include "sim_bvh.h"
#include "sim_random.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static vec3 vtx(const struct sim_mesh *m, uint32_t t, int k)
{
    const float *p = &m->pos[3 * m->tri[3 * t + (uint32_t)k]];
    return v3(p[0], p[1], p[2]);
}

static int reaches(const struct sim_bvh *self, vec3 p, vec3 n, vec3 src, double min_cos)
{
    vec3 d = v3_sub(src, p);
    if (v3_dot(n, d) < min_cos * v3_len(d))
        return 0;
    return !sim_bvh_occluded(self, v3_add(p, v3_scale(n, 0.01)), d, 1e-6, 1.0);
}

/* Can some view's camera and projector both reach p (object frame, normal n)? */
static int observable(const struct mesh_visibility *vis, const struct sim_bvh *self, vec3 p, vec3 n)
{
    double min_cos = cos(vis->max_incidence_deg * M_PI / 180.0);
    for (uint32_t k = 0; k < vis->views; k++) {
        double a = 2.0 * M_PI * k / vis->views, c = cos(a), s = sin(a);
        /* the table turned the object by +a: devices are at Rz(-a) in the object frame */
        vec3 cam = v3(c * vis->camera_table.x + s * vis->camera_table.y,
                      -s * vis->camera_table.x + c * vis->camera_table.y, vis->camera_table.z);
        vec3 proj =
            v3(c * vis->projector_table.x + s * vis->projector_table.y,
               -s * vis->projector_table.x + c * vis->projector_table.y, vis->projector_table.z);
        if (reaches(self, p, n, cam, min_cos) && reaches(self, p, n, proj, min_cos))
            return 1;
    }
    return 0;
}

/* Distances of @p n area-uniform samples of @p from to @p to; sample heights in @p z; and
 * whether each is observable (when @p vis and @p self, the BVH of @p from, are given). */
static int sample_distances(const struct sim_mesh *from, const struct sim_bvh *to, uint32_t n,
                            double *dist, double *z, const struct mesh_visibility *vis,
                            const struct sim_bvh *self, uint8_t *seen)
{
    double *cum = malloc(sizeof(double) * from->tri_count);
    if (cum == NULL)
        return -1;
    double total = 0.0;
    for (uint32_t t = 0; t < from->tri_count; t++) {
        vec3 a = vtx(from, t, 0);
        total += 0.5 * v3_len(v3_cross(v3_sub(vtx(from, t, 1), a), v3_sub(vtx(from, t, 2), a)));
        cum[t] = total;
    }
    uint64_t seed = 12345;
    for (uint32_t i = 0; i < n; i++) {
        double target = sim_random_unit(&seed) * total;
        uint32_t lo = 0, hi = from->tri_count - 1;
        while (lo < hi) { /* first triangle whose cumulative area exceeds target */
            uint32_t mid = (lo + hi) / 2;
            if (cum[mid] < target)
                lo = mid + 1;
            else
                hi = mid;
        }
        double r1 = sqrt(sim_random_unit(&seed)), r2 = sim_random_unit(&seed);
        vec3 a = vtx(from, lo, 0), b = vtx(from, lo, 1), c = vtx(from, lo, 2);
        vec3 p = v3_add(v3_scale(a, 1.0 - r1),
                        v3_add(v3_scale(b, r1 * (1.0 - r2)), v3_scale(c, r1 * r2)));
        dist[i] = sim_bvh_distance(to, p, 1e9);
        z[i] = p.z;
        if (seen != NULL) {
            vec3 nn = v3_norm(v3_cross(v3_sub(b, a), v3_sub(c, a)));
            seen[i] = (uint8_t)observable(vis, self, p, nn);
        }
    }
    free(cum);
    return 0;
}

/* Move @p m rigidly onto the surface of @p truth: point-to-plane ICP of its vertices against
 * their closest true points (the plane through the closest point, across p - q), pairs over
 * 3 mm left out (a fringe, a fragment). @p deg, @p mm: how far it moved. */
static void align_to_truth(struct sim_mesh *m, const struct sim_bvh *truth, double *deg, double *mm)
{
    uint32_t step = m->vert_count / 20000u + 1u;
    struct frame_xform total = {{1, 0, 0, 0, 1, 0, 0, 0, 1}, {0, 0, 0}};
    for (int it = 0; it < 30; it++) {
        struct lsq_rigid eq;
        lsq_rigid_clear(&eq);
        for (uint32_t i = 0; i < m->vert_count; i += step) {
            vec3 p = v3(m->pos[3 * i], m->pos[3 * i + 1], m->pos[3 * i + 2]), q;
            double d = sim_bvh_closest(truth, p, 3.0, &q);
            if (d <= 3.0 && d >= 1e-9)
                lsq_rigid_add(&eq, p, q, v3_scale(v3_sub(p, q), 1.0 / d));
        }
        struct frame_xform step_x, moved;
        if (lsq_rigid_step(&eq, &step_x) != 0)
            break;
        for (uint32_t i = 0; i < m->vert_count; i++) {
            vec3 p = frame_point(&step_x, v3(m->pos[3 * i], m->pos[3 * i + 1], m->pos[3 * i + 2]));
            m->pos[3 * i] = (float)p.x, m->pos[3 * i + 1] = (float)p.y,
                       m->pos[3 * i + 2] = (float)p.z;
        }
        frame_compose(&step_x, &total, &moved);
        total = moved;
        double tr = step_x.rot[0] + step_x.rot[4] + step_x.rot[8]; /* 3 - angle^2 */
        if (3.0 - tr < 1e-14 && v3_len(step_x.origin) < 1e-6)
            break;
    }
    double tr = total.rot[0] + total.rot[4] + total.rot[8], c = 0.5 * (tr - 1.0);
    *deg = acos(c > 1.0 ? 1.0 : c) * 180.0 / M_PI;
    *mm = v3_len(v3_sub(frame_point(&total, v3(100, 0, 50)), v3(100, 0, 50)));
}

static uint32_t root_of(uint32_t *parent, uint32_t v)
{
    while (parent[v] != v)
        v = parent[v] = parent[parent[v]];
    return v;
}

/* Connected pieces of @p m (vertices joined by its triangles; unused vertices not counted). */
static uint32_t count_pieces(const struct sim_mesh *m)
{
    uint32_t *parent = malloc(sizeof(uint32_t) * m->vert_count), pieces = 0;
    uint8_t *used = calloc(m->vert_count, 1);
    if (parent == NULL || used == NULL) {
        free(parent);
        free(used);
        return 0;
    }
    for (uint32_t v = 0; v < m->vert_count; v++)
        parent[v] = v;
    for (uint32_t t = 0; t < m->tri_count; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t a = root_of(parent, m->tri[3 * t + k]);
            uint32_t b = root_of(parent, m->tri[3 * t + (k + 1) % 3]);
            parent[a] = b;
            used[m->tri[3 * t + k]] = 1;
        }
    for (uint32_t v = 0; v < m->vert_count; v++)
        pieces += used[v] && root_of(parent, v) == v;
    free(parent);
    free(used);
    return pieces;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Holes of @p m: its boundary edges (used by one triangle) joined into pieces, each measured
 * by the diagonal of its bounding box; edges used by more than two triangles counted apart. */
static void count_holes(const struct sim_mesh *m, struct mesh_comparison *out)
{
    size_t ne = 3 * (size_t)m->tri_count;
    uint64_t *edge = malloc(sizeof(uint64_t) * (ne > 0 ? ne : 1));
    uint32_t *parent = malloc(sizeof(uint32_t) * (m->vert_count > 0 ? m->vert_count : 1));
    double *box = malloc(sizeof(double) * 6 * (m->vert_count > 0 ? m->vert_count : 1));
    uint8_t *on_hole = calloc(m->vert_count > 0 ? m->vert_count : 1, 1);
    if (edge == NULL || parent == NULL || box == NULL || on_hole == NULL)
        goto out_free;
    for (uint32_t t = 0; t < m->tri_count; t++)
        for (int k = 0; k < 3; k++) {
            uint64_t a = m->tri[3 * t + k], b = m->tri[3 * t + (k + 1) % 3];
            edge[3 * (size_t)t + k] = a < b ? a << 32 | b : b << 32 | a;
        }
    qsort(edge, ne, sizeof(uint64_t), cmp_u64);
    for (uint32_t v = 0; v < m->vert_count; v++)
        parent[v] = v;
    for (size_t i = 0; i < ne;) {
        size_t j = i;
        while (j < ne && edge[j] == edge[i])
            j++;
        uint32_t a = (uint32_t)(edge[i] >> 32), b = (uint32_t)edge[i];
        if (j - i == 1) {
            out->boundary_edges++;
            on_hole[a] = on_hole[b] = 1;
            parent[root_of(parent, a)] = root_of(parent, b);
        } else if (j - i > 2) {
            out->nonmanifold_edges++;
        }
        i = j;
    }
    for (uint32_t v = 0; v < m->vert_count; v++) {
        double *bx = &box[6 * (size_t)v];
        bx[0] = bx[1] = bx[2] = 1e30;
        bx[3] = bx[4] = bx[5] = -1e30;
    }
    for (uint32_t v = 0; v < m->vert_count; v++) {
        if (!on_hole[v])
            continue;
        double *bx = &box[6 * (size_t)root_of(parent, v)];
        for (int k = 0; k < 3; k++) {
            bx[k] = fmin(bx[k], m->pos[3 * v + k]);
            bx[3 + k] = fmax(bx[3 + k], m->pos[3 * v + k]);
        }
    }
    for (uint32_t v = 0; v < m->vert_count; v++) {
        if (!on_hole[v] || root_of(parent, v) != v)
            continue;
        const double *bx = &box[6 * (size_t)v];
        double size = v3_len(v3(bx[3] - bx[0], bx[4] - bx[1], bx[5] - bx[2]));
        out->holes++;
        out->holes_under_10mm += size < 10.0;
        out->largest_hole_mm = fmax(out->largest_hole_mm, size);
    }
out_free:
    free(edge);
    free(parent);
    free(box);
    free(on_hole);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int mesh_compare_files(const char *result_ply, const char *truth_ply, uint32_t n,
                       const struct mesh_visibility *vis, int align, struct mesh_comparison *out,
                       char *err, size_t err_len)
{
    struct sim_mesh res, tru;
    struct sim_bvh res_bvh, tru_bvh;
    int rc = sim_mesh_load_ply(&res, result_ply, err, (unsigned)err_len);
    if (rc != 0)
        return rc;
    rc = sim_mesh_load_ply(&tru, truth_ply, err, (unsigned)err_len);
    if (rc != 0) {
        sim_mesh_free(&res);
        return rc;
    }
    double *d1 = malloc(sizeof(double) * n), *d2 = malloc(sizeof(double) * n);
    double *z1 = malloc(sizeof(double) * n), *z2 = malloc(sizeof(double) * n);
    uint8_t *observed = vis != NULL ? malloc(n) : NULL;
    rc = -1;
    double align_deg = 0.0, align_mm = 0.0;
    if (d1 && d2 && z1 && z2 && sim_bvh_build(&tru_bvh, &tru) == 0) {
        if (align)
            align_to_truth(&res, &tru_bvh, &align_deg, &align_mm);
        if (sim_bvh_build(&res_bvh, &res) == 0) {
            rc = sample_distances(&res, &tru_bvh, n, d1, z1, NULL, NULL, NULL);
            if (rc == 0)
                rc = sample_distances(&tru, &res_bvh, n, d2, z2, vis, &tru_bvh, observed);
            sim_bvh_free(&res_bvh);
        }
        sim_bvh_free(&tru_bvh);
    }
    if (rc == 0) {
        memset(out, 0, sizeof(*out));
        out->aligned = align;
        out->align_deg = align_deg;
        out->align_mm = align_mm;
        out->result_triangles = res.tri_count;
        out->result_pieces = count_pieces(&res);
        count_holes(&res, out);
        double s1 = 0, s2 = 0, s2_seen = 0;
        uint32_t within = 0, seen = 0, seen_within = 0;
        for (uint32_t i = 0; i < n; i++) {
            s1 += d1[i];
            s2 += d2[i];
            within += d2[i] <= 1.0;
            if (z2[i] >= 1.0) {
                seen++;
                seen_within += d2[i] <= 1.0;
                s2_seen += d2[i];
            }
        }
        if (observed != NULL) {
            uint32_t obs = 0, obs_within = 0;
            double s_obs = 0.0;
            for (uint32_t i = 0; i < n; i++) {
                if (!observed[i])
                    continue;
                obs++;
                obs_within += d2[i] <= 1.0;
                s_obs += d2[i];
            }
            out->observable_share = (double)obs / n;
            out->truth_observable_within_1mm = obs ? (double)obs_within / obs : 0.0;
            out->truth_observable_to_result_mean_mm = obs ? s_obs / obs : 0.0;
            out->symmetric_observable_mean_mm =
                0.5 * (s1 / n + out->truth_observable_to_result_mean_mm);
        }
        qsort(d1, n, sizeof(double), cmp_double);
        out->result_to_truth_mean_mm = s1 / n;
        out->result_to_truth_p95_mm = d1[(size_t)(0.95 * (n - 1))];
        out->result_to_truth_max_mm = d1[n - 1];
        out->truth_to_result_mean_mm = s2 / n;
        out->truth_within_1mm = (double)within / n;
        out->truth_seen_within_1mm = seen ? (double)seen_within / seen : 0.0;
        out->truth_seen_to_result_mean_mm = seen ? s2_seen / seen : 0.0;
        out->symmetric_mean_mm =
            0.5 * (out->result_to_truth_mean_mm + out->truth_seen_to_result_mean_mm);
    } else {
        snprintf(err, err_len, "out of memory");
    }
    free(d1);
    free(d2);
    free(z1);
    free(z2);
    free(observed);
    sim_mesh_free(&res);
    sim_mesh_free(&tru);
    return rc;
}

void mesh_compare_print(const struct mesh_comparison *r, FILE *out)
{
    if (r->aligned)
        fprintf(out, "aligned to the truth first: turned %.3f deg, moved %.3f mm\n", r->align_deg,
                r->align_mm);
    fprintf(out,
            "result triangles: %u in %u connected pieces\n"
            "result holes: %u (%u under 10 mm across, the largest %.1f mm); %u boundary edges, "
            "%u edges of more than two triangles (watertight: both 0)\n"
            "result -> truth: mean %.3f mm, 95%% %.3f mm, max %.3f mm\n"
            "truth -> result: mean %.3f mm, within 1 mm %.2f%%\n"
            "truth above the table (z >= 1 mm) -> result: mean %.3f mm, within 1 mm %.2f%%\n"
            "symmetric mean surface distance: %.3f mm\n",
            (unsigned)r->result_triangles, (unsigned)r->result_pieces, (unsigned)r->holes,
            (unsigned)r->holes_under_10mm, r->largest_hole_mm, (unsigned)r->boundary_edges,
            (unsigned)r->nonmanifold_edges, r->result_to_truth_mean_mm, r->result_to_truth_p95_mm,
            r->result_to_truth_max_mm, r->truth_to_result_mean_mm, 100.0 * r->truth_within_1mm,
            r->truth_seen_to_result_mean_mm, 100.0 * r->truth_seen_within_1mm,
            r->symmetric_mean_mm);
    if (r->observable_share > 0.0) /* only with a scan directory's rig */
        fprintf(out,
                "observable true surface: %.2f%% of it; within 1 mm of the result %.2f%%, mean "
                "distance %.3f mm\n"
                "symmetric mean surface distance over the observable surface: %.3f mm\n",
                100.0 * r->observable_share, 100.0 * r->truth_observable_within_1mm,
                r->truth_observable_to_result_mean_mm, r->symmetric_observable_mean_mm);
}

int mesh_visibility_from_scan(const char *scan_dir, struct mesh_visibility *vis, char *err,
                              size_t err_len)
{
    static struct app_config cfg;
    struct scan_calib calib;
    char path[HAL_MAX_PATH + 32];
    scan_dir_path(path, sizeof(path), scan_dir, -1, "config.ini");
    int rc = config_load(&cfg, path, err, err_len);
    scan_dir_path(path, sizeof(path), scan_dir, -1, "calibration.ini");
    if (rc == 0)
        rc = calib_load(&calib, path, cfg.light_count, err, err_len);
    if (rc != 0)
        return rc;
    struct frame_xform t;
    frame_table_from_camera(&calib, &t);
    vis->camera_table = frame_point(&t, v3(0, 0, 0));
    vec3 proj_cam = v3_scale(m3_tmul(calib.proj_rot, v3_from(calib.proj_trans_mm)), -1.0);
    vis->projector_table = frame_point(&t, proj_cam);
    vis->views = cfg.views;
    vis->max_incidence_deg = 75.0;
    return 0;
}
