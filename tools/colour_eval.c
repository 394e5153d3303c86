/* build/colour-eval: how close a scan's fused colour is to the simulated object's true albedo.
 *
 *   colour-eval measure SCAN_DIR RESULT_DIR LABEL   one CSV row (header with LABEL = header)
 *   colour-eval closeup SCAN_DIR OUT.png RESULT_DIR...  the boundary of views 0 and 1, truth first
 *   colour-eval closeup-dark SCAN_DIR OUT.png RESULT_DIR...  the same on the very dark paint
 *
 * SCAN_DIR is a simulated scan (its config, calibration, truth mesh and view angles); RESULT_DIR
 * holds mesh.ply and view_NNN/cloud.ply from `scanner process SCAN_DIR --out RESULT_DIR`
 * (or SCAN_DIR itself). Fused vertices are compared with the true albedo at the closest true
 * surface point, away from paint edges (the fusion blends colour over ~2 voxels); the very dark
 * paint counts as every paint and is also summed on its own (dark_*). A vertex belongs to the view
 * that weighs most there in the fusion (head-on, near, both camera and projector reaching it);
 * where that view changes is a boundary between views, and the colour step there is the difference
 * between the two views' own colour estimates (their clouds) at the boundary. */
#define _POSIX_C_SOURCE 200809L
#include "colour_metrics.h"
#include "config.h"
#include "frames.h"
#include "image_io.h"
#include "scan_dir.h"
#include "sim_bvh.h"
#include "sim_mesh.h"
#include "sim_rig.h"
#include "storage_posix.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_VIEWS 64
#define EDGE_MM 1.5         /* paint within this of a vertex must be one colour */
#define MATCH_MM 1.0        /* a result vertex farther from the truth is not compared */
#define HIGHLIGHT_WHITE 0.3 /* white added, as a share of the diffuse colour: a highlight */
#define GREY_VARIANCE 0.004 /* paint whose channels vary less is too grey for white_fit() */
#define MAX_PAINTS 16
#define CLOSEUP_PX 320

struct rig_views {
    struct app_config cfg;
    struct scan_calib calib;
    double height_mm;
    uint32_t views;
    long angle_mdeg[MAX_VIEWS];
    struct frame_xform obj[MAX_VIEWS]; /* object from camera, per view */
    vec3 cam_obj[MAX_VIEWS], proj_obj[MAX_VIEWS];
};

/* ---- the scan's rig ---- */

static int rig_load(struct rig_views *r, const char *scan_dir)
{
    char path[HAL_MAX_PATH + 64], err[512];
    scan_dir_path(path, sizeof(path), scan_dir, -1, "config.ini");
    int rc = config_load(&r->cfg, path, err, sizeof(err));
    scan_dir_path(path, sizeof(path), scan_dir, -1, "calibration.ini");
    if (rc == 0)
        rc = calib_load(&r->calib, path, r->cfg.light_count, err, sizeof(err));
    if (rc != 0) {
        fprintf(stderr, "colour-eval: %s\n", err);
        return rc;
    }
    const double *pose = r->cfg.sim.object_pose_deg;
    if (pose[0] != 0.0 || pose[1] != 0.0 || pose[2] != 0.0 || r->cfg.sim.has_rig) {
        /* its truth is looked up in the standing object's frame and the scan's calibration */
        fprintf(stderr, "colour-eval: %s: [sim] object_pose and rig are not supported here\n",
                scan_dir);
        return -EINVAL;
    }
    r->height_mm = sim_rig_placed_height(&r->cfg.sim);
    r->views = r->cfg.views < MAX_VIEWS ? r->cfg.views : MAX_VIEWS;
    vec3 proj_cam = v3_scale(m3_tmul(r->calib.proj_rot, v3_from(r->calib.proj_trans_mm)), -1.0);
    for (uint32_t v = 0; v < r->views; v++) {
        static struct scan_dir_view meta;
        rc = scan_dir_read_view(scan_dir, v, &meta, err, sizeof(err));
        if (rc != 0) {
            fprintf(stderr, "colour-eval: %s\n", err);
            return rc;
        }
        int32_t angle = meta.angle_mdeg;
        r->angle_mdeg[v] = angle;
        frame_object_from_camera(&r->calib, (int32_t)angle, &r->obj[v]);
        r->cam_obj[v] = frame_point(&r->obj[v], v3(0, 0, 0));
        r->proj_obj[v] = frame_point(&r->obj[v], proj_cam);
    }
    return 0;
}

