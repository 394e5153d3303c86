/* build/relight-eval: the recovered model shown under a light the scan never used, against the
 * simulator's rendering of the true object under that light (issue 18's relighting measure).
 *
 *   relight-eval SCENE.ini SCAN_DIR RESULT_DIR LABEL [OUT.png]   one CSV line (LABEL = header)
 *
 * The truth: the simulator renders the object (SCENE.ini's object and material, the scan's
 * calibration) at a turntable angle between two views (22.5 deg) lit by one light alone, moved
 * to a place none of the rig's lights had, without noise, offset or ambient light. The model:
 * RESULT_DIR's mesh.ply (linear vertex colours: the diffuse albedo) and reflectance.ini (each
 * material cluster's lobe; none: matte), drawn by this file's own ray caster through the mesh:
 * S = rho cos(theta_i) + K D(alpha) / cos(theta_r) (GGX, firmware/reflect.h), in
 * the units where a white-referenced matte white facing the light at the reference distance is 1.
 * The truth's signal is put in the same units with the scan's white reference and falloff.
 * Compared: CIEDE2000 over the object's pixels the new light reaches in the truth (cast shadows
 * are geometry, not reflectance: this renderer draws none). Also printed: the lobe fitted to the
 * most samples (strength: K's mean over the channels; roughness) beside the simulator's material
 * put in the same form (material_lobe: the best lobe of the model's form for its specular part
 * where the scan saw it, through the rig's own lights). */
#define _POSIX_C_SOURCE 200809L
#include "colour_metrics.h"
#include "config.h"
#include "frames.h"
#include "image_io.h"
#include "reflect.h"
#include "scan.h"
#include "scan_dir.h"
#include "sim_bvh.h"
#include "sim_mesh.h"
#include "sim_rig.h"
#include "storage_posix.h"

#include <errno.h>
#include <ini.h>
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ANGLE_MDEG 22500 /* between views 0 and 1 */
/* The new light, camera frame (mm): to the right of the camera and below it, where the eval
 * rig's eight lights (tests/eval/ring-calib.ini) have none. */
static const double novel_light_mm[3] = {260.0, 120.0, 80.0};

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* reflectance.ini into @p m (inih handler). */
static int reflectance_key(void *user, const char *section, const char *name, const char *value)
{
    struct reflect_model *m = user;
    unsigned k;
    if (sscanf(section, "cluster_%u", &k) != 1 || k >= REFLECT_MAX_CLUSTERS)
        return 1;
    struct reflect_cluster *c = &m->cluster[k];
    if (k + 1 > m->count)
        m->count = k + 1;
    if (strcmp(name, "diffuse") == 0)
        sscanf(value, "%lf, %lf, %lf", &c->centre[0], &c->centre[1], &c->centre[2]);
    else if (strcmp(name, "specular") == 0)
        sscanf(value, "%lf, %lf, %lf", &c->specular[0], &c->specular[1], &c->specular[2]);
    else if (strcmp(name, "roughness") == 0)
        c->roughness = atof(value);
    else if (strcmp(name, "diffuse_roughness") == 0)
        c->retro = atof(value);
    else if (strcmp(name, "samples") == 0)
        c->samples = (uint32_t)strtoul(value, NULL, 10);
    else if (strcmp(name, "lobe_specular") == 0)
        sscanf(value, "%lf, %lf, %lf", &c->lobe_specular[0], &c->lobe_specular[1],
               &c->lobe_specular[2]);
    else if (strcmp(name, "lobe") == 0) {
        char *end = (char *)value;
        for (uint32_t n = 0; n < REFLECT_LOBE_NODES; n++) {
            c->lobe[n] = strtod(end, &end);
            end += *end == ',';
        }
        c->measured = 1;
    }
    return 1;
}

static uint8_t to_srgb(double linear)
{
    double v = linear <= 0.0031308 ? 12.92 * linear : 1.055 * pow(linear, 1.0 / 2.4) - 0.055;
    return (uint8_t)(v <= 0.0 ? 0 : v >= 1.0 ? 255 : v * 255.0 + 0.5);
}

/* The model at the truth's pixel whose surface point is @p p_cam (camera frame): the ray from
 * the camera through it hits the recovered mesh; @retval 0 when it does not. */
