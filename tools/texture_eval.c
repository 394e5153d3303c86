/* build/texture-eval: how close a scan's texture (texture.png through mesh.obj's vt) and its
 * vertex colours are to the simulated object's true albedo, over the whole surface, paint edges
 * included (issue 34).
 *
 *   texture-eval SCAN_DIR RESULT_DIR [SCENE_CONFIG] [--balanced]
 *
 * SCAN_DIR is a simulated scan (its config and truth mesh); RESULT_DIR holds mesh.obj, mesh.mtl and
 * texture.png (`scanner process SCAN_DIR --out RESULT_DIR`, or SCAN_DIR itself); SCENE_CONFIG
 * is the config the scan was taken with, for [sim] albedo_image's path (the scan keeps a copy of
 * it whose relative paths no longer lead anywhere), default SCAN_DIR/config.ini. Each triangle is
 * sampled at its centroid and three points towards its corners; a sample farther than 1 mm from
 * the true surface is not compared. Prints one line: samples, then CIEDE2000 mean and 95th
 * percentile of the texture and of the vertex colours (interpolated across the triangle as a
 * viewer shows them), then the same over the dark paint (true L* < 30), then the seams: at each
 * vertex that has more than one place in the texture (a chart's border), the texture's colour
 * at each place against its first; then the same numbers as one CSV line ("csv,samples,
 * texture mean,p95,vertex mean,p95,dark samples,dark texture,dark vertex,seams,mean,max"), and
 * per channel the gain that brings the texture (and the vertex colours) to the truth in least
 * squares; --balanced applies them first (what a white reference of the renderer that made the
 * frames would set: make eval-cycles, whose frames are not the simulator's). Then the paint
 * edges apart: the samples where the truth changes by more than EDGE_DE00 within EDGE_MM (six
 * points at +-EDGE_MM along the axes), the texture's mean there and elsewhere, and the truth
 * averaged over those seven points against itself: what a colour perfect but for a blur of about
 * a texel would score ("edges,samples,texture mean on edges,elsewhere,blur alone"). */
#define _POSIX_C_SOURCE 200809L
#include "board_albedo.h"
#include "colour_metrics.h"
#include "config.h"
#include "image_io.h"
#include "sim_bvh.h"
#include "sim_mesh.h"
#include "sim_rig.h"

#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MATCH_MM 1.0
#define EDGE_MM 0.25  /* about a texel of make run's texture (0.268 mm) */
#define EDGE_DE00 2.0 /* a change of paint a person sees side by side */
#define MAX_SIDE 4096u

struct obj_mesh {
    float *v;   /* x y z (object frame, mm) and r g b (sRGB 0..1) */
    float *vt;  /* u v (OBJ: v up from the bottom) */
    int64_t *f; /* per corner: vertex, texture coordinate */
    size_t nv, nvt, nf, cap_v, cap_vt, cap_f;
};

static void *grow(void *p, size_t *cap, size_t need, size_t size)
{
    if (need <= *cap)
        return p;
    *cap = need * 2;
    return realloc(p, *cap * size);
}

/* mesh.obj as the scanner writes it: "v x y z r g b" (Y up: the object frame's x, z, -y),
 * "vt u v", "f v/vt/vn ..." (triangles). @retval 0 @retval -1 (said) */