/* The scan's true mesh (truth_mesh.ply) and its BVH. @retval 0 or -errno, said on stderr */
static int truth_load(const char *scan_dir, struct sim_mesh *truth, struct sim_bvh *bvh)
{
    char path[HAL_MAX_PATH + 64], err[512];
    snprintf(path, sizeof(path), "%s/truth_mesh.ply", scan_dir);
    int rc = sim_mesh_load_ply(truth, path, err, sizeof(err));
    if (rc != 0) {
        fprintf(stderr, "colour-eval: %s\n", err);
        return rc;
    }
    rc = sim_bvh_build(bvh, truth);
    if (rc != 0)
        fprintf(stderr, "colour-eval: %s: out of memory for its BVH\n", path);
    return rc;
}

static int reaches(const struct sim_bvh *truth, vec3 p, vec3 n, vec3 src)
{
    vec3 start = v3_add(p, v3_scale(n, 0.05));
    return !sim_bvh_occluded(truth, start, v3_sub(src, start), 1e-6, 1.0 - 1e-6);
}

/* The view whose fusion weight is largest at true point @p p with normal @p n; -1: none. */
static int dominant_view(const struct rig_views *r, const struct sim_bvh *truth, vec3 p, vec3 n)
{
    const struct scan_calib *c = &r->calib;
    const double min_cos = cos(75.0 * M_PI / 180.0);
    int best = -1;
    double best_w = 0.0;
    for (uint32_t v = 0; v < r->views; v++) {
        vec3 pc = frame_point_inv(&r->obj[v], p);
        double u = c->cam_fx_px * pc.x / pc.z + c->cam_cx_px;
        double w = c->cam_fy_px * pc.y / pc.z + c->cam_cy_px;
        vec3 to_cam = v3_norm(v3_sub(r->cam_obj[v], p));
        vec3 to_proj = v3_norm(v3_sub(r->proj_obj[v], p));
        double head_on = v3_dot(n, to_cam);
        if (pc.z <= 0.0 || u < 0 || w < 0 || u >= c->cam_width || w >= c->cam_height ||
            head_on < min_cos || v3_dot(n, to_proj) < min_cos)
            continue;
        double weight = head_on * (600.0 / pc.z) * (600.0 / pc.z);
        if (weight <= best_w || !reaches(truth, p, n, r->cam_obj[v]) ||
            !reaches(truth, p, n, r->proj_obj[v]))
            continue;
        best = (int)v;
        best_w = weight;
    }
    return best;
}

/* True albedo at @p p; @p dark: set on the very dark paint (compared as every paint, and also
 * on its own). @retval 0 usable, 1 within EDGE_MM of a paint edge */