static int model_at(const struct sim_mesh *m, const struct sim_bvh *bvh,
                    const struct reflect_model *lobes, const struct frame_xform *obj, vec3 p_cam,
                    double fall_ref_mm, double out[3])
{
    vec3 cam = frame_point(obj, v3(0, 0, 0)), dir = frame_dir(obj, v3_norm(p_cam));
    struct sim_hit h;
    if (!sim_bvh_intersect(bvh, cam, dir, 1e-6, 1e9, &h))
        return 0;
    const uint32_t *tv = &m->tri[3 * h.tri];
    double w[3] = {1.0 - h.u - h.v, h.u, h.v}, rho[3] = {0, 0, 0};
    vec3 n = v3(0, 0, 0);
    for (int k = 0; k < 3; k++) {
        const float *nn = &m->normal[3 * tv[k]];
        double lin[3];
        n = v3_add(n, v3_scale(v3(nn[0], nn[1], nn[2]), w[k]));
        sim_mesh_linear(m, tv[k], lin);
        for (int c = 0; c < 3; c++)
            rho[c] += w[k] * lin[c];
    }
    n = v3_norm(frame_dir_inv(obj, v3_norm(n))); /* to the camera frame */
    vec3 p = v3_scale(v3_norm(p_cam), h.t), to = v3_sub(v3_from(novel_light_mm), p);
    double d = v3_len(to), fall = (fall_ref_mm / d) * (fall_ref_mm / d);
    vec3 l = v3_scale(to, 1.0 / d), v = v3_norm(v3_scale(p, -1.0));
    double ci = v3_dot(n, l), cr = v3_dot(n, v);
    for (int c = 0; c < 3; c++)
        out[c] = 0.0;
    if (ci <= 0.0 || cr <= 0.0)
        return 1;
    double spec[3] = {0, 0, 0}, diffuse = ci;
    if (lobes->count > 0) {
        const struct reflect_cluster *cl = &lobes->cluster[reflect_cluster_of(lobes, rho)];
        double nh = v3_dot(n, v3_norm(v3_add(l, v)));
        reflect_specular(cl, acos(fmin(1.0, fmax(-1.0, nh))), cr, spec);
        diffuse = reflect_diffuse(cl, ci, cr, reflect_cos_d(v3_dot(l, v)));
    }
    /* the model's units hold at the reference distance: the new light's falloff times that */
    for (int c = 0; c < 3; c++)
        out[c] = (rho[c] * diffuse + spec[c]) * fall;
    return 1;
}

/* The simulator's material as this model's lobe, to compare the fitted one with: the best lobe
 * of the model's form, K D(alpha) / cos(theta_r) (reflect_lobe), for the material's specular
 * part where the scan saw it: at every 4th pixel of each view's angle (@p cfg's views, the
 * scan's calibration in @p seen) and each light that reaches the point, the simulator's own
 * rendering of the lobe (sim_rig_specular_at: through the light's diffuser, so a lobe sharper
 * than the diffuser is seen as wide as the diffuser, and more so for the nearer lights) in the
 * fit's units (the white reference, the falloff taken out); fitted by least squares over those
 * observations alike, as the scan's fit weighs its own (the roughness on a fine grid). A
 * material that is not of the model's form (Phong has no 1 / cos(theta_r); Low et al.'s ABC
 * lobe a heavier tail) is compared in the form it takes on the rig, not as its own numbers.
 * @p strength: K's mean over the channels. @retval 0, or -ENOMEM */
static int material_lobe(struct sim_rig *seen, const struct app_config *cfg, double *strength,
                         double *roughness)
{
    const struct colour_params *col = &cfg->scan.colour;
    enum { STEP = 4 };
    size_t cap = 1u << 20, n = 0;
    float *obs = malloc(sizeof(float) * 3 * cap); /* alpha, cos_r, signal */
    if (obs == NULL)
        return -ENOMEM;
    double gain = (double)col->exposure_us / seen->cfg.reference_exposure_us;
    for (uint32_t v = 0; v < cfg->views; v++) {
        seen->table_angle_mdeg =
            (int32_t)(1000.0 * (cfg->start_angle_deg + 360.0 * v / cfg->views));
        sim_rig_update(seen);
        for (uint32_t y = 0; y < seen->height; y += STEP)
            for (uint32_t x = 0; x < seen->width; x += STEP) {
                size_t i = (size_t)y * seen->width + x;
                if (!seen->truth.hit[i])
                    continue;
                const float *pc = &seen->truth.pos_cam[3 * i], *nc = &seen->truth.normal_cam[3 * i];
                vec3 p = v3(pc[0], pc[1], pc[2]), nn = v3(nc[0], nc[1], nc[2]);
                vec3 view = v3_norm(v3_scale(p, -1.0));
                for (uint32_t l = 0; l < seen->calib.light_count && n < cap; l++) {
                    vec3 to = v3_sub(v3_from(seen->calib.light_pos_mm[l]), p);
                    double d = v3_len(to), sig[3], sum = 0.0;
                    if (v3_dot(nn, to) / d < col->min_cos)
                        continue;
                    sim_rig_specular_at(seen, i, l, sig);
                    for (int c = 0; c < 3; c++)
                        sum += sig[c] * gain * col->white_scale[c] / 3.0;
                    double fall = (d / col->reference_mm) * (d / col->reference_mm);
                    double nh = v3_dot(nn, v3_norm(v3_add(v3_scale(to, 1.0 / d), view)));
                    obs[3 * n + 0] = (float)acos(fmin(1.0, fmax(-1.0, nh)));
                    obs[3 * n + 1] = (float)v3_dot(nn, view);
                    obs[3 * n + 2] = (float)(sum * fall);
                    n++;
                }
            }
    }
    double best = 1e300;
    for (int g = 0; g < 400; g++) {
        double s = 0.01 * pow(100.0, g / 399.0), sgg = 0.0, syg = 0.0, syy = 0.0;
        for (size_t k = 0; k < n; k++) {
            double lobe = reflect_lobe(s, obs[3 * k], obs[3 * k + 1]), yk = obs[3 * k + 2];
            sgg += lobe * lobe, syg += yk * lobe, syy += yk * yk;
        }
        double kk = sgg > 0.0 ? syg / sgg : 0.0, err = syy - kk * syg;
        if (err < best)
            best = err, *strength = kk, *roughness = s;
    }
    free(obs);
    return 0;
}