static int obj_load(const char *path, struct obj_mesh *m)
{
    FILE *fp = fopen(path, "r");
    char line[512];
    memset(m, 0, sizeof(*m));
    if (fp == NULL) {
        perror(path);
        return -1;
    }
    while (fgets(line, sizeof(line), fp) != NULL) {
        float a[6];
        long long c[6];
        if (sscanf(line, "v %f %f %f %f %f %f", &a[0], &a[1], &a[2], &a[3], &a[4], &a[5]) == 6) {
            m->v = grow(m->v, &m->cap_v, m->nv + 1, 6 * sizeof(float));
            float *o = &m->v[6 * m->nv++];
            o[0] = a[0], o[1] = -a[2], o[2] = a[1]; /* back to the object frame */
            o[3] = a[3], o[4] = a[4], o[5] = a[5];
        } else if (sscanf(line, "vt %f %f", &a[0], &a[1]) == 2) {
            m->vt = grow(m->vt, &m->cap_vt, m->nvt + 1, 2 * sizeof(float));
            m->vt[2 * m->nvt] = a[0], m->vt[2 * m->nvt + 1] = a[1];
            m->nvt++;
        } else if (sscanf(line, "f %lld/%lld/%*d %lld/%lld/%*d %lld/%lld/%*d", &c[0], &c[1], &c[2],
                          &c[3], &c[4], &c[5]) == 6) {
            m->f = grow(m->f, &m->cap_f, m->nf + 1, 6 * sizeof(int64_t));
            for (int k = 0; k < 6; k++)
                m->f[6 * m->nf + (size_t)k] = c[k] - 1;
            m->nf++;
        }
    }
    fclose(fp);
    for (size_t i = 0; i < 6 * m->nf; i++)
        if (m->f[i] < 0 || (size_t)m->f[i] >= (i % 2 == 0 ? m->nv : m->nvt)) {
            fprintf(stderr, "texture-eval: %s: a face names a vertex or vt it does not have\n",
                    path);
            return -1;
        }
    if (m->nf == 0 || m->v == NULL || m->vt == NULL) {
        fprintf(stderr, "texture-eval: %s: no textured faces\n", path);
        return -1;
    }
    return 0;
}

static double srgb_decode(double e)
{
    return e <= 0.04045 ? e / 12.92 : pow((e + 0.055) / 1.055, 2.4);
}

/* The texture's linear colour at (u, v) (OBJ's), bilinear, texel centres at +0.5. */
static void texture_at(const uint8_t *tex, uint32_t w, uint32_t h, double u, double v,
                       double out[3])
{
    double x = u * w - 0.5, y = (1.0 - v) * h - 0.5;
    long x0 = (long)floor(x), y0 = (long)floor(y);
    double fx = x - x0, fy = y - y0;
    out[0] = out[1] = out[2] = 0.0;
    for (int q = 0; q < 4; q++) {
        long xs = x0 + q % 2, ys = y0 + q / 2;
        xs = xs < 0 ? 0 : xs >= (long)w ? (long)w - 1 : xs;
        ys = ys < 0 ? 0 : ys >= (long)h ? (long)h - 1 : ys;
        double wt = (q % 2 ? fx : 1.0 - fx) * (q / 2 ? fy : 1.0 - fy);
        for (int k = 0; k < 3; k++)
            out[k] += wt * srgb_decode(tex[3 * ((size_t)ys * w + (size_t)xs) + (size_t)k] / 255.0);
    }
}

/* Doubles a sample keeps: the truth, the texture's and the vertex colour (linear), the truth
 * averaged round it and how much it changes there (truth_around). */
#define SAMPLE 13

/* The truth at @p q and at six points +-EDGE_MM along the axes round it: their mean (@p blur,
 * linear) and the largest CIEDE2000 of one of them from @p at, the truth at q (@p change). */
static void truth_around(const struct sim_config *sim, double height, vec3 q, const double at[3],
                         double blur[3], double *change)
{
    double lab_at[3];
    colour_linear_rgb_to_lab(at, lab_at);
    memcpy(blur, at, 3 * sizeof(double));
    *change = 0.0;
    for (int k = 0; k < 6; k++) {
        double d = k % 2 ? -EDGE_MM : EDGE_MM, a[3], lab[3];
        vec3 o = v3(k / 2 == 0 ? d : 0.0, k / 2 == 1 ? d : 0.0, k / 2 == 2 ? d : 0.0);
        sim_albedo_at(sim, height, v3_add(q, o), a);
        colour_linear_rgb_to_lab(a, lab);
        *change = fmax(*change, colour_ciede2000(lab_at, lab));
        for (int c = 0; c < 3; c++)
            blur[c] += a[c];
    }
    for (int c = 0; c < 3; c++)
        blur[c] /= 7.0;
}

/* The stage before fusion: each view's own colour (RESULT_DIR/view_NNN/cloud.ply, at its
 * registered pose; every 8th point with a colour estimate) against the truth, also apart on
 * the paint edges. Prints a line "views,points,mean,p95". */