static int true_albedo(const struct rig_views *r, vec3 p, double albedo[3], int *dark)
{
    *dark = sim_albedo_at(&r->cfg.sim, r->height_mm, p, albedo);
    static const double d[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                   {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
    for (int k = 0; k < 6; k++) {
        double other[3];
        vec3 q = v3_add(p, v3_scale(v3(d[k][0], d[k][1], d[k][2]), EDGE_MM));
        sim_albedo_at(&r->cfg.sim, r->height_mm, q, other);
        if (memcmp(other, albedo, sizeof(other)) != 0)
            return 1;
    }
    return 0;
}

static void lab_of(const uint8_t rgb[3], double lab[3])
{
    double lin[3] = {rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0};
    colour_linear_rgb_to_lab(lin, lab);
}

/* ---- nearest point of a view's cloud (a sorted grid of 1 mm cells) ---- */

struct cloud {
    struct sim_mesh pts;
    uint64_t *key; /* cell key << 32 | point index, sorted */
};

static uint64_t cell_key(int64_t x, int64_t y, int64_t z)
{
    return (uint64_t)((x + 1024) & 2047) << 22 | (uint64_t)((y + 1024) & 2047) << 11 |
           (uint64_t)((z + 1024) & 2047);
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static int cloud_load(struct cloud *c, const char *path)
{
    char err[512];
    int rc = sim_mesh_load_ply_points(&c->pts, path, err, sizeof(err));
    if (rc == 0 && c->pts.rgb == NULL)
        rc = -EINVAL;
    if (rc != 0) {
        fprintf(stderr, "colour-eval: %s\n", rc == -EINVAL ? path : err);
        return rc;
    }
    c->key = malloc(sizeof(uint64_t) * c->pts.vert_count);
    if (c->key == NULL)
        return -ENOMEM;
    for (uint32_t i = 0; i < c->pts.vert_count; i++) {
        const float *p = &c->pts.pos[3 * i];
        c->key[i] =
            cell_key((int64_t)floor(p[0]), (int64_t)floor(p[1]), (int64_t)floor(p[2])) << 32 | i;
    }
    qsort(c->key, c->pts.vert_count, sizeof(uint64_t), cmp_u64);
    return 0;
}

static void cloud_free(struct cloud *c)
{
    sim_mesh_free(&c->pts);
    free(c->key);
}

/* The view's colour at @p p as the fusion takes it: the mean of its points within MATCH_MM
 * (about 50 pixels) weighted by their confidence, so that a step measures what differs between
 * views, not the pixels' noise. @retval 1 found */
static int cloud_colour(const struct cloud *c, vec3 p, uint8_t rgb[3], double *mean_weight)
{
    int count = 0;
    int64_t cx = (int64_t)floor(p.x), cy = (int64_t)floor(p.y), cz = (int64_t)floor(p.z);
    double sum[3] = {0, 0, 0}, weight = 0.0;
    for (int64_t dz = -1; dz <= 1; dz++)
        for (int64_t dy = -1; dy <= 1; dy++)
            for (int64_t dx = -1; dx <= 1; dx++) {
                uint64_t k = cell_key(cx + dx, cy + dy, cz + dz) << 32;
                size_t lo = 0, hi = c->pts.vert_count;
                while (lo < hi) { /* first entry of the cell */
                    size_t mid = (lo + hi) / 2;
                    if (c->key[mid] < k)
                        lo = mid + 1;
                    else
                        hi = mid;
                }
                for (size_t j = lo; j < c->pts.vert_count && (c->key[j] >> 32) == (k >> 32); j++) {
                    uint32_t i = (uint32_t)c->key[j];
                    const float *q = &c->pts.pos[3 * i];
                    if (v3_len(v3_sub(p, v3(q[0], q[1], q[2]))) >= MATCH_MM ||
                        (c->pts.quality != NULL && c->pts.quality[i] <= 0.0f))
                        continue; /* no colour estimate there (saturated, every light grazing) */
                    double w = c->pts.quality != NULL ? c->pts.quality[i] : 1.0, lin[3];
                    sim_mesh_linear(&c->pts, i, lin);
                    for (int k = 0; k < 3; k++)
                        sum[k] += w * 255.0 * lin[k];
                    weight += w;
                    count++;
                }
            }
    if (mean_weight != NULL)
        *mean_weight = count ? weight / count : 0.0;
    for (int k = 0; weight > 0.0 && k < 3; k++)
        rgb[k] = (uint8_t)(sum[k] / weight + 0.5);
    return weight > 0.0;
}

/* ---- measure ---- */

struct vertex_eval {
    int usable;     /* compared with the truth */
    int dark;       /* on the very dark paint */
    int view;       /* dominant view, -1 none */
    vec3 truth_pos; /* closest true point */
    double albedo[3];
    double lab_true[3], lab_got[3];
};

/* White light on top of a colour: @p got fitted as a * albedo + b * (1, 1, 1) (least squares).
 * A shading or white-reference error scales the albedo (a); a highlight adds white, since the
 * lights are white (b), and so does an offset left in (none keeps Ca). @retval -1 where the
 * paint is too grey to tell the two apart */
static int white_fit(const double got[3], const double albedo[3], double *a, double *b)
{
    double s_aa = 0.0, s_a = 0.0, s_ag = 0.0, s_g = 0.0;
    for (int k = 0; k < 3; k++) {
        s_aa += albedo[k] * albedo[k];
        s_a += albedo[k];
        s_ag += albedo[k] * got[k];
        s_g += got[k];
    }
    double det = 3.0 * s_aa - s_a * s_a; /* 9 x the variance of the channels */
    if (det < 9.0 * GREY_VARIANCE)
        return -1;
    *a = (3.0 * s_ag - s_a * s_g) / det;
    *b = (s_aa * s_g - s_a * s_ag) / det;
    return 0;
}

static int cmp_double(const void *a, const void *b);

static double median(double *v, size_t n)
{
    qsort(v, n, sizeof(double), cmp_double);
    return n ? v[n / 2] : NAN;
}

/* The paint of a vertex, as an index into @p paints (added when new; at most MAX_PAINTS). */
static int paint_index(double paints[][3], int *count, const double albedo[3])
{
    for (int k = 0; k < *count; k++)
        if (memcmp(paints[k], albedo, sizeof(paints[k])) == 0)
            return k;
    if (*count == MAX_PAINTS)
        return -1;
    memcpy(paints[*count], albedo, sizeof(paints[0]));
    return (*count)++;
}

/* Highlight shares: of the fused vertices, and of the views' own colours at them (each view's
 * visible surface, weighted by the confidence it gives its colour there, as the fusion is). A
 * colour carries a highlight where the white in it (white_fit) exceeds the method's usual white for
 * that paint (its median over the model: an offset such as none's Ca) by HIGHLIGHT_WHITE x the
 * paint's usual diffuse part. Chromatic paint only. */
static int highlight_shares(const struct sim_mesh *res, const struct vertex_eval *ve,
                            const struct cloud *clouds, uint32_t views, double *fused,
                            double *per_view)
{
    double paints[MAX_PAINTS][3], base_b[MAX_PAINTS], unit[MAX_PAINTS];
    int npaint = 0, *paint = malloc(sizeof(int) * res->vert_count);
    double *fa = malloc(sizeof(double) * res->vert_count),
           *fb = malloc(sizeof(double) * res->vert_count);
    double *tmp = malloc(sizeof(double) * res->vert_count);
    if (paint == NULL || fa == NULL || fb == NULL || tmp == NULL) {
        free(paint), free(fa), free(fb), free(tmp);
        return -ENOMEM;
    }
    for (uint32_t i = 0; i < res->vert_count; i++) {
        double got[3];
        sim_mesh_linear(res, i, got);
        paint[i] = -1;
        if (ve[i].usable && white_fit(got, ve[i].albedo, &fa[i], &fb[i]) == 0)
            paint[i] = paint_index(paints, &npaint, ve[i].albedo);
    }
    for (int p = 0; p < npaint; p++) { /* the paint's usual white and diffuse part */
        size_t n = 0;
        for (uint32_t i = 0; i < res->vert_count; i++)
            if (paint[i] == p)
                tmp[n++] = fb[i];
        base_b[p] = median(tmp, n);
        n = 0;
        for (uint32_t i = 0; i < res->vert_count; i++)
            if (paint[i] == p)
                tmp[n++] = fa[i];
        unit[p] = median(tmp, n) * (paints[p][0] + paints[p][1] + paints[p][2]) / 3.0;
    }
    size_t fn = 0, fh = 0;
    double vn = 0.0, vh = 0.0;
    for (uint32_t i = 0; i < res->vert_count; i++) {
        int p = paint[i];
        if (p < 0)
            continue;
        fn++;
        fh += fb[i] - base_b[p] > HIGHLIGHT_WHITE * unit[p];
        const float *q = &res->pos[3 * i];
        for (uint32_t v = 0; v < views; v++) {
            uint8_t rgb[3];
            double got[3], a, b, w;
            if (!cloud_colour(&clouds[v], v3(q[0], q[1], q[2]), rgb, &w))
                continue;
            for (int k = 0; k < 3; k++)
                got[k] = rgb[k] / 255.0;
            if (white_fit(got, ve[i].albedo, &a, &b) != 0)
                continue;
            vn += w; /* as much as the fusion will take from this view here */
            vh += w * (b - base_b[p] > HIGHLIGHT_WHITE * unit[p]);
        }
    }
    *fused = fn ? (double)fh / fn : NAN;
    *per_view = vn > 0.0 ? vh / vn : NAN;
    free(paint), free(fa), free(fb), free(tmp);
    return 0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double registration_coupling(const char *result_dir, uint32_t views)
{
    double sum = 0.0;
    int pairs = 0;
    for (uint32_t v = 1; v < views; v++) {
        char path[HAL_MAX_PATH + 64], line[256];
        snprintf(path, sizeof(path), "%s/view_%03u/registration.ini", result_dir, (unsigned)v);
        FILE *f = fopen(path, "r");
        double share;
        while (f != NULL && fgets(line, sizeof(line), f) != NULL)
            if (sscanf(line, "coupled_share = %lf", &share) == 1) {
                sum += share;
                pairs++;
            }
        if (f != NULL)
            fclose(f);
    }
    return pairs > 0 ? sum / pairs : NAN;
}

/* Mean colour step between the two views' own estimates at the boundary vertices, and between
 * the fused colours across boundary edges whose ends have the same true albedo. */
static void boundary_steps(const struct sim_mesh *res, const struct vertex_eval *ve,
                           const struct cloud *clouds, double *view_step, double *fused_step)
{
    double vsum = 0.0, fsum = 0.0;
    size_t vn = 0, fn = 0;
    for (uint32_t t = 0; t < res->tri_count; t++)
        for (int e = 0; e < 3; e++) {
            uint32_t a = res->tri[3 * t + e], b = res->tri[3 * t + (e + 1) % 3];
            if (a > b || !ve[a].usable || !ve[b].usable || ve[a].view < 0 || ve[b].view < 0 ||
                ve[a].view == ve[b].view)
                continue; /* each boundary edge once (its reverse is in the neighbour) */
            if (colour_ciede2000(ve[a].lab_true, ve[b].lab_true) < 1e-9) {
                fsum += colour_ciede2000(ve[a].lab_got, ve[b].lab_got);
                fn++;
            }
            uint8_t ca[3], cb[3];
            const float *p = &res->pos[3 * a];
            vec3 q = v3(p[0], p[1], p[2]);
            if (cloud_colour(&clouds[ve[a].view], q, ca, NULL) &&
                cloud_colour(&clouds[ve[b].view], q, cb, NULL)) {
                double la[3], lb[3];
                lab_of(ca, la);
                lab_of(cb, lb);
                vsum += colour_ciede2000(la, lb);
                vn++;
            }
        }
    *view_step = vn ? vsum / vn : NAN;
    *fused_step = fn ? fsum / fn : NAN;
}

static int cmd_measure(const char *scan_dir, const char *result_dir, const char *label)
{
    static struct rig_views r;
    struct sim_mesh truth, res;
    struct sim_bvh bvh;
    struct cloud clouds[MAX_VIEWS];
    char path[HAL_MAX_PATH + 64], err[512];
    memset(clouds, 0, sizeof(clouds));
    if (rig_load(&r, scan_dir) != 0 || truth_load(scan_dir, &truth, &bvh) != 0)
        return 1;
    snprintf(path, sizeof(path), "%s/mesh.ply", result_dir);
    if (sim_mesh_load_ply(&res, path, err, sizeof(err)) != 0 || res.rgb == NULL) {
        fprintf(stderr, "colour-eval: %s: no coloured mesh\n", path);
        return 1;
    }
    for (uint32_t v = 0; v < r.views; v++) {
        snprintf(path, sizeof(path), "%s/view_%03u/cloud.ply", result_dir, (unsigned)v);
        if (cloud_load(&clouds[v], path) != 0)
            return 1;
    }
    struct vertex_eval *ve = calloc(res.vert_count, sizeof(*ve));
    double *de = calloc(res.vert_count, sizeof(double));
    double mae[3] = {0, 0, 0}, dark_sum = 0.0, dark_l = 0.0;
    size_t used = 0, dark_n = 0;
    for (uint32_t i = 0; ve != NULL && de != NULL && i < res.vert_count; i++) {
        const float *p = &res.pos[3 * i], *n = &res.normal[3 * i];
        vec3 q;
        ve[i].view = -1;
        if (sim_bvh_closest(&bvh, v3(p[0], p[1], p[2]), MATCH_MM, &q) >= MATCH_MM)
            continue;
        double *albedo = ve[i].albedo, got[3];
        ve[i].truth_pos = q;
        ve[i].view = dominant_view(&r, &bvh, q, v3(n[0], n[1], n[2]));
        if (true_albedo(&r, q, albedo, &ve[i].dark) != 0)
            continue;
        ve[i].usable = 1;
        sim_mesh_linear(&res, i, got);
        for (int k = 0; k < 3; k++)
            mae[k] += fabs(got[k] - albedo[k]);
        colour_linear_rgb_to_lab(albedo, ve[i].lab_true);
        colour_linear_rgb_to_lab(got, ve[i].lab_got);
        de[used] = colour_ciede2000(ve[i].lab_true, ve[i].lab_got);
        if (ve[i].dark) {
            dark_n++;
            dark_sum += de[used];
            dark_l += ve[i].lab_got[0];
        }
        used++;
    }
    if (used == 0) {
        fprintf(stderr, "colour-eval: %s: no vertex of the result lies on the true surface\n",
                result_dir);
        return 1;
    }
    double sum = 0.0;
    for (size_t i = 0; i < used; i++)
        sum += de[i];
    qsort(de, used, sizeof(double), cmp_double);
    double view_step, fused_step, hl_fused, hl_views;
    boundary_steps(&res, ve, clouds, &view_step, &fused_step);
    if (highlight_shares(&res, ve, clouds, r.views, &hl_fused, &hl_views) != 0)
        return 1;
    printf("%s,%zu,%.3f,%.3f,%.4f,%.4f,%.4f,%.3f,%.3f,%.4f,%.4f,%.4f,%zu,%.3f,%.2f\n", label, used,
           sum / used, de[(size_t)(0.95 * (double)(used - 1))], mae[0] / used, mae[1] / used,
           mae[2] / used, view_step, fused_step, hl_views, hl_fused,
           registration_coupling(result_dir, r.views), dark_n, dark_n ? dark_sum / dark_n : 0.0,
           dark_n ? dark_l / dark_n : 0.0);
    free(ve);
    free(de);
    for (uint32_t v = 0; v < r.views; v++)
        cloud_free(&clouds[v]);
    sim_bvh_free(&bvh);
    sim_mesh_free(&truth);
    sim_mesh_free(&res);
    return 0;
}

/* ---- close-up of the boundary between views 0 and 1 ---- */

static uint8_t to_srgb(double linear)
{
    double v = linear <= 0.0031308 ? 12.92 * linear : 1.055 * pow(linear, 1.0 / 2.4) - 0.055;
    return (uint8_t)(v <= 0.0 ? 0 : v >= 1.0 ? 255 : v * 255.0 + 0.5);
}

/* Add object point @p q's pixel (pinhole) seen by camera @p xf to the sums @p su, @p sv. */
static void add_projection(const struct rig_views *r, const struct frame_xform *xf, vec3 q,
                           double *su, double *sv, size_t *n)
{
    vec3 pc = frame_point_inv(xf, q);
    *su += r->calib.cam_fx_px * pc.x / pc.z + r->calib.cam_cx_px;
    *sv += r->calib.cam_fy_px * pc.y / pc.z + r->calib.cam_cy_px;
    (*n)++;
}

/* Camera half way between views 0 and 1; centre: the 0|1 boundary of the truth it sees. */
static int closeup_camera(const struct rig_views *r, const struct sim_mesh *truth,
                          const struct sim_bvh *bvh, struct frame_xform *mid, double centre[2])
{
    long a0 = r->angle_mdeg[0], a1 = r->angle_mdeg[1];
    if (a1 < a0)
        a1 += 360000;
    frame_object_from_camera(&r->calib, (int32_t)((a0 + a1) / 2), mid);
    vec3 cam = frame_point(mid, v3(0, 0, 0));
    double su = 0.0, sv = 0.0;
    size_t n = 0;
    for (uint32_t i = 0; i < truth->vert_count; i++) {
        const float *p = &truth->pos[3 * i], *nn = &truth->normal[3 * i];
        vec3 q = v3(p[0], p[1], p[2]), nv = v3(nn[0], nn[1], nn[2]);
        int v = dominant_view(r, bvh, q, nv);
        if ((v != 0 && v != 1) || v3_dot(nv, v3_norm(v3_sub(cam, q))) < 0.5 ||
            !reaches(bvh, q, nv, cam))
            continue;
        /* on the boundary: a neighbourhood point 3 mm along the turn belongs to the other view */
        vec3 along = v3_norm(v3(-q.y, q.x, 0.0));
        vec3 q2 = v3_add(q, v3_scale(along, v == 0 ? 3.0 : -3.0));
        if (dominant_view(r, bvh, q2, nv) == v)
            continue;
        add_projection(r, mid, q, &su, &sv, &n);
    }
    if (n == 0)
        return -ENOENT;
    centre[0] = su / n;
    centre[1] = sv / n;
    return 0;
}

/* Render @p m (vertex colours, or the true albedo when @p r is given) into a panel. */
static void render_panel(const struct sim_mesh *m, const struct sim_bvh *bvh,
                         const struct rig_views *truth_of, const struct rig_views *r,
                         const struct frame_xform *mid, const double centre[2], uint8_t *out,
                         uint32_t stride, uint32_t x0)
{
    vec3 cam = frame_point(mid, v3(0, 0, 0));
    for (uint32_t y = 0; y < CLOSEUP_PX; y++)
        for (uint32_t x = 0; x < CLOSEUP_PX; x++) {
            double u = centre[0] - CLOSEUP_PX / 2 + x, v = centre[1] - CLOSEUP_PX / 2 + y;
            vec3 d = v3((u - r->calib.cam_cx_px) / r->calib.cam_fx_px,
                        (v - r->calib.cam_cy_px) / r->calib.cam_fy_px, 1.0);
            uint8_t *px = &out[3 * ((size_t)y * stride + x0 + x)];
            struct sim_hit h;
            px[0] = px[1] = px[2] = 40;
            if (!sim_bvh_intersect(bvh, cam, frame_dir(mid, d), 1e-6, 1e9, &h))
                continue;
            const uint32_t *tv = &m->tri[3 * h.tri];
            double w[3] = {1.0 - h.u - h.v, h.u, h.v}, lin[3] = {0, 0, 0};
            vec3 p = v3(0, 0, 0);
            for (int k = 0; k < 3; k++) {
                const float *pp = &m->pos[3 * tv[k]];
                double got[3];
                p = v3_add(p, v3_scale(v3(pp[0], pp[1], pp[2]), w[k]));
                if (truth_of != NULL)
                    continue; /* the truth's colour, below: its mesh has none */
                sim_mesh_linear(m, tv[k], got);
                for (int c = 0; c < 3; c++)
                    lin[c] += w[k] * got[c];
            }
            if (truth_of != NULL)
                sim_albedo_at(&truth_of->cfg.sim, truth_of->height_mm, p, lin);
            for (int c = 0; c < 3; c++)
                px[c] = to_srgb(lin[c]);
        }
}

/* View 0's camera; centre: the very dark paint it sees head-on (the stripe faces angle 0). */
static int closeup_dark_camera(const struct rig_views *r, const struct sim_mesh *truth,
                               const struct sim_bvh *bvh, struct frame_xform *cam_xf,
                               double centre[2])
{
    *cam_xf = r->obj[0];
    vec3 cam = r->cam_obj[0];
    double su = 0.0, sv = 0.0, albedo[3];
    size_t n = 0;
    for (uint32_t i = 0; i < truth->vert_count; i++) {
        const float *p = &truth->pos[3 * i], *nn = &truth->normal[3 * i];
        vec3 q = v3(p[0], p[1], p[2]), nv = v3(nn[0], nn[1], nn[2]);
        if (!sim_albedo_at(&r->cfg.sim, r->height_mm, q, albedo) ||
            v3_dot(nv, v3_norm(v3_sub(cam, q))) < 0.5 || !reaches(bvh, q, nv, cam))
            continue;
        add_projection(r, cam_xf, q, &su, &sv, &n);
    }
    if (n == 0)
        return -ENOENT;
    centre[0] = su / n;
    centre[1] = sv / n;
    return 0;
}

/* Close-up panels, truth first, then each result: at the boundary of views 0 and 1, or (@p dark)
 * on the very dark paint. */
static int cmd_closeup(const char *scan_dir, const char *out_png, int count, char **results,
                       int dark)
{
    static struct rig_views r;
    struct sim_mesh truth;
    struct sim_bvh bvh;
    struct frame_xform mid;
    double centre[2];
    char path[HAL_MAX_PATH + 64], err[512];
    if (rig_load(&r, scan_dir) != 0 || truth_load(scan_dir, &truth, &bvh) != 0)
        return 1;
    if (dark ? closeup_dark_camera(&r, &truth, &bvh, &mid, centre) != 0
             : closeup_camera(&r, &truth, &bvh, &mid, centre) != 0) {
        fprintf(stderr, "colour-eval: %s\n",
                dark ? "view 0 sees no dark paint head-on"
                     : "views 0 and 1 share no boundary the camera "
                       "sees");
        return 1;
    }
    uint32_t width = CLOSEUP_PX * (uint32_t)(count + 1);
    uint8_t *img = calloc((size_t)width * CLOSEUP_PX * 3, 1);
    if (img == NULL)
        return 1;
    render_panel(&truth, &bvh, &r, &r, &mid, centre, img, width, 0);
    for (int i = 0; i < count; i++) {
        struct sim_mesh m;
        struct sim_bvh mb;
        snprintf(path, sizeof(path), "%s/mesh.ply", results[i]);
        if (sim_mesh_load_ply(&m, path, err, sizeof(err)) != 0 || m.rgb == NULL ||
            sim_bvh_build(&mb, &m) != 0) {
            fprintf(stderr, "colour-eval: %s: no coloured mesh\n", path);
            free(img);
            return 1;
        }
        render_panel(&m, &mb, NULL, &r, &mid, centre, img, width, CLOSEUP_PX * (uint32_t)(i + 1));
        sim_bvh_free(&mb);
        sim_mesh_free(&m);
    }
    struct hal_storage st;
    storage_posix_init(&st);
    int rc = image_write_png(&st, out_png, img, width, CLOSEUP_PX, 3);
    free(img);
    sim_bvh_free(&bvh);
    sim_mesh_free(&truth);
    if (rc != 0)
        fprintf(stderr, "colour-eval: %s: %s\n", out_png, strerror(-rc));
    return rc == 0 ? 0 : 1;
}

int main(int argc, char **argv)
{
    if (argc == 5 && strcmp(argv[1], "measure") == 0)
        return cmd_measure(argv[2], argv[3], argv[4]);
    if (argc >= 5 && strcmp(argv[1], "closeup") == 0)
        return cmd_closeup(argv[2], argv[3], argc - 4, argv + 4, 0);
    if (argc >= 5 && strcmp(argv[1], "closeup-dark") == 0)
        return cmd_closeup(argv[2], argv[3], argc - 4, argv + 4, 1);
    if (argc == 2 && strcmp(argv[1], "header") == 0) {
        printf("label,vertices,de2000_mean,de2000_p95,mae_r,mae_g,mae_b,view_step_de2000,"
               "fused_step_de2000,highlight_views,highlight_fused,icp_coupling,dark_vertices,"
               "dark_de2000_mean,dark_lstar\n");
        return 0;
    }
    fprintf(stderr, "usage: colour-eval header\n"
                    "       colour-eval measure SCAN_DIR RESULT_DIR LABEL\n"
                    "       colour-eval closeup SCAN_DIR OUT.png RESULT_DIR...\n"
                    "       colour-eval closeup-dark SCAN_DIR OUT.png RESULT_DIR...\n");
    return 2;
}