static int run(const char *scene, const char *scan_dir, const char *result_dir, const char *label,
               const char *out_png)
{
    static struct app_config cfg, made;
    static struct scan_calib calib;
    static struct sim_rig rig;
    char path[HAL_MAX_PATH + 64], err[512], dir[HAL_MAX_PATH];
    int rc = config_load(&cfg, scene, err, sizeof(err));
    /* the white reference and colour settings the result was made with */
    snprintf(path, sizeof(path), "%s/config.ini", result_dir);
    if (rc == 0)
        rc = config_load(&made, path, err, sizeof(err));
    cfg.scan.colour = made.scan.colour;
    scan_dir_path(path, sizeof(path), scan_dir, -1, "calibration.ini");
    if (rc == 0)
        rc = calib_load(&calib, path, cfg.light_count, err, sizeof(err));
    if (rc != 0) {
        fprintf(stderr, "relight-eval: %s\n", err);
        return 1;
    }
    for (uint32_t l = 0; l < calib.light_count; l++) /* truly a new place */
        if (v3_len(v3_sub(v3_from(calib.light_pos_mm[l]), v3_from(novel_light_mm))) < 100.0) {
            fprintf(stderr, "relight-eval: light %u is within 100 mm of the new light\n", l);
            return 1;
        }
    struct scan_calib lit = calib; /* light 0 moved to the new place: the one rendered */
    memcpy(lit.light_pos_mm[0], novel_light_mm, sizeof(novel_light_mm));
    lit.light_gain[0] = 1.0;
    struct sim_config sc = cfg.sim;
    sc.read_noise_dn = 0.0, sc.electrons_per_dn = 1e12, sc.black_offset_dn = 0.0;
    sc.ambient_dn = 0.0, sc.jpeg_quality = 0, sc.bounce_samples = 0;
    struct gray_layout layout;
    scan_layout(&cfg.scan, &calib, &layout);
    snprintf(dir, sizeof(dir), "%s", scene);
    rc = sim_rig_init(&rig, &sc, &lit, &layout, dirname(dir), err, sizeof(err));
    if (rc != 0) {
        fprintf(stderr, "relight-eval: %s\n", err);
        return 1;
    }
    rig.table_angle_mdeg = ANGLE_MDEG;
    sim_rig_update(&rig);
    uint32_t w = rig.width, h = rig.height;
    uint8_t *frame = malloc((size_t)w * h * 3);
    struct sim_sources src = {0, 0, 1u, cfg.scan.colour.exposure_us, 1000};
    sim_rig_render(&rig, &src, 0, frame); /* rig.signal: the light before gain and noise */
    double gain = (double)src.exposure_us / sc.reference_exposure_us;

    struct sim_mesh m;
    struct sim_bvh bvh;
    struct reflect_model lobes;
    memset(&lobes, 0, sizeof(lobes));
    snprintf(path, sizeof(path), "%s/mesh.ply", result_dir);
    if (sim_mesh_load_ply(&m, path, err, sizeof(err)) != 0 || m.rgb == NULL ||
        sim_bvh_build(&bvh, &m) != 0) {
        fprintf(stderr, "relight-eval: %s: no coloured mesh\n", path);
        return 1;
    }
    snprintf(path, sizeof(path), "%s/reflectance.ini", result_dir);
    ini_parse(path, reflectance_key, &lobes); /* none: a matte model */
    struct frame_xform obj;
    frame_object_from_camera(&calib, ANGLE_MDEG, &obj);
    double *de = malloc(sizeof(double) * w * h);
    uint8_t *img = calloc((size_t)2 * w * h * 3, 1);
    size_t n = 0;
    uint32_t x0 = w, x1 = 0, y0 = h, y1 = 0;
    for (uint32_t y = 0; y < h; y++)
        for (uint32_t x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            const float *pc = &rig.truth.pos_cam[3 * i];
            if (!rig.truth.hit[i] || !(rig.light_vis[i] & 1u))
                continue;
            vec3 p = v3(pc[0], pc[1], pc[2]);
            double truth[3], model[3], lt[3], lm[3];
            for (int c = 0; c < 3; c++) /* the scan's white reference: albedo units */
                truth[c] = rig.signal[3 * i + (size_t)c] * gain * cfg.scan.colour.white_scale[c];
            if (!model_at(&m, &bvh, &lobes, &obj, p, cfg.scan.colour.reference_mm, model))
                continue;
            colour_linear_rgb_to_lab(truth, lt);
            colour_linear_rgb_to_lab(model, lm);
            de[n++] = colour_ciede2000(lt, lm);
            for (int c = 0; c < 3; c++) {
                img[3 * ((size_t)y * 2 * w + x) + (size_t)c] = to_srgb(truth[c]);
                img[3 * ((size_t)y * 2 * w + w + x) + (size_t)c] = to_srgb(model[c]);
            }
            x0 = x < x0 ? x : x0, x1 = x > x1 ? x : x1, y0 = y < y0 ? y : y0, y1 = y > y1 ? y : y1;
        }
    if (n == 0) {
        fprintf(stderr, "relight-eval: the new light reaches none of the object's pixels\n");
        return 1;
    }
    double sum = 0.0;
    for (size_t i = 0; i < n; i++)
        sum += de[i];
    qsort(de, n, sizeof(double), cmp_double);
    /* the lobe fitted to the most samples, against the material's own */
    double sim_k = 0.0, sim_s = 0.0, fit_k = 0.0, fit_s = 0.0;
    uint32_t most = 0;
    for (uint32_t k = 1; k < lobes.count; k++)
        if (lobes.cluster[k].samples > lobes.cluster[most].samples)
            most = k;
    if (lobes.count > 0) {
        const struct reflect_cluster *c = &lobes.cluster[most];
        fit_k = (c->specular[0] + c->specular[1] + c->specular[2]) / 3.0;
        fit_s = c->roughness;
    }
    /* the material as the rig saw it, for a model with a lobe to compare (a matte one: 0) */
    if (rig.material.kind != SIM_MAT_LAMBERT && lobes.count > 0) {
        static struct sim_rig seen;
        snprintf(dir, sizeof(dir), "%s", scene);
        rc = sim_rig_init(&seen, &sc, &calib, &layout, dirname(dir), err, sizeof(err));
        if (rc == 0)
            rc = material_lobe(&seen, &cfg, &sim_k, &sim_s);
        if (rc != 0) {
            fprintf(stderr, "relight-eval: the material's lobe: %s\n",
                    rc == -ENOMEM ? "no memory" : err);
            return 1;
        }
        sim_rig_free(&seen);
    }
    printf("%s,%zu,%.3f,%.3f,%.4f,%.4f,%.4f,%.4f\n", label, n, sum / n,
           de[(size_t)(0.95 * (double)(n - 1))], sim_k, fit_k, sim_s, fit_s);
    if (out_png != NULL) { /* truth | model, cropped to the object */
        uint32_t cw = x1 - x0 + 1, ch = y1 - y0 + 1;
        uint8_t *crop = malloc((size_t)2 * cw * ch * 3);
        for (uint32_t y = 0; y < ch; y++)
            for (int half = 0; half < 2; half++)
                memcpy(&crop[3 * ((size_t)y * 2 * cw + (size_t)half * cw)],
                       &img[3 * ((size_t)(y0 + y) * 2 * w + (size_t)half * w + x0)],
                       (size_t)cw * 3);
        struct hal_storage st;
        storage_posix_init(&st);
        rc = image_write_png(&st, out_png, crop, 2 * cw, ch, 3);
        free(crop);
    }
    free(de);
    free(img);
    free(frame);
    sim_bvh_free(&bvh);
    sim_mesh_free(&m);
    sim_rig_free(&rig);
    return rc == 0 ? 0 : 1;
}

int main(int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "header") == 0) {
        printf("label,relit_pixels,relit_de2000_mean,relit_de2000_p95,material_strength,"
               "fitted_strength,material_roughness,fitted_roughness\n");
        return 0;
    }
    if (argc == 5 || argc == 6)
        return run(argv[1], argv[2], argv[3], argv[4], argc == 6 ? argv[5] : NULL);
    fprintf(stderr, "usage: relight-eval header\n"
                    "       relight-eval SCENE.ini SCAN_DIR RESULT_DIR LABEL [OUT.png]\n");
    return 2;
}