static double p95(double *v, size_t n);
static void views_stage(const char *result, const struct app_config *cfg, double height,
                        const struct sim_bvh *bvh)
{
    size_t n = 0, cap = 0, edges = 0;
    double *de = NULL, sum = 0.0, edge_sum = 0.0;
    for (unsigned v = 0;; v++) {
        char path[HAL_MAX_PATH * 2 + 64], err[512];
        struct sim_mesh c;
        snprintf(path, sizeof(path), "%s/view_%03u/cloud.ply", result, v);
        if (sim_mesh_load_ply_points(&c, path, err, sizeof(err)) != 0)
            break;
        for (uint32_t i = 0; c.rgb != NULL && c.quality != NULL && i < c.vert_count; i += 8) {
            const float *p = &c.pos[3 * i];
            vec3 q;
            if (!(c.quality[i] > 0.0f) ||
                sim_bvh_closest(bvh, v3(p[0], p[1], p[2]), MATCH_MM, &q) >= MATCH_MM)
                continue;
            double albedo[3], got[3], lab_true[3], lab_got[3], blur[3], change;
            sim_albedo_at(&cfg->sim, height, q, albedo);
            truth_around(&cfg->sim, height, q, albedo, blur, &change);
            sim_mesh_linear(&c, i, got);
            colour_linear_rgb_to_lab(albedo, lab_true);
            colour_linear_rgb_to_lab(got, lab_got);
            if (n == cap)
                de = realloc(de, (cap = cap ? 2 * cap : 65536) * sizeof(double));
            if (de == NULL)
                break;
            de[n] = colour_ciede2000(lab_true, lab_got);
            if (change > EDGE_DE00)
                edges++, edge_sum += de[n];
            sum += de[n++];
        }
        sim_mesh_free(&c);
    }
    if (n > 0)
        printf("texture-eval: each view's own colour before fusion (%zu points): dE00 mean %.3f "
               "p95 %.3f; on paint edges (%zu) %.3f, elsewhere %.3f\nviews,%zu,%.3f,%.3f\n",
               n, sum / n, p95(de, n), edges, edges ? edge_sum / edges : 0.0,
               n > edges ? (sum - edge_sum) / (n - edges) : 0.0, n, sum / n, p95(de, n));
    free(de);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double p95(double *v, size_t n)
{
    qsort(v, n, sizeof(double), cmp_double);
    return n > 0 ? v[(size_t)(0.95 * (double)(n - 1))] : 0.0;
}

int main(int argc, char **argv)
{
    int balanced = argc > 3 && strcmp(argv[argc - 1], "--balanced") == 0;
    argc -= balanced;
    if (argc < 3 || argc > 4) {
        fprintf(stderr, "usage: texture-eval SCAN_DIR RESULT_DIR [SCENE_CONFIG] [--balanced]\n");
        return 2;
    }
    static struct app_config cfg;
    char path[HAL_MAX_PATH * 2 + 64], err[512], dir[HAL_MAX_PATH * 2 + 64];
    snprintf(path, sizeof(path), "%s/config.ini", argv[1]);
    snprintf(dir, sizeof(dir), "%s", argc == 4 ? argv[3] : path);
    if (config_load(&cfg, argc == 4 ? argv[3] : path, err, sizeof(err)) != 0 ||
        board_albedo_image_load(&cfg.sim, dirname(dir), err, sizeof(err)) != 0) {
        fprintf(stderr, "texture-eval: %s\n", err);
        return 1;
    }
    struct sim_mesh truth;
    struct sim_bvh bvh;
    struct obj_mesh m;
    snprintf(path, sizeof(path), "%s/truth_mesh.ply", argv[1]);
    if (sim_mesh_load_ply(&truth, path, err, sizeof(err)) != 0 || sim_bvh_build(&bvh, &truth)) {
        fprintf(stderr, "texture-eval: %s: %s\n", path, err);
        return 1;
    }
    snprintf(path, sizeof(path), "%s/mesh.obj", argv[2]);
    if (obj_load(path, &m) != 0)
        return 1;
    uint8_t *tex = malloc((size_t)MAX_SIDE * MAX_SIDE * 3);
    uint32_t w = 0, h = 0;
    snprintf(path, sizeof(path), "%s/texture.png", argv[2]);
    if (tex == NULL ||
        image_read_png(path, tex, (size_t)MAX_SIDE * MAX_SIDE * 3, &w, &h, 3, err, sizeof(err))) {
        fprintf(stderr, "texture-eval: %s: %s\n", path, err);
        return 1;
    }
    const double height = sim_rig_placed_height(&cfg.sim);
    static const double bary[4][3] = {{1.0 / 3, 1.0 / 3, 1.0 / 3},
                                      {4.0 / 6, 1.0 / 6, 1.0 / 6},
                                      {1.0 / 6, 4.0 / 6, 1.0 / 6},
                                      {1.0 / 6, 1.0 / 6, 4.0 / 6}};
    /* every sample's true, texture and vertex colour (linear) first: the gains need them all */
    double *smp = malloc(4 * m.nf * SAMPLE * sizeof(double));
    size_t n = 0;
    for (size_t f = 0; f < m.nf && smp != NULL; f++) {
        const int64_t *c = &m.f[6 * f];
        for (int s = 0; s < 4; s++) {
            double p[3] = {0, 0, 0}, uv[2] = {0, 0}, *o = &smp[SAMPLE * n];
            o[6] = o[7] = o[8] = 0.0;
            for (int k = 0; k < 3; k++) {
                const float *v = &m.v[6 * (size_t)c[2 * k]], *t = &m.vt[2 * (size_t)c[2 * k + 1]];
                for (int d = 0; d < 3; d++) {
                    p[d] += bary[s][k] * v[d];
                    o[6 + d] += bary[s][k] * srgb_decode(v[3 + d]);
                }
                uv[0] += bary[s][k] * t[0], uv[1] += bary[s][k] * t[1];
            }
            vec3 q;
            if (sim_bvh_closest(&bvh, v3(p[0], p[1], p[2]), MATCH_MM, &q) >= MATCH_MM)
                continue;
            sim_albedo_at(&cfg.sim, height, q, o);
            texture_at(tex, w, h, uv[0], uv[1], &o[3]);
            truth_around(&cfg.sim, height, q, o, &o[9], &o[12]);
            n++;
        }
    }
    /* per channel, the gain that brings each to the truth in least squares: what a white
     * reference of the same renderer would have set (applied with --balanced) */
    double gain[2][3];
    for (int which = 0; which < 2; which++)
        for (int k = 0; k < 3; k++) {
            double num = 0.0, den = 0.0;
            for (size_t i = 0; i < n; i++)
                num += smp[SAMPLE * i + k] * smp[SAMPLE * i + 3 + 3 * which + k],
                    den +=
                    smp[SAMPLE * i + 3 + 3 * which + k] * smp[SAMPLE * i + 3 + 3 * which + k];
            gain[which][k] = den > 0.0 ? num / den : 1.0;
        }
    double *de_tex = malloc((n + 1) * sizeof(double)), *de_vtx = malloc((n + 1) * sizeof(double));
    size_t dark = 0, edges = 0;
    double sum_tex = 0, sum_vtx = 0, dark_tex = 0, dark_vtx = 0, edge_tex = 0, blur_sum = 0;
    for (size_t i = 0; i < n && de_tex != NULL && de_vtx != NULL; i++) {
        double lab_true[3], lab_tex[3], lab_vtx[3], tc[3], vc[3];
        for (int k = 0; k < 3; k++) {
            tc[k] = smp[SAMPLE * i + 3 + k] * (balanced ? gain[0][k] : 1.0);
            vc[k] = smp[SAMPLE * i + 6 + k] * (balanced ? gain[1][k] : 1.0);
        }
        colour_linear_rgb_to_lab(&smp[SAMPLE * i], lab_true);
        colour_linear_rgb_to_lab(tc, lab_tex);
        colour_linear_rgb_to_lab(vc, lab_vtx);
        de_tex[i] = colour_ciede2000(lab_true, lab_tex);
        de_vtx[i] = colour_ciede2000(lab_true, lab_vtx);
        sum_tex += de_tex[i], sum_vtx += de_vtx[i];
        if (lab_true[0] < 30.0)
            dark++, dark_tex += de_tex[i], dark_vtx += de_vtx[i];
        double lab_blur[3];
        colour_linear_rgb_to_lab(&smp[SAMPLE * i + 9], lab_blur);
        blur_sum += colour_ciede2000(lab_true, lab_blur);
        if (smp[SAMPLE * i + 12] > EDGE_DE00)
            edges++, edge_tex += de_tex[i];
    }
    free(smp);
    if (n == 0) {
        fprintf(stderr, "texture-eval: %s: no sample lies on the true surface\n", argv[2]);
        return 1;
    }
    /* seams: each vertex's first place in the texture against its others */
    int64_t *first_vt = malloc(m.nv * sizeof(int64_t));
    double *first_lab = malloc(m.nv * 3 * sizeof(double)), seam_sum = 0.0, seam_max = 0.0;
    size_t seams = 0;
    for (size_t i = 0; first_vt != NULL && i < m.nv; i++)
        first_vt[i] = -1;
    for (size_t i = 0; first_vt != NULL && first_lab != NULL && i < 3 * m.nf; i++) {
        int64_t v = m.f[2 * i], t = m.f[2 * i + 1];
        double tc[3], lab[3];
        texture_at(tex, w, h, m.vt[2 * t], m.vt[2 * t + 1], tc);
        colour_linear_rgb_to_lab(tc, lab);
        if (first_vt[v] < 0) {
            first_vt[v] = t;
            memcpy(&first_lab[3 * v], lab, sizeof(lab));
        } else if (first_vt[v] != t) {
            double d = colour_ciede2000(&first_lab[3 * v], lab);
            seam_sum += d, seam_max = fmax(seam_max, d), seams++;
        }
    }
    free(first_vt);
    free(first_lab);
    double tex_mean = sum_tex / n, vtx_mean = sum_vtx / n;
    printf("texture-eval: %zu samples on %zu triangles, texture %u x %u: texture dE00 mean %.3f "
           "p95 %.3f; vertex colours mean %.3f p95 %.3f; dark paint (L* < 30, %zu samples) "
           "texture %.3f, vertex colours %.3f; seams: %zu places, dE00 mean %.3f max %.3f\n",
           n, m.nf, (unsigned)w, (unsigned)h, tex_mean, p95(de_tex, n), vtx_mean, p95(de_vtx, n),
           dark, dark ? dark_tex / dark : 0.0, dark ? dark_vtx / dark : 0.0, seams,
           seams ? seam_sum / seams : 0.0, seam_max);
    printf("texture-eval: the truth over the texture, per channel %.3f %.3f %.3f; over the vertex "
           "colours %.3f %.3f %.3f%s\n",
           gain[0][0], gain[0][1], gain[0][2], gain[1][0], gain[1][1], gain[1][2],
           balanced ? " (applied: --balanced)" : "");
    double tex_p95 = p95(de_tex, n), vtx_p95 = p95(de_vtx, n);
    printf("csv,%zu,%.3f,%.3f,%.3f,%.3f,%zu,%.3f,%.3f,%zu,%.3f,%.3f\n", n, tex_mean, tex_p95,
           vtx_mean, vtx_p95, dark, dark ? dark_tex / dark : 0.0, dark ? dark_vtx / dark : 0.0,
           seams, seams ? seam_sum / seams : 0.0, seam_max);
    printf(
        "texture-eval: paint edges (the truth changes by more than %.0f dE00 within %.2f mm): %zu "
        "samples, texture dE00 mean %.3f there, %.3f elsewhere; the truth blurred over +-%.2f "
        "mm alone: mean %.3f\nedges,%zu,%.3f,%.3f,%.3f\n",
        EDGE_DE00, EDGE_MM, edges, edges ? edge_tex / edges : 0.0,
        n > edges ? (sum_tex - edge_tex) / (n - edges) : 0.0, EDGE_MM, blur_sum / n, edges,
        edges ? edge_tex / edges : 0.0, n > edges ? (sum_tex - edge_tex) / (n - edges) : 0.0,
        blur_sum / n);
    views_stage(argv[2], &cfg, height, &bvh);
    free(de_tex);
    free(de_vtx);
    free(tex);
    free(m.v), free(m.vt), free(m.f);
    sim_bvh_free(&bvh);
    sim_mesh_free(&truth);
    return 0;
}
